"""Terrain geometry: box frames, raster, exact heights, support surfaces and exports."""

import math

import mujoco
import numpy as np
import pytest
import trimesh

from leas_jax.terrain import Box, SupportSurface, Terrain, TerrainError, loads_terrain
from leas_jax.terrain.export import export_terrain, terrain_to_mesh, terrain_to_mjcf


def make_terrain(boxes, bounds=((0.0, 0.0), (1.0, 1.0)), resolution=0.1, void_height=-2.0):
    return Terrain(name="t", bounds=bounds, void_height=void_height, resolution=resolution, boxes=boxes)


def grid(terrain):
    """[nx, ny] x and y of the raster points."""
    xs, ys = terrain.grid_axes()
    return np.meshgrid(xs, ys, indexing="ij")


# ------------------------------------------------------------------------ frames


def test_rotation_is_rz_ry_rx():
    roll, pitch, yaw = 0.3, -0.2, 1.1
    rx = np.array([[1, 0, 0], [0, math.cos(roll), -math.sin(roll)], [0, math.sin(roll), math.cos(roll)]])
    ry = np.array([[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0], [-math.sin(pitch), 0, math.cos(pitch)]])
    rz = np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]])
    box = Box([0, 0, 0], [1, 1, 1], [roll, pitch, yaw])
    np.testing.assert_allclose(box.rotation, rz @ ry @ rx, atol=1e-15)


