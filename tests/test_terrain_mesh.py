"""Terrain format v2: meshes and elevation maps as terrains.

Round trip of every committed box terrain through STL, parity with MuJoCo's ray cast,
mesh defects, an elevation map of a known function, the bad inputs, exports and the
hpp-environments scenes.
"""

import math
from pathlib import Path

import numpy as np
import pytest
import trimesh

from leas_jax.terrain import TerrainError, load_terrain, loads_terrain
from leas_jax.terrain import sources as terrain_sources
from leas_jax.terrain.export import export_terrain, terrain_to_mesh, terrain_to_mjcf

REPO = Path(__file__).resolve().parents[1]
BOX_TERRAINS = sorted(p for p in (REPO / "terrains").glob("*.toml") if "[[box]]" in p.read_text()) + [
    REPO / "tests" / "data" / "slab_with_wall.toml"
]
# Scenes of hpp-environments, kept apart from the generated box terrains of terrains/*.toml.
HPP_TERRAINS = sorted((REPO / "terrains" / "hpp").glob("*.toml"))
HEAD = 'name = "m"\nbounds = [[-1.0, -1.0], [3.0, 2.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
STEP = (
    HEAD
    + "[[box]]\ncenter = [1.0, 0.5, -0.1]\nsize = [3.0, 2.0, 0.2]\n[[box]]\ncenter = [1.5, 0.5, 0.05]\nsize = [0.6, 0.8, 0.3]\n"
)


def _area(surface) -> float:
    v = surface.vertices
    return float(0.5 * np.linalg.norm(np.cross(v[1:-1] - v[0], v[2:] - v[0]), axis=1).sum())


def _twin(terrain, folder: Path, transform=None, name="twin", **mesh_keys):
    """The terrain's boxes as one STL `[[mesh]]` terrain (vertices optionally mapped by `transform`)."""
    mesh = terrain_to_mesh(terrain)
    if transform is not None:
        mesh = transform(mesh)
    mesh.export(folder / f"{name}.stl")
    (xmin, ymin), (xmax, ymax) = terrain.bounds.tolist()
    keys = "".join(f"{k} = {v}\n" for k, v in mesh_keys.items())
    text = (
        f'name = "{name}"\nbounds = [[{xmin}, {ymin}], [{xmax}, {ymax}]]\n'
        f"void_height = {terrain.void_height}\nresolution = {terrain.resolution}\n"
        f'[[mesh]]\nfile = "{name}.stl"\n{keys}'
    )
    path = folder / f"{name}.toml"
    path.write_text(text)
    return load_terrain(path)


def _away_from_edges(heights: np.ndarray) -> np.ndarray:
    """[nx, ny] cells whose 3 x 3 neighbourhood has one height (1 mm): not on an edge."""
    padded = np.pad(heights.astype(np.float64), 1, mode="edge")
    spread = np.zeros(heights.shape)
    for di in (0, 1, 2):
        for dj in (0, 1, 2):
            window = padded[di : di + heights.shape[0], dj : dj + heights.shape[1]]
            spread = np.maximum(spread, np.abs(window - heights))
    return spread <= 1e-3


@pytest.mark.parametrize("path", BOX_TERRAINS, ids=lambda p: p.stem)
def test_round_trip_raster_and_surfaces(path, tmp_path):
    boxes = load_terrain(path)
    mesh = _twin(boxes, tmp_path)
    a, b = boxes.raster(), mesh.raster()
    keep = _away_from_edges(a)
    assert keep.mean() > 0.85  # the curriculum arena's rubble and blocks put 10 % of its cells on edges
    np.testing.assert_allclose(b[keep], a[keep], atol=1e-3, rtol=0)
    area_boxes = sum(map(_area, boxes.support_surfaces()))
    area_mesh = sum(map(_area, mesh.support_surfaces()))
    assert abs(area_mesh - area_boxes) <= 0.01 * area_boxes
    # Every mesh surface is convex and counter-clockwise about its upward normal.
    for surface in mesh.support_surfaces():
        v = surface.vertices
        turns = (
            np.cross(np.roll(v, -1, axis=0) - v, np.roll(v, -2, axis=0) - np.roll(v, -1, axis=0))
            @ surface.normal
        )
        assert np.all(turns >= -1e-9) and surface.normal[2] > 0 and surface.mesh_index == 0


