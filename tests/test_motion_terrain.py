"""Physics scenes of mesh terrains: MuJoCo collides a mesh through its convex hull, so a mesh
terrain's collision surface is convex columns under its faces or raster boxes of its heights
(leas_jax.motion.robot.physics_terrain_mjcf), and the friction solver holds a sole on a slope."""

import math

import numpy as np
import pytest

from leas_jax.contacts.robot.model import FRICTION, SOLE_LENGTH, SOLE_WIDTH
from leas_jax.motion.config import SimulationConfig
from leas_jax.motion.robot import (
    physics_terrain_mjcf,
    raster_boxes,
    set_friction_solver,
    surface_columns,
    terrain_scene,
)
from leas_jax.terrain import load_terrain
from leas_jax.terrain.mesh import TerrainMesh
from leas_jax.terrain.model import Terrain

SLOPE = math.radians(15.0)


def ramp(slope: float = SLOPE, quads: int = 4) -> Terrain:
    """A 1 x 1 m mesh ramp rising along x at `slope` (0.3 m high at x = 0), as quads x quads pairs of triangles."""
    axis = np.linspace(-0.5, 0.5, quads + 1)
    vertices = np.array([[x, y, 0.3 + x * math.tan(slope)] for y in axis for x in axis])
    faces = []
    for j in range(quads):
        for i in range(quads):
            a = j * (quads + 1) + i
            faces += [[a, a + 1, a + quads + 2], [a, a + quads + 2, a + quads + 1]]
    mesh = TerrainMesh("mesh[0]", vertices, np.array(faces), "0" * 64, "ramp.stl")
    bounds = np.array([[-0.5, -0.5], [0.5, 0.5]])
    return Terrain(name="ramp", bounds=bounds, void_height=-1.0, resolution=0.02, boxes=(), meshes=(mesh,))