def test_quaternion_matches_mujoco_euler():
    """Independent reference: MuJoCo's own conversion of extrinsic X-Y-Z Euler angles
    (= Rz(yaw) Ry(pitch) Rx(roll)) to a quaternion (w, x, y, z)."""
    rpy = (0.3, -0.2, 1.1)
    xml = f"""<mujoco><compiler angle="radian" eulerseq="XYZ"/><worldbody>
      <geom type="box" size="1 1 1" euler="{rpy[0]} {rpy[1]} {rpy[2]}"/></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    box = Box([0, 0, 0], [1, 1, 1], rpy)
    q_ref = model.geom_quat[0] * np.sign(model.geom_quat[0][0])
    np.testing.assert_allclose(box.quaternion_wxyz, q_ref, atol=1e-9)
    matrix = np.zeros(9)
    mujoco.mju_quat2Mat(matrix, box.quaternion_wxyz)
    np.testing.assert_allclose(matrix.reshape(3, 3), box.rotation, atol=1e-12)


def test_vertices_and_aabb():
    box = Box([1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, math.pi / 2])
    # a quarter turn swaps the x and y extents: x in [1 - 2, 1 + 2], y in [2 - 1, 2 + 1]
    np.testing.assert_allclose(box.aabb(), [[-1.0, 1.0, 0.0], [3.0, 3.0, 6.0]], atol=1e-12)
    vertices = box.vertices()
    assert vertices.shape == (8, 3)
    np.testing.assert_allclose(vertices.min(axis=0), [-1.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(vertices.max(axis=0), [3.0, 3.0, 6.0], atol=1e-12)
    assert len({tuple(np.round(v, 9)) for v in vertices}) == 8


def test_boxes_compare_by_value():
    assert Box([0, 0, 0], [1, 1, 1]) == Box((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (0.0, 0.0, 0.0))
    assert Box([0, 0, 0], [1, 1, 1]) != Box([0, 0, 0], [1, 1, 2])
    assert hash(Box([0, 0, 0], [1, 1, 1])) == hash(Box([0, 0, 0], [1, 1, 1]))


# ------------------------------------------------------------------------ raster


def test_shape_formula():
    # (1.0 - 0.0) / 0.1 + 1 = 11 points along x; (0.5 - 0.0) / 0.1 + 1 = 6 along y
    terrain = make_terrain([Box([0.5, 0.5, 0.0], [1.0, 1.0, 0.1])], bounds=((0.0, 0.0), (1.0, 0.5)))
    assert terrain.shape == (11, 6)
    assert terrain.raster().shape == (11, 6) and terrain.raster().dtype == np.float32


def test_flat_box_raster():
    # top at z = -0.1 + 0.2 / 2 = 0 over x, y in [0.2, 0.8] (closed: edges included), void elsewhere
    terrain = make_terrain([Box([0.5, 0.5, -0.1], [0.6, 0.6, 0.2])])
    x, y = grid(terrain)
    inside = (x >= 0.2 - 1e-9) & (x <= 0.8 + 1e-9) & (y >= 0.2 - 1e-9) & (y <= 0.8 + 1e-9)
    assert inside.sum() == 7 * 7
    np.testing.assert_array_equal(terrain.raster(), np.where(inside, 0.0, -2.0).astype(np.float32))


def test_raster_is_cached_and_read_only():
    terrain = make_terrain([Box([0.5, 0.5, -0.1], [0.6, 0.6, 0.2])])
    assert terrain.raster() is terrain.raster()
    with pytest.raises(ValueError):
        terrain.raster()[0, 0] = 1.0


def test_pitched_box_height_formula():
    # Box at the origin, thickness 0.2, pitched by p with tan p = 0.25. Its top face has
    # normal n = R e_z = (sin p, 0, cos p) and passes through c + 0.1 n, so on it
    # x sin p + z cos p = 0.1, i.e. z = 0.1 / cos p - x tan p = 0.1 * sqrt(1.0625) - 0.25 x.
    # The face spans |x| <= 1.0 cos p = 0.970 m horizontally; test |x| <= 0.9.
    pitch = math.atan(0.25)
    terrain = make_terrain(
        [Box([0.0, 0.0, 0.0], [2.0, 1.0, 0.2], [0.0, pitch, 0.0])],
        bounds=((-0.9, -0.4), (0.9, 0.4)),
        resolution=0.05,
    )
    x, _ = grid(terrain)
    expected = 0.1 * math.sqrt(1.0625) - 0.25 * x
    np.testing.assert_allclose(terrain.raster(), expected, atol=1e-6)
    np.testing.assert_allclose(terrain.height_at([[0.5, 0.1]]), [0.1 * math.sqrt(1.0625) - 0.125], atol=1e-12)


def test_rolled_box_stands_on_its_side():
    # Roll by 90 degrees: the box's y axis points up, so a 1 x 2 x 0.5 box stands 2 m tall
    # over x in [-0.5, 0.5], y in [-0.25, 0.25]: top at z = 1.
    terrain = make_terrain(
        [Box([0.0, 0.0, 0.0], [1.0, 2.0, 0.5], [math.pi / 2, 0.0, 0.0])], bounds=((-1.0, -1.0), (1.0, 1.0))
    )
    np.testing.assert_allclose(
        terrain.height_at([[0.4, 0.2], [0.4, 0.3], [0.6, 0.0]]), [1.0, -2.0, -2.0], atol=1e-12
    )


def test_yawed_box_footprint():
    # A 1 x 1 m square turned by 45 degrees covers |x| + |y| <= sqrt(2) / 2 = 0.7071.
    terrain = make_terrain(
        [Box([0.0, 0.0, 0.0], [1.0, 1.0, 0.4], [0.0, 0.0, math.pi / 4])], bounds=((-1.0, -1.0), (1.0, 1.0))
    )
    heights = terrain.height_at([[0.65, 0.0], [0.75, 0.0], [0.35, 0.35], [0.36, 0.36], [0.0, -0.7]])
    np.testing.assert_allclose(heights, [0.2, -2.0, 0.2, -2.0, 0.2], atol=1e-12)


def test_hole_between_boxes_is_void():
    # two slabs with top 0 over x in [0, 0.3] and [0.7, 1.0]: the hole x in (0.3, 0.7) is void
    terrain = make_terrain(
        [Box([0.15, 0.5, -0.1], [0.3, 1.0, 0.2]), Box([0.85, 0.5, -0.1], [0.3, 1.0, 0.2])], void_height=-3.5
    )
    expected_row = np.array([0, 0, 0, 0, -3.5, -3.5, -3.5, 0, 0, 0, 0], dtype=np.float32)
    np.testing.assert_array_equal(terrain.raster(), np.tile(expected_row[:, None], (1, 11)))


def test_overlapping_boxes_take_the_highest_point():
    ground = Box([0.5, 0.5, -0.1], [1.0, 1.0, 0.2])  # top 0 everywhere
    buried = Box([0.5, 0.5, -0.15], [0.4, 0.4, 0.1])  # top -0.1, inside the ground
    step = Box([0.25, 0.5, 0.05], [0.3, 1.0, 0.3])  # top 0.2 over x in [0.1, 0.4]
    roof = Box([0.8, 0.8, 1.5], [0.2, 0.2, 0.1])  # floating, top 1.55 over [0.7, 0.9]^2
    terrain = make_terrain([ground, buried, step, roof])
    x, y = grid(terrain)
    expected = np.zeros_like(x)
    expected[(x > 0.05) & (x < 0.45)] = 0.2
    expected[(x > 0.65) & (x < 0.95) & (y > 0.65) & (y < 0.95)] = 1.55
    np.testing.assert_allclose(terrain.raster(), expected, atol=1e-6)
    # a box below the void height still counts where it is the only box
    low = make_terrain([Box([0.5, 0.5, -5.0], [0.2, 0.2, 0.2])])
    assert low.height_at([[0.5, 0.5]])[0] == pytest.approx(-4.9)


def test_height_at_agrees_with_raster_on_grid_points():
    terrain = make_terrain(
        [
            Box([0.5, 0.4, 0.0], [0.7, 0.5, 0.3], [0.1, -0.2, 0.7]),
            Box([0.3, 0.6, 0.1], [0.4, 0.4, 0.1], [0.0, 0.0, 0.3]),
        ],
        resolution=0.02,
    )
    x, y = grid(terrain)
    exact = terrain.height_at(np.stack([x, y], axis=-1))
    assert exact.shape == terrain.shape
    np.testing.assert_allclose(terrain.raster(), exact, atol=1e-6)
    assert terrain.height_at([0.5, 0.4]).shape == ()


def test_height_at_many_points_matches_brute_force():
    # height_at buckets points by tile; compare with every box tested on every point,
    # including points outside the bounds and on the tile grid
    rng = np.random.default_rng(1)
    boxes = [
        Box(rng.uniform(0, 5, 3), rng.uniform(0.1, 1.5, 3), rng.uniform(-0.4, 0.4, 3)) for _ in range(40)
    ]
    terrain = make_terrain(boxes, bounds=((0.0, 0.0), (5.0, 5.0)))
    xy = np.concatenate(
        [rng.uniform(-1.0, 6.0, size=(20000, 2)), np.mgrid[0:5.5:0.5, 0:5.5:0.5].reshape(2, -1).T]
    )
    top = np.max([box.column_top(xy[:, 0], xy[:, 1]) for box in boxes], axis=0)
    expected = np.where(np.isfinite(top), top, -2.0)
    assert np.mean(expected > -2.0) > 0.3
    np.testing.assert_array_equal(terrain.height_at(xy), expected)
    assert terrain.height_at(np.zeros((0, 2))).shape == (0,)
    with pytest.raises(TerrainError, match="nan or inf"):
        terrain.height_at([[np.nan, 1.0]])
    with pytest.raises(TerrainError, match=r"shape \(3,\)"):
        terrain.height_at([1.0, 2.0, 3.0])


def test_raster_of_a_large_box_is_chunked_and_correct():
    # 2001 x 2001 = 4 million points under one box: more than one chunk of 2^20 points
    terrain = make_terrain(
        [Box([20.0, 20.0, -0.5], [40.0, 40.0, 1.0])], bounds=((0.0, 0.0), (40.0, 40.0)), resolution=0.02
    )
    heights = terrain.raster()
    assert heights.shape == (2001, 2001)
    assert np.all(heights == 0.0)


# ------------------------------------------------------------ support surfaces


def signed_area_normal(vertices):
    """Newell's normal of a polygon: its direction is where the polygon turns counter-clockwise."""
    v = np.asarray(vertices)
    nxt = np.roll(v, -1, axis=0)
    return 0.5 * np.cross(v, nxt).sum(axis=0)