@pytest.mark.parametrize(
    "guide", sorted((REPO / "tests" / "data").glob("*_leas_guide.npz")), ids=lambda p: p.stem
)
def test_round_trip_contact_plans(guide, tmp_path):
    from leas_jax.contacts import plan_contacts

    with np.load(guide) as data:
        path, dt = data["guide"], float(data["timestep"])
    # <a>_<b>_<what>_leas_guide.npz is a path on terrains/<a>_<b>.toml (eval_stairs, training_arena)
    boxes = load_terrain(REPO / "terrains" / ("_".join(guide.stem.split("_")[:2]) + ".toml"))
    mesh = _twin(boxes, tmp_path)
    a, b = plan_contacts(boxes, path, dt), plan_contacts(mesh, path, dt)
    assert abs(a.coverage - b.coverage) <= 1.0 / len(path) + 1e-12


def test_raster_matches_mujoco_ray_cast():
    import mujoco

    terrain = load_terrain(REPO / "terrains" / "hpp" / "rubble.toml")
    model = mujoco.MjModel.from_xml_string(terrain_to_mjcf(terrain))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    xs, ys = terrain.grid_axes()
    heights = terrain.raster()
    geom = np.zeros(1, np.int32)
    rng = np.random.default_rng(0)
    for i, j in zip(rng.integers(0, len(xs), 400), rng.integers(0, len(ys), 400)):
        dist = mujoco.mj_ray(
            model, data, np.array([xs[i], ys[j], 5.0]), np.array([0.0, 0.0, -1.0]), None, 1, -1, geom
        )
        expected = 5.0 - dist if dist >= 0 else terrain.void_height
        assert abs(heights[i, j] - expected) < 1e-4, (xs[i], ys[j])


def _same_geometry(reference, other):
    np.testing.assert_allclose(other.raster(), reference.raster(), atol=1e-4, rtol=0)
    assert len(other.support_surfaces()) == len(reference.support_surfaces())
    area = sum(map(_area, reference.support_surfaces()))
    assert abs(sum(map(_area, other.support_surfaces())) - area) <= 1e-4 * area


def test_defects_flipped_normals_duplicates_and_open_edges(tmp_path):
    reference = _twin(loads_terrain(STEP), tmp_path, name="ref")

    def flipped(mesh):
        return trimesh.Trimesh(mesh.vertices, mesh.faces[:, ::-1], process=False)

    def duplicated(mesh):
        return trimesh.Trimesh(
            mesh.vertices, np.concatenate([mesh.faces, mesh.faces[:, [1, 2, 0]]]), process=False
        )

    def open_edges(mesh):
        # Keep the upward faces only: no sides, no bottoms, every edge open.
        keep = mesh.face_normals[:, 2] > 0.5
        return trimesh.Trimesh(mesh.vertices, mesh.faces[keep], process=False)

    for transform in (flipped, duplicated, open_edges):
        _same_geometry(reference, _twin(loads_terrain(STEP), tmp_path, transform, name=transform.__name__))


def test_defects_hole_in_the_mesh(tmp_path):
    terrain = loads_terrain(STEP)

    def holed(mesh):
        # Drop one top triangle of the step: its rays fall through to the slab below.
        top = np.flatnonzero(np.isclose(mesh.triangles_center[:, 2], 0.2))
        return trimesh.Trimesh(mesh.vertices, np.delete(mesh.faces, top[0], axis=0), process=False)

    twin = _twin(terrain, tmp_path, holed, name="holed")
    lost = terrain.raster() - twin.raster()
    np.testing.assert_allclose(lost[np.abs(lost) > 1e-4], 0.2, atol=1e-4)  # down to the slab (z = 0)
    assert 0.3 * 0.48 / 0.02**2 < np.count_nonzero(lost > 1e-4) < 0.7 * 0.48 / 0.02**2  # about half the top
    # The slab and what is left of the step's top: one triangle, half of it.
    slab, top = sorted(twin.support_surfaces(), key=lambda s: s.vertices[0, 2])
    assert len(top.vertices) == 3 and _area(top) == pytest.approx(0.5 * 0.6 * 0.8)
    assert _area(slab) == pytest.approx(3.0 * 2.0)


def test_defects_millimetres_and_y_up(tmp_path):
    terrain = loads_terrain(STEP)
    reference = _twin(terrain, tmp_path, name="ref")

    def millimetres(mesh):
        return trimesh.Trimesh(mesh.vertices * 1000.0, mesh.faces, process=False)

    def y_up(mesh):
        # (x, y, z) world -> (x, z, -y): the mesh as a Y-up tool writes it.
        v = mesh.vertices
        return trimesh.Trimesh(np.stack([v[:, 0], v[:, 2], -v[:, 1]], axis=1), mesh.faces, process=False)

    _same_geometry(reference, _twin(terrain, tmp_path, millimetres, name="mm", scale=0.001))
    _same_geometry(reference, _twin(terrain, tmp_path, y_up, name="yup", rpy=[math.pi / 2, 0.0, 0.0]))


