"""Collisions and clearance along a motion: BodyClearance, the swing path's bulge and the arms' change."""

import numpy as np
import pytest

from leas_jax.contacts.robot.clearance import BodyClearance
from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion import motion
from leas_jax.motion.config import MotionConfig
from leas_jax.motion.paths import HELD_BULGES, LAND_WINDOWS, LIFT_WINDOWS, swing_path
from leas_jax.terrain import loads_terrain

FLOOR = """
name = "floor"
bounds = [[-2.0, -2.0], [2.0, 2.0]]
void_height = -2.0
resolution = 0.02

[[box]]
center = [0.0, 0.0, -0.3]
size = [4.0, 4.0, 0.6]
"""


def _beam(x: float) -> str:
    """A beam 0.3-0.6 m above the floor's plane, at knee height, whose near face is at x, m
    (in front of the robot, above its feet), alone: the distances are to it."""
    lines = FLOOR.split("[[box]]")[0]
    return lines + f"[[box]]\ncenter = [{x + 0.05}, 0.0, 0.45]\nsize = [0.1, 1.0, 0.3]\n"


@pytest.fixture(scope="module")
def talos():
    return load_talos()


@pytest.fixture(scope="module")
def standing(talos):
    """Half-sitting with both soles on the floor (z = 0), facing +x."""
    q = talos.q_ref.copy()
    q[2] -= talos.sole_placements(q)[:, 2].mean()
    return q


def test_a_standing_posture_is_clear_and_a_sunken_one_collides(talos, standing):
    clearance = BodyClearance(talos, loads_terrain(FLOOR))
    assert clearance.collisions(standing) is None
    assert clearance.too_close(standing, 0.05) is None  # the feet rest on the floor, nothing else is near
    sunk = standing.copy()
    sunk[2] -= 0.05
    assert "collides with terrain box 0" in clearance.collisions(sunk)
    assert clearance.first_too_close(np.stack([standing, standing, sunk]), 0.01)[0] == 2


def test_a_beam_in_front_of_the_knees_is_too_close_before_it_collides(talos, standing):
    """A beam 2 mm in front of the knees collides with nothing, is within a 1 cm margin, and
    its distance is that gap."""
    front = 1.0 - BodyClearance(talos, loads_terrain(_beam(1.0))).distance(standing, 1.5)
    assert 0.0 < front < 0.3  # the knees' front, m ahead of the root
    near = BodyClearance(talos, loads_terrain(_beam(front + 0.002)))
    assert near.collisions(standing) is None
    assert abs(near.distance(standing, 0.05) - 0.002) < 1e-4
    assert "comes within 1 cm of terrain box 0" in near.too_close(standing, 0.01)
    assert near.too_close(standing, 0.001) is None


def test_the_swing_path_bulges_away_at_mid_travel_and_not_at_its_ends():
    start, end = np.array([0.0, 0.1, 0.0]), np.array([0.3, 0.1, 0.0])
    t = np.linspace(0.0, 1.0, 401)
    plain = swing_path(start, end, 0.05, t, LAND_WINDOWS)
    bulged = swing_path(start, end, 0.05, t, LAND_WINDOWS, 0.04, np.array([0.0, 1.0]))
    side = bulged[:, 1] - plain[:, 1]
    np.testing.assert_allclose(bulged[:, [0, 2]], plain[:, [0, 2]])
    assert side[0] == side[-1] == 0.0 and abs(side.max() - 0.04) < 1e-4 and side.min() >= 0.0
    velocity = np.diff(side) / np.diff(t)
    assert abs(velocity[0]) < 1e-3 and abs(velocity[-1]) < 1e-3


