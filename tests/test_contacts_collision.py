"""Collision geometry: NumPy placements vs Pinocchio, terrain and leg collisions with coal."""

import numpy as np
import pytest

from leas_jax.contacts.robot.collision import robot_collision, terrain_collision
from leas_jax.contacts.robot.model import FOOT_CLEARANCE, NOMINAL_ROOT_HEIGHT, load_talos, rotz
from leas_jax.terrain import loads_terrain

HEAD = 'name = "c"\nbounds = [[-2.0, -2.0], [2.0, 2.0]]\nvoid_height = -2.0\nresolution = 0.05\n'
GROUND = HEAD + "[[box]]\ncenter = [0.0, 0.0, -0.1]\nsize = [4.0, 4.0, 0.2]\n"


@pytest.fixture(scope="module")
def talos():
    return load_talos()


def _standing(talos, yaw=0.4, xy=(0.3, -0.2), dz=0.0):
    rot = rotz(yaw)
    legs = np.stack([talos.q_ref[leg.q_index] for leg in talos.legs])
    root = np.array([xy[0], xy[1], NOMINAL_ROOT_HEIGHT + dz])
    return rot, root, legs, talos.configuration(root, rot, legs)


def test_fast_placements_match_pinocchio(talos):
    robot = robot_collision(talos)
    rng = np.random.default_rng(0)
    for _ in range(5):
        rot, root, legs, _ = _standing(talos, yaw=rng.uniform(-3, 3))
        legs = legs + rng.normal(0, 0.2, size=legs.shape)
        for upper in talos.upper_refs:
            q = talos.configuration(root, rot, legs, upper)
            fast = robot.placements_fast(talos, rot, root, legs, upper)
            ref = robot.placements_pinocchio(talos, q)
            np.testing.assert_allclose(fast[0], ref[0], atol=1e-12)
            np.testing.assert_allclose(fast[1], ref[1], atol=1e-12)


def test_standing_on_ground_is_free_and_sinking_collides(talos):
    robot = robot_collision(talos)
    ground = terrain_collision(loads_terrain(GROUND))
    rot, root, legs, q = _standing(talos)
    placements = robot.placements_pinocchio(talos, q)
    assert robot.terrain_contacts(*placements, ground) == []
    assert robot.self_contacts(*placements) == []
    # 1 cm lower: the feet (raised by FOOT_CLEARANCE = 5 mm) enter the ground.
    _, _, _, q_low = _standing(talos, dz=-0.01)
    hits = robot.terrain_contacts(*robot.placements_pinocchio(talos, q_low), ground, first_only=False)
    assert {robot.names[g] for g, _ in hits} == {"leg_left_6_link_0", "leg_right_6_link_0"}
    assert FOOT_CLEARANCE == 0.005


def test_box_through_the_torso_collides(talos):
    robot = robot_collision(talos)
    # A 1 m wide bar at chest height across the robot (meshes are surfaces: the bar must
    # cut them, which any terrain obstacle larger than the robot does).
    terrain = loads_terrain(GROUND + "[[box]]\ncenter = [0.3, -0.2, 1.3]\nsize = [0.1, 1.0, 0.1]\n")
    objects = terrain_collision(terrain)
    assert terrain_collision(terrain) is objects  # cached per terrain
    _, _, _, q = _standing(talos)
    hits = robot.terrain_contacts(*robot.placements_pinocchio(talos, q), objects, first_only=False)
    assert hits and {b for _, b in hits} == {1}


def test_crossed_legs_collide(talos):
    robot = robot_collision(talos)
    rot, root, legs, _ = _standing(talos)
    legs[0, 1] = -0.5  # left hip roll inward
    legs[1, 1] = 0.5  # right hip roll inward: shins cross
    q = talos.configuration(root, rot, legs)
    hits = robot.self_contacts(*robot.placements_pinocchio(talos, q), first_only=False)
    assert any(
        robot.names[a].startswith("leg_left") and robot.names[b].startswith("leg_right") for a, b in hits
    )