def test_translate_and_mixed_boxes(tmp_path):
    mesh = trimesh.creation.box(extents=[0.5, 0.5, 0.2])
    mesh.export(tmp_path / "block.stl")
    path = tmp_path / "mixed.toml"
    path.write_text(
        HEAD
        + "[[box]]\ncenter = [1.0, 0.5, -0.1]\nsize = [3.0, 2.0, 0.2]\n"
        + '[[mesh]]\nfile = "block.stl"\ntranslate = [2.0, 1.0, 0.1]\n'
    )
    terrain = load_terrain(path)
    assert terrain.height_at([2.0, 1.0]) == pytest.approx(0.2)
    assert terrain.height_at([1.0, 0.0]) == pytest.approx(0.0)
    assert terrain.height_at([2.9, 1.9]) == terrain.void_height
    tops = sorted(round(float(s.vertices[:, 2].mean()), 6) for s in terrain.support_surfaces())
    assert tops == [0.0, 0.2]
    # verify's collision messages name the object: the boxes first, then the mesh tiles
    from leas_jax.contacts.robot.collision import terrain_collision, terrain_object_name

    names = [terrain_object_name(terrain, b) for b in range(len(terrain_collision(terrain).shapes))]
    # the block straddles x = 2 and y = 1, the corners of four 1 m tiles
    assert names == ["terrain box 0"] + [f"terrain mesh tile {k}" for k in range(4)]


def test_elevation_map_of_a_known_function(tmp_path):
    res = 0.05
    x = -1.0 + np.arange(81) * res
    y = -1.0 + np.arange(61) * res

    def f(x, y):
        return 0.3 * np.sin(x) * np.cos(0.5 * y)

    np.save(tmp_path / "h.npy", f(x[:, None], y[None, :]))
    text = (
        'name = "e"\nbounds = [[-1.0, -1.0], [3.0, 2.0]]\nvoid_height = -2.0\nresolution = 0.05\n'
        '[elevation]\nfile = "h.npy"\norigin = [-1.0, -1.0, 0.0]\nresolution = 0.05\n'
    )
    (tmp_path / "e.toml").write_text(text)
    terrain = load_terrain(tmp_path / "e.toml")
    np.testing.assert_allclose(
        terrain.raster(), f(x[:, None], y[None, :]).astype(np.float32), atol=1e-6, rtol=0
    )
    # Between samples the surface is the grid's triangles: linear along a cell edge.
    mid = terrain.height_at([x[10] + res / 2, y[7]])
    assert mid == pytest.approx(0.5 * (f(x[10], y[7]) + f(x[11], y[7])), abs=1e-12)

    # The same map as a 16-bit PNG (north up) with a height scale and a z offset.
    from PIL import Image

    counts = np.round((f(x[:, None], y[None, :]) + 0.3) / 1e-4).astype(np.uint16)  # [nx, ny]
    Image.fromarray(np.ascontiguousarray(counts.T[::-1])).save(tmp_path / "h.png")
    png = loads_terrain(
        text.replace('"h.npy"', '"h.png"').replace("[-1.0, -1.0, 0.0]", "[-1.0, -1.0, -0.3]")
        + "height_scale = 0.0001\n",
        path=str(tmp_path / "p.toml"),
    )
    np.testing.assert_allclose(png.raster(), (-0.3 + 1e-4 * counts).astype(np.float32), atol=1e-6, rtol=0)


def test_text_records_sources_and_detects_changes(tmp_path):
    terrain = _twin(loads_terrain(STEP), tmp_path)
    assert "[resolved]" in terrain.text and terrain.meshes[0].sha256 in terrain.text
    again = loads_terrain(terrain.text)  # from anywhere: base_dir is absolute
    np.testing.assert_array_equal(again.raster(), terrain.raster())
    assert again.text == terrain.text
    (tmp_path / "twin.stl").write_bytes((tmp_path / "twin.stl").read_bytes()[:-50] + bytes(50))
    with pytest.raises(TerrainError, match=r"mesh\[0\]\.file = \"twin\.stl\": .*SHA-256.*the file changed"):
        loads_terrain(terrain.text, source="<plan terrain>")
    v1 = (REPO / "terrains" / "eval_stairs.toml").read_text()
    assert load_terrain(REPO / "terrains" / "eval_stairs.toml").text == v1  # v1 unchanged


def _bad(tmp_path, entry: str, files: dict):
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
    path = tmp_path / "bad.toml"
    path.write_text(HEAD + entry)
    with pytest.raises(TerrainError) as err:
        load_terrain(path)
    message = str(err.value)
    assert message.startswith(str(path) + ": ") and "\n" not in message
    return message