@pytest.mark.parametrize("kind, windows", [("lift", LIFT_WINDOWS), ("land", LAND_WINDOWS)])
def test_a_held_bulge_is_out_while_the_legs_pass_within_its_acceleration(kind, windows):
    """Held out over the middle of the phase (where a bump has come back), at rest at both
    ends, and over `bulge_samples` its sideways acceleration stays within the config's."""
    config = MotionConfig()
    samples = motion.bulge_samples(kind, 0.07, config)
    t = np.arange(samples + 1) / samples
    start, end = np.array([0.0, 0.1, 0.0]), np.array([0.3, 0.1, 0.0])
    plain = swing_path(start, end, 0.1, t, windows)
    bump = swing_path(start, end, 0.1, t, windows, 0.07, np.array([0.0, 1.0]))[:, 1] - plain[:, 1]
    held = (
        swing_path(start, end, 0.1, t, windows, 0.07, np.array([0.0, 1.0]), HELD_BULGES[kind])[:, 1]
        - plain[:, 1]
    )
    out, back = HELD_BULGES[kind]
    between = (t >= out[1]) & (t <= back[0])
    np.testing.assert_allclose(held[between], 0.07)
    assert held[0] == 0.0 and abs(held[-1]) < 1e-12 and held.min() >= 0.0
    assert (held[between] > bump[between] + 0.03).any()  # out where the bump is (nearly) back
    acceleration = np.diff(held, 2) / config.dt**2
    assert np.abs(acceleration).max() <= config.bulge_acceleration * 1.01
    faster = motion.bulge_samples(kind, 0.07, MotionConfig(bulge_acceleration=4 * config.bulge_acceleration))
    assert abs(faster - samples / 2) <= 1  # duration scales with acceleration^-1/2


def test_the_bulge_points_away_from_the_stance_sole():
    feet = np.repeat(np.eye(4)[None], 2, axis=0)
    feet[1, :3, 3] = [0.0, -0.2, 0.0]  # right stance sole
    landed = feet.copy()
    landed[0, :3, 3] = [0.3, 0.0, 0.0]  # the left sole travels along +x, left of the stance
    spec = motion._PhaseSpec(
        "land", (0, 1), 0, 80, feet, landed, None, None, np.eye(3), np.eye(3), None, None, 0.05
    )
    np.testing.assert_allclose(motion.away_from_stance(spec), [0.0, 1.0])
    feet[1, :3, 3] = [0.0, 0.2, 0.0]  # stance on the other side: the bulge turns
    np.testing.assert_allclose(motion.away_from_stance(spec), [0.0, -1.0])


class _Corridor:
    """A stand-in for BodyClearance in one dimension: the root's x is q[0], the arms' state
    q[UPPER_BODY] (0: half-sitting, 1: held in). Arms held out collide from x = 3 on (a wall),
    and arms on their way between the two from x = 2 on."""

    def collisions(self, q):
        x, arms = q[0], q[motion.UPPER_BODY]
        if arms < 1.0 and x >= 3.0:
            return "arm collides with the wall"
        if 0.0 < arms < 1.0 and x >= 2.0:
            return "arm on its way collides with the wall"
        return None


def _keys(arms: list) -> np.ndarray:
    keys = np.zeros((len(arms), 39))
    keys[:, 0] = np.arange(len(arms))
    keys[:, motion.UPPER_BODY :] = np.array(arms, dtype=float)[:, None]
    return keys


def test_the_arms_change_where_their_way_is_clear():
    corridor = _Corridor()
    keys = _keys([0, 0, 0, 1, 1])
    assert motion.upper_body_window(corridor, keys[1], keys[2]) == (0.0, 1.0)  # no change
    assert motion.upper_body_window(corridor, keys[2], keys[3]) is None  # blocked both ways
    tucked, changed = motion.tucked_arms(keys, corridor)
    assert changed == [2]
    np.testing.assert_array_equal(tucked[:, motion.UPPER_BODY], [0, 0, 1, 1, 1])
    assert motion.upper_body_window(corridor, tucked[1], tucked[2]) == (0.0, motion.UPPER_BODY_SPLIT)
    # arms held in until x = 3, out after: the change moves later, out of the corridor's way
    keys = _keys([1, 1, 0, 0, 0])
    keys[:, 0] = [4, 3, 2, 1, 0]  # walking out of the corridor
    assert motion.upper_body_window(corridor, keys[1], keys[2]) is None  # half-sitting at x = 3 collides
    tucked, changed = motion.tucked_arms(keys, corridor)
    assert changed == [2]
    np.testing.assert_array_equal(tucked[:, motion.UPPER_BODY], [1, 1, 1, 0, 0])
    assert motion.upper_body_window(corridor, tucked[2], tucked[3]) == (1.0 - motion.UPPER_BODY_SPLIT, 1.0)
