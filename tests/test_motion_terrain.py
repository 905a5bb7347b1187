"""Physics scenes of mesh terrains: MuJoCo collides a mesh through its convex hull, so a mesh
terrain's collision surface is raster boxes of its heights (leas_jax.motion.robot.terrain_scene)."""

import numpy as np
import pytest

from leas_jax.motion.robot import raster_boxes, terrain_scene
from leas_jax.terrain import load_terrain


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

    mj = terrain_scene(stairs, 0.001)
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