def _stl(vertices, faces) -> bytes:
    return trimesh.Trimesh(vertices, faces, process=False).export(file_type="stl")


def test_bad_mesh_inputs(tmp_path, monkeypatch):
    good = _stl([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    cases = [
        ('[[mesh]]\nfile = "missing.stl"\n', {}, r'mesh\[0\]\.file = "missing\.stl": cannot read'),
        ('[[mesh]]\nfile = "dir.stl"\n', {}, r'mesh\[0\]\.file = "dir\.stl": cannot read'),
        (
            '[[mesh]]\nfile = "junk.obj"\n',
            {"junk.obj": b"\x00\x01garbage"},
            r"junk\.obj.*(not a readable|no triangle)",
        ),
        (
            '[[mesh]]\nfile = "empty.obj"\n',
            {"empty.obj": b"v 0 0 0\nv 1 0 0\n"},
            r"empty\.obj.*(no triangle|not a readable)",
        ),
        (
            '[[mesh]]\nfile = "nan.obj"\n',
            {"nan.obj": b"v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"},
            r"nan\.obj.*(nan or inf|not a readable)",
        ),
        (
            '[[mesh]]\nfile = "t.stl"\nscale = 0.0\n',
            {"t.stl": good},
            r"mesh\[0\]\.scale = 0\.0: must be non-zero",
        ),
        (
            '[[mesh]]\nfile = "t.stl"\nscale = [1.0, 0.0, 1.0]\n',
            {"t.stl": good},
            r"mesh\[0\]\.scale = \[1\.0, 0\.0, 1\.0\]",
        ),
        ('[[mesh]]\nfile = "t.dae"\n', {}, r"mesh\[0\]\.file = \"t\.dae\": unknown file type"),
        ('[[mesh]]\nfile = "hpp-environments:../x.stl"\n', {}, r"must be relative, without '\.\.'"),
        ('[[mesh]]\nfile = "t.stl"\ncolour = 1\n', {"t.stl": good}, r"mesh\[0\]\.colour = 1: unknown key"),
    ]
    (tmp_path / "dir.stl").mkdir()
    for entry, files, pattern in cases:
        message = _bad(tmp_path, entry, files)
        assert __import__("re").search(pattern, message), message
    huge = _stl([[0, 0, 0], [2, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    message = _bad(tmp_path, '[[mesh]]\nfile = "huge.stl"\nscale = 9000.0\n', {"huge.stl": huge})
    assert (
        'mesh[0].file ("huge.stl") largest world |coordinate| = 18000.0: must lie in [-10000, 10000]'
        in message
    )
    monkeypatch.setattr(terrain_sources, "MAX_TRIANGLES", 1)
    big = _stl([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2]])
    message = _bad(tmp_path, '[[mesh]]\nfile = "big.stl"\n', {"big.stl": big})
    assert "holds 2 triangles, over the bound of 1" in message
    monkeypatch.setattr(terrain_sources, "MAX_FILE_BYTES", 10)
    assert "exceeds the 10-byte bound" in _bad(tmp_path, '[[mesh]]\nfile = "t.stl"\n', {"t.stl": good})


def test_bad_elevation_inputs(tmp_path):
    from PIL import Image

    entry = '[elevation]\nfile = "{}"\norigin = [0.0, 0.0, 0.0]\nresolution = 0.1\n'
    np.save(tmp_path / "i64.npy", np.zeros((3, 3), dtype=np.int64))
    np.save(tmp_path / "nan.npy", np.array([[0.0, np.nan], [0.0, 0.0]]))
    np.save(tmp_path / "line.npy", np.zeros(5))
    Image.fromarray(np.zeros((4, 4), dtype=np.uint8)).save(tmp_path / "8bit.png")
    (tmp_path / "junk.png").write_bytes(b"not a png")
    for name, pattern in (
        ("i64.npy", r'elevation\.file = "i64\.npy": .*dtype int64'),
        ("nan.npy", r'elevation\.file = "nan\.npy": .*1 nan or inf samples'),
        ("line.npy", r"shape \[5\]"),
        ("8bit.png", r"mode L: use a 16-bit grayscale PNG"),
        ("junk.png", r"is not a readable PNG"),
    ):
        message = _bad(tmp_path, entry.format(name), {})
        assert __import__("re").search(pattern, message), message
    np.save(tmp_path / "ok.npy", np.zeros((3, 3)))
    message = _bad(tmp_path, entry.format("ok.npy").replace("0.1", "0.0"), {})
    assert "elevation.resolution = 0.0: must be > 0" in message


def test_exports_and_collision_objects(tmp_path):
    import mujoco

    from leas_jax.contacts.robot.collision import terrain_collision

    terrain = _twin(loads_terrain(STEP), tmp_path)
    mujoco.MjModel.from_xml_string(terrain_to_mjcf(terrain))
    for suffix in (".glb", ".stl", ".xml"):
        export_terrain(terrain, tmp_path / f"out{suffix}")
        assert (tmp_path / f"out{suffix}").stat().st_size > 0
    assert len(trimesh.load(tmp_path / "out.stl", force="mesh").faces) == len(terrain.meshes[0].faces)
    objects = terrain_collision(terrain)
    assert len(objects.shapes) >= 2 and np.all(objects.aabb[:, 0] <= objects.aabb[:, 1])
    lo = np.min(objects.aabb[:, 0], axis=0)
    hi = np.max(objects.aabb[:, 1], axis=0)
    np.testing.assert_allclose(lo, [-0.5, -0.5, -0.2], atol=1e-6)
    np.testing.assert_allclose(hi, [2.5, 1.5, 0.2], atol=1e-6)


@pytest.mark.parametrize("path", HPP_TERRAINS, ids=lambda p: p.stem)
def test_hpp_scenes_load_with_scenarios(path):
    terrain = load_terrain(path)
    assert terrain.meshes and terrain.meshes[0].source.startswith("hpp-environments:multicontact/")
    assert terrain.scenario is not None
    heights = terrain.height_at(
        np.concatenate([terrain.scenario.start_region, terrain.scenario.target[None]])
    )
    assert np.all(heights > terrain.void_height + 1.0)  # starts and target on the scene
    assert terrain.support_surfaces()


def test_verified_plan_on_an_hpp_scene(tmp_path):
    from leas_jax.contacts import plan_contacts, verify
    from leas_jax.contacts.robot.model import NOMINAL_ROOT_HEIGHT

    terrain = load_terrain(REPO / "terrains" / "hpp" / "bridge.toml")
    count = int(round(1.5 / 0.018)) + 1
    x = np.linspace(-2.0, -0.5, count)
    guide = np.stack([x, np.full(count, -0.65), np.full(count, NOMINAL_ROOT_HEIGHT), np.zeros(count)], axis=1)
    plan = plan_contacts(terrain, guide, 0.1)
    assert plan.coverage == 1.0
    assert "hpp-environments:multicontact/bridge.stl" in plan.terrain and "[resolved]" in plan.terrain
    report = verify(plan)  # re-parses plan.terrain: reads the scene again and checks its hash
    assert report.ok, str(report)
    from leas_jax.contacts.viewer import write_footsteps_png, write_html

    write_html(plan, tmp_path / "plan.html", robot=False)
    write_footsteps_png(plan, tmp_path / "plan.png")
    html = (tmp_path / "plan.html").read_text()
    assert len(html) > 10_000 and (tmp_path / "plan.png").stat().st_size > 10_000


def test_env_heightfield_and_cli_on_a_mesh_scene(tmp_path):
    from leas_jax.cli import main
    from leas_jax.env.field import heightfield_from_terrain

    path = REPO / "terrains" / "hpp" / "stairs.toml"
    field = heightfield_from_terrain(load_terrain(path))
    spawn = np.asarray(field.spawn_xy)
    assert len(spawn) > 100
    heights = load_terrain(path).height_at(spawn.astype(np.float64))
    assert np.all(heights > -1.0)  # spawn points lie on the scene, not over the void
    assert main(["terrain", "show", str(path), "--out", str(tmp_path / "s.png")]) in (0, None)
    assert main(["terrain", "export", str(path), "--out", str(tmp_path / "s.glb")]) in (0, None)
    assert len(trimesh.load(tmp_path / "s.glb", force="mesh").faces) == 36


def test_verify_checks_the_mesh_hash_of_a_given_terrain(tmp_path):
    from leas_jax.contacts import ContactPlan, verify

    terrain = _twin(loads_terrain(STEP), tmp_path)
    other = _twin(loads_terrain(STEP.replace("0.05]", "0.06]")), tmp_path, name="other")
    plan = ContactPlan(
        q=np.zeros((0, 39)),
        feet=np.zeros((0, 2, 4)),
        guide_index=np.zeros(0, dtype=np.int64),
        last_valid_index=-1,
        coverage=0.0,
        terrain=terrain.text,
        guide=np.zeros((2, 4)),
    )
    assert verify(plan, terrain).ok
    report = verify(plan, other)
    assert not report.ok and "terrain mesh[0] (other.stl): SHA-256" in str(report)