def test_axis_aligned_box_has_its_top_face():
    terrain = make_terrain([Box([0.5, 0.5, -0.1], [0.6, 0.4, 0.2])])
    surfaces = terrain.support_surfaces()
    assert len(surfaces) == 1
    surface = surfaces[0]
    assert isinstance(surface, SupportSurface) and surface.box_index == 0
    np.testing.assert_allclose(surface.normal, [0, 0, 1], atol=1e-12)
    expected = {(0.2, 0.3, 0.0), (0.8, 0.3, 0.0), (0.2, 0.7, 0.0), (0.8, 0.7, 0.0)}
    assert {tuple(np.round(v, 9) + 0.0) for v in surface.vertices} == expected
    # counter-clockwise seen from above: the area vector points up, area 0.6 x 0.4
    np.testing.assert_allclose(signed_area_normal(surface.vertices), [0, 0, 0.24], atol=1e-12)


@pytest.mark.parametrize(
    "slope_deg, mu, kept",
    [
        (20.0, 0.5, True),  # tan 20 deg = 0.364 <= 0.5
        (26.0, 0.5, True),  # atan 0.5 = 26.57 deg
        (27.0, 0.5, False),
        (30.0, 0.5, False),  # tan 30 deg = 0.577 > 0.5
        (30.0, 0.6, True),  # ... <= 0.6
        (-20.0, 0.5, True),
    ],
)
def test_slope_inside_or_outside_the_friction_cone(slope_deg, mu, kept):
    pitch = math.radians(slope_deg)
    terrain = make_terrain([Box([0.5, 0.5, 0.0], [0.5, 0.5, 0.1], [0.0, pitch, 0.3])])
    surfaces = terrain.support_surfaces(mu=mu)
    assert len(surfaces) == (1 if kept else 0)
    if kept:
        surface = surfaces[0]
        np.testing.assert_allclose(surface.normal, terrain.boxes[0].rotation[:, 2], atol=1e-12)
        assert math.degrees(math.acos(surface.normal[2])) == pytest.approx(abs(slope_deg))
        area = signed_area_normal(surface.vertices)
        # counter-clockwise about the normal, area 0.5 x 0.5
        np.testing.assert_allclose(area, 0.25 * surface.normal, atol=1e-12)
        # the polygon lies in the plane of the face, at the top of the box
        np.testing.assert_allclose(
            (surface.vertices - terrain.boxes[0].center) @ surface.normal, 0.05, atol=1e-12
        )