def ray_heights(mjcf: str, points: np.ndarray, void_height: float) -> np.ndarray:
    """Heights where vertical rays from 5 m meet a MuJoCo scene's geoms, [N] (`void_height` where none)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(mjcf)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geom = np.zeros(1, np.int32)
    down = np.array([0.0, 0.0, -1.0])
    distance = np.array(
        [mujoco.mj_ray(model, data, np.r_[xy, 5.0], down, None, 1, -1, geom) for xy in points]
    )
    return np.where(distance < 0.0, void_height, 5.0 - distance)


@pytest.fixture(scope="module")
def stairs():
    return load_terrain("terrains/hpp/demos/talos_stairs10.toml")


def test_raster_boxes_reproduce_the_heights(stairs):
    boxes = raster_boxes(stairs)
    assert 5 < len(boxes) < 200  # equal-height cells merge: a floor, steps, a platform
    lo = np.array([b[0] for b in boxes])
    hi = np.array([b[1] for b in boxes])
    assert (hi > lo).all() and np.allclose(lo[:, 2], stairs.void_height)
    rng = np.random.default_rng(0)
    (x0, y0), (x1, y1) = stairs.bounds
    points = np.c_[rng.uniform(x0 + 0.05, x1 - 0.05, 400), rng.uniform(y0 + 0.05, y1 - 0.05, 400)]
    inside = (points[:, None, :] >= lo[None, :, :2]) & (points[:, None, :] <= hi[None, :, :2])
    top = np.where(inside.all(axis=2), hi[None, :, 2], stairs.void_height).max(axis=1)
    exact = stairs.height_at(points)
    # a cell's top is the height at its centre: off only within a cell of an edge
    near_edge = np.abs(top - exact) > 1e-3
    assert near_edge.mean() < 0.1 and (exact > 0.5).any() and (exact < 0.01).any()


def test_mesh_terrain_scene_collides_with_boxes_only(stairs):
    import mujoco

    mj = terrain_scene(stairs, 0.001, "raster")
    model = mj.model
    robot = set(mj.robot_geoms.tolist())
    terrain = [g for g in range(model.ngeom) if g not in robot and model.geom_bodyid[g] == 0]
    assert terrain and all(model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX for g in terrain)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    # a vertical ray meets the raster at the staircase's height, not at its convex hull's
    for xy in ([0.34, 0.18], [-1.61, -0.06], [3.0, 3.0]):
        geom = np.zeros(1, np.int32)
        distance = mujoco.mj_ray(model, data, np.r_[xy, 5.0], np.array([0.0, 0.0, -1.0]), None, 1, -1, geom)
        assert 5.0 - distance == pytest.approx(float(stairs.height_at(np.array(xy))), abs=2e-3)


def test_columns_reproduce_the_heights_of_a_mesh_terrain(stairs):
    rng = np.random.default_rng(1)
    (x0, y0), (x1, y1) = stairs.bounds
    points = np.c_[rng.uniform(x0 + 0.05, x1 - 0.05, 400), rng.uniform(y0 + 0.05, y1 - 0.05, 400)]
    heights = ray_heights(physics_terrain_mjcf(stairs, "columns"), points, stairs.void_height)
    exact = stairs.height_at(points)
    # exact wherever the terrain has a face, and the void where it has none
    assert np.abs(heights - exact).max() < 1e-4
    assert (exact > 0.5).any() and (exact < 0.01).any() and (exact == stairs.void_height).any()


def test_columns_keep_a_tilted_face_a_plane_where_the_raster_makes_steps():
    terrain = ramp()
    columns = surface_columns(terrain)
    assert len(columns) < 8  # the ramp's coplanar triangles merge into few convex pieces
    assert all(np.allclose(c[len(c) // 2 :, 2], terrain.void_height) for c in columns)
    rng = np.random.default_rng(2)
    points = rng.uniform(-0.45, 0.45, (300, 2))
    plane = 0.3 + points[:, 0] * math.tan(SLOPE)
    assert (
        np.abs(
            ray_heights(physics_terrain_mjcf(terrain, "columns"), points, terrain.void_height) - plane
        ).max()
        < 1e-5
    )
    # the raster's cells are flat: up to half a cell's rise (2.7 mm at 2 cm) off the face
    assert (
        np.abs(
            ray_heights(physics_terrain_mjcf(terrain, "raster"), points, terrain.void_height) - plane
        ).max()
        > 2e-3
    )


def sole_push_slip(mesh_contact: str, cone: str, impratio: float) -> float:
    """How far, m, a 45 kg sole-sized box standing on `ramp()` slides in 2 s of a +-150 N push
    along the slope (a stance leg's tangential load), after 0.2 s of settling."""
    import mujoco

    spec = mujoco.MjSpec.from_string(physics_terrain_mjcf(ramp(), mesh_contact))
    for geom in spec.geoms:
        geom.friction = [FRICTION, 0.005, 0.0001]
    x = 0.03
    height = 0.3 + x * math.tan(SLOPE) + 0.02 / math.cos(SLOPE) + 0.003
    body = spec.worldbody.add_body(pos=[x, 0.01, height], euler=[0.0, -15.0, 0.0])
    body.add_freejoint()
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[SOLE_LENGTH / 2, SOLE_WIDTH / 2, 0.02], mass=45.0)
    model = spec.compile()
    set_friction_solver(model, cone, impratio)
    model.opt.noslip_iterations = SimulationConfig().noslip_iterations
    data = mujoco.MjData(model)
    for _ in range(200):
        mujoco.mj_step(model, data)
    settled = data.qpos[:2].copy()
    for k in range(2000):
        data.xfrc_applied[1, 0] = 150.0 * math.sin(2.0 * math.pi * 1.5 * k * model.opt.timestep)
        mujoco.mj_step(model, data)
    return float(np.linalg.norm(data.qpos[:2] - settled))


def test_a_pushed_sole_holds_on_a_slope_with_the_default_friction_solver():
    config = SimulationConfig()
    # 0.2 mm in 2 s; with MuJoCo's default impedance ratio the same sole creeps 2.1 mm, its
    # load within the friction cone
    assert sole_push_slip(config.mesh_contact, config.cone, config.impratio) < 5e-4
    assert sole_push_slip("columns", "pyramidal", 1.0) > 1.5e-3


def test_bad_physics_settings_are_named():
    import mujoco

    model = mujoco.MjModel.from_xml_string("<mujoco/>")
    with pytest.raises(ValueError, match="cone"):
        set_friction_solver(model, "conical", 10.0)
    with pytest.raises(ValueError, match="impratio"):
        set_friction_solver(model, "elliptic", 0.0)
    with pytest.raises(ValueError, match="mesh_contact"):
        physics_terrain_mjcf(ramp(), "heightfield")