def test_side_face_of_a_rolled_box_is_a_support_surface():
    # roll by 90 degrees turns the box's y axis to +z: its +y face (0.4 x 0.3) is on top, at z = 0.1
    terrain = make_terrain([Box([0.5, 0.5, 0.0], [0.4, 0.2, 0.3], [math.pi / 2, 0.0, 0.0])])
    (surface,) = terrain.support_surfaces()
    np.testing.assert_allclose(surface.normal, [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(surface.vertices[:, 2], 0.1, atol=1e-12)
    np.testing.assert_allclose(signed_area_normal(surface.vertices), [0, 0, 0.4 * 0.3], atol=1e-12)


def test_only_faces_buried_whole_under_other_boxes_are_left_out():
    ground = Box([0.5, 0.5, -0.1], [1.0, 1.0, 0.2])
    over_centre = Box([0.5, 0.5, 0.05], [0.3, 0.3, 0.1])  # a pillar on the ground's centre
    off_centre = Box([0.15, 0.15, 0.05], [0.2, 0.2, 0.1])
    over_all = Box([0.5, 0.5, 0.05], [1.2, 1.2, 0.1])  # covers the whole ground face
    halves = [Box([0.25, 0.5, 0.05], [0.5, 1.0, 0.1]), Box([0.75, 0.5, 0.05], [0.5, 1.0, 0.1])]
    for covering, kept in (
        ([over_centre], [0, 1]),
        ([off_centre], [0, 1]),
        ([over_all], [1]),
        (halves, [1, 2]),
    ):
        surfaces = make_terrain([ground, *covering]).support_surfaces()
        assert [s.box_index for s in surfaces] == kept
    with pytest.raises(TerrainError):
        make_terrain([ground]).support_surfaces(mu=0.0)


# ------------------------------------------------------------------------ exports

EXPORT_TEXT = """\
name = "export"
bounds = [[0.0, 0.0], [3.0, 2.0]]
void_height = -2.0
resolution = 0.05
[[box]]
center = [1.0, 1.0, -0.1]
size = [2.0, 2.0, 0.2]
[[box]]
center = [2.5, 1.0, 0.1]
size = [0.6, 0.8, 0.2]
rpy = [0.1, -0.2, 0.7]
"""


def test_mjcf_has_one_box_geom_per_box():
    terrain = loads_terrain(EXPORT_TEXT)
    model = mujoco.MjModel.from_xml_string(terrain_to_mjcf(terrain))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert model.ngeom == 2
    assert np.all(model.geom_type == mujoco.mjtGeom.mjGEOM_BOX)
    for index, box in enumerate(terrain.boxes):
        np.testing.assert_allclose(model.geom_size[index], box.size / 2, atol=1e-12)
        np.testing.assert_allclose(data.geom_xpos[index], box.center, atol=1e-12)
        np.testing.assert_allclose(data.geom_xmat[index].reshape(3, 3), box.rotation, atol=1e-9)
        assert mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, index) == f"box{index}"


def test_mesh_has_the_boxes():
    terrain = loads_terrain(EXPORT_TEXT)
    mesh = terrain_to_mesh(terrain)
    assert isinstance(mesh, trimesh.Trimesh)
    assert mesh.vertices.shape == (16, 3) and mesh.faces.shape == (24, 3)
    # disjoint boxes: volume 2 x 2 x 0.2 + 0.6 x 0.8 x 0.2 = 0.8 + 0.096
    assert mesh.volume == pytest.approx(0.896, abs=1e-9)
    np.testing.assert_allclose(
        np.sort(mesh.vertices, axis=0)[-8:].max(axis=0),
        np.max([b.vertices().max(axis=0) for b in terrain.boxes], axis=0),
        atol=1e-12,
    )
    for index, box in enumerate(terrain.boxes):
        np.testing.assert_allclose(
            np.sort(mesh.vertices[8 * index : 8 * index + 8], axis=0),
            np.sort(box.vertices(), axis=0),
            atol=1e-12,
        )


@pytest.mark.parametrize("suffix", [".xml", ".glb", ".obj", ".stl"])
def test_export_by_extension(tmp_path, suffix):
    terrain = loads_terrain(EXPORT_TEXT)
    path = tmp_path / f"terrain{suffix}"
    export_terrain(terrain, path)
    assert path.stat().st_size > 0
    if suffix == ".xml":
        assert mujoco.MjModel.from_xml_path(str(path)).ngeom == 2
    else:
        loaded = trimesh.load(str(path), force="mesh")
        assert loaded.volume == pytest.approx(0.896, rel=1e-5)


def test_export_rejects_unknown_extension(tmp_path):
    with pytest.raises(TerrainError, match=r"unknown export format '\.ply'"):
        export_terrain(loads_terrain(EXPORT_TEXT), tmp_path / "terrain.ply")
