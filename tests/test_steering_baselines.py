"""RBLin and RBKino by hand: durations, bounds, rotation steps, goal reached at rest."""

import math

import numpy as np
import pytest

from leas_jax.env import EnvConfig, heightfield_from_terrain
from leas_jax.steering.baselines import BaselineConfig, heading_from_velocity
from leas_jax.steering.rbkino import fixed_time_profile, min_time, rbkino, rbkino_planar, steer
from leas_jax.steering.rblin import rblin, rblin_planar, rblin_through
from leas_jax.terrain import loads_terrain

FLAT = """name = "flat"
bounds = [[0.0, 0.0], [10.0, 6.0]]
void_height = -2.0
resolution = 0.05
[[box]]
center = [5.0, 3.0, -0.1]
size = [10.0, 6.0, 0.2]
"""
CONFIG = BaselineConfig()


@pytest.fixture(scope="module")
def field():
    return heightfield_from_terrain(loads_terrain(FLAT), EnvConfig())


def test_min_time_by_hand():
    # Rest to rest over 4 m, v_max 0.18, a_max 0.1: ramps of 1.8 s covering 0.162 m each,
    # cruise (4 - 0.324) / 0.18 = 20.422 s -> 1.8 + 20.422 + 1.8 = 24.0222 s.
    assert min_time(0.0, 4.0, 0.0, 0.0, 0.18, 0.1) == pytest.approx(24.02222, abs=1e-4)
    # Short move without reaching v_max: bang-bang, d = a t^2 (two halves) -> t = 2 sqrt(d / a).
    assert min_time(0.0, 0.1, 0.0, 0.0, 0.18, 0.1) == pytest.approx(2 * math.sqrt(1.0), abs=1e-9)
    # Moving away at 0.07 m/s from a goal 0 m away: stop (0.7 s, 0.0245 m), come back
    # bang-bang over 0.0245 m (2 sqrt(0.245) s) -> 0.7 + 0.98995 s.
    assert min_time(0.0, 0.0, -0.07, 0.0, 0.18, 0.1) == pytest.approx(0.7 + 2 * math.sqrt(0.245), abs=1e-6)


@pytest.mark.parametrize("sync", ["hpp", "cruise"])
def test_rbkino_reaches_goal_at_rest_within_bounds_and_slowest_axis_time(sync):
    rng = np.random.default_rng(3)
    for _ in range(200):
        p0, p1 = rng.uniform(-3, 3, 2), rng.uniform(-3, 3, 2)
        v0 = rng.uniform(-0.18, 0.18, 2)
        profile = steer(p0, v0, p1, np.zeros(2), 0.18, 0.1, sync=sync)
        slowest = max(min_time(p0[k], p1[k], v0[k], 0.0, 0.18, 0.1) for k in range(2))
        assert profile.duration == pytest.approx(slowest, abs=1e-9)
        t = np.linspace(0.0, profile.duration, 4001)
        pos, vel = profile.state(t)
        np.testing.assert_allclose(pos[0], p0, atol=1e-9)
        np.testing.assert_allclose(vel[0], v0, atol=1e-9)
        np.testing.assert_allclose(pos[-1], p1, atol=1e-7)
        np.testing.assert_allclose(vel[-1], 0.0, atol=1e-7)
        assert np.abs(vel).max() <= 0.18 + 1e-9
        assert np.abs(np.diff(vel, axis=0) / np.diff(t)[:, None]).max() <= 0.1 + 1e-6
        # Positions integrate the velocities (trapezoid rule on a fine grid).
        integral = p0 + np.concatenate(
            [np.zeros((1, 2)), np.cumsum(0.5 * (vel[1:] + vel[:-1]) * np.diff(t)[:, None], axis=0)]
        )
        np.testing.assert_allclose(integral, pos, atol=2e-5)


@pytest.mark.parametrize("sync", ["hpp", "cruise"])
def test_rbkino_synchronises_with_nonzero_end_velocity(sync):
    # v0 = v1 = 0.1 m/s and 5 cm to go: the slowest axis (y, 3 m) lasts ~17 s, during which
    # x cannot end 5 cm ahead at 0.1 m/s with |a| <= 0.1; steer lengthens the duration instead.
    profile = steer([0, 0], [0.1, 0.0], [0.05, 3.0], [0.1, 0.0], 0.18, 0.1, sync=sync)
    pos, vel = profile.state([profile.duration])
    np.testing.assert_allclose(pos[0], [0.05, 3.0], atol=1e-7)
    np.testing.assert_allclose(vel[0], [0.1, 0.0], atol=1e-7)


def test_fixed_time_profile_by_hand():
    # Rest to rest, 5 cm in 24 s: a triangle, T^2 a^2 - 4 d a = 0 -> a = 4 d / T^2, t1 = T / 2.
    t1, tc, t2, a1, vc, ok = fixed_time_profile(24.0, [0.05], [0.0], [0.0], 0.18, 0.1)
    assert ok[0] and a1[0] == pytest.approx(4 * 0.05 / 24.0**2) and t1[0] == pytest.approx(12.0)
    assert tc[0] == 0.0 and t2[0] == pytest.approx(12.0) and vc[0] == pytest.approx(a1[0] * 12.0)
    # 4 m in 30 s (minimum 24.02 s): the triangle would peak above v_max, so three segments
    # coasting at 0.18 m/s with a = 2 * 0.18^2 / (2 (0.18 * 30 - 4)) = 0.0231 m/s^2.
    t1, tc, t2, a1, vc, ok = fixed_time_profile(30.0, [4.0], [0.0], [0.0], 0.18, 0.1)
    a = 0.18**2 / (0.18 * 30.0 - 4.0)
    assert ok[0] and a1[0] == pytest.approx(a) and vc[0] == pytest.approx(0.18)
    np.testing.assert_allclose([t1[0], tc[0], t2[0]], [0.18 / a, 30.0 - 0.36 / a, 0.18 / a])


def test_rbkino_slowed_axis_decays_over_the_path_as_in_hpp():
    # Start 0.01 m/s across the goal direction (paper Table II, 90 degrees): x lasts the minimum
    # time T; y must end where it began, at rest, in T. HPP's eq. (20) with d = 0, v0 = 0.01,
    # v1 = 0: T^2 a^2 + 0.02 T a - 1e-4 = 0, larger root a = -0.01 (1 + sqrt 2) / T, so y decays
    # over the whole path (an a_max ramp would stop it within 0.1 s and turn the heading by
    # 90 degrees in one step).
    profile = steer([0.0, 0.0], [0.0, 0.01], [4.0, 0.0], [0.0, 0.0], 0.18, 0.1, sync="hpp")
    T = profile.duration
    assert T == pytest.approx(min_time(0.0, 4.0, 0.0, 0.0, 0.18, 0.1))
    a = -0.01 * (1 + math.sqrt(2)) / T
    assert profile.a1[1] == pytest.approx(a) and profile.a2[1] == pytest.approx(-a)
    assert profile.t1[1] == pytest.approx(0.5 * (-0.01 / a + T)) and profile.tc[1] == 0.0
    guide = rbkino_planar([0.0, 0.0, math.pi / 2], [4.0, 0.0], 0.01, CONFIG)
    # at t = 0.1 s: vx = 0.01, vy = 0.01 + 0.1 a -> heading ~44.7 degrees, not ~0
    assert guide[1, 2] == pytest.approx(math.atan2(0.01 + 0.1 * a, 0.01), abs=1e-9)
    assert math.degrees(guide[5, 2]) > 10.0
    cruise = rbkino_planar([0.0, 0.0, math.pi / 2], [4.0, 0.0], 0.01, BaselineConfig(rbkino_sync="cruise"))
    assert abs(math.degrees(cruise[1, 2])) < 1.0  # the former synchronisation: 90 degrees in 0.1 s
    with pytest.raises(ValueError, match="sync"):
        steer([0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [0.0, 0.0], 0.18, 0.1, sync="linear")


def test_rbkino_guide_heading_follows_velocity_and_ends_on_goal(field):
    guide = rbkino(field, [2.0, 3.0, 1.0, math.pi / 2], [6.0, 3.0], 0.04, CONFIG)
    assert guide.shape[1] == 4
    np.testing.assert_allclose(guide[-1, :2], [6.0, 3.0], atol=1e-7)
    np.testing.assert_allclose(guide[:, 2], 1.0, atol=1e-5)  # flat ground at z = 0, nominal height 1 m
    assert guide[0, 3] == pytest.approx(math.pi / 2)
    steps = np.diff(guide[:, :2], axis=0)
    moving = np.hypot(*steps.T) > 1e-4
    heading = np.arctan2(steps[moving, 1], steps[moving, 0])
    # yaw at the end of each step is the velocity direction, ~ the step direction
    err = (guide[1:, 3][moving] - heading + np.pi) % (2 * np.pi) - np.pi
    assert np.abs(err[5:]).max() < 0.2
    assert len(guide) == math.ceil(steer([2, 3], [0, 0.04], [6, 3], [0, 0], 0.18, 0.1).duration / 0.1) + 1


def test_heading_is_held_while_still():
    yaw = heading_from_velocity([[0, 0], [0, 0], [0.1, 0.1], [0, 0], [-0.1, 0.0]], 0.5)
    np.testing.assert_allclose(yaw[:4], [0.5, 0.5, math.pi / 4, math.pi / 4])
    assert yaw[4] == pytest.approx(math.pi)


def test_rblin_rotates_in_exactly_n_steps_then_walks_at_target_speed(field):
    config = BaselineConfig(rotation_steps=40)
    planar = rblin_planar([2.0, 3.0, math.pi], [6.0, 3.0], 0.0, config)
    # 1 start pose + 40 rotation poses + ceil(4 / 0.018) = 223 walking poses
    assert len(planar) == 1 + 40 + 223
    rotation = planar[1:41]
    np.testing.assert_allclose(rotation[:, :2], [[2.0, 3.0]] * 40)
    np.testing.assert_allclose(np.diff(planar[:41, 2]), -math.pi / 40)  # shortest turn, constant rate
    walk = planar[41:]
    np.testing.assert_allclose(np.hypot(*np.diff(planar[40:, :2], axis=0).T)[:-1], 0.018, atol=1e-12)
    np.testing.assert_allclose(walk[:, 2] % (2 * math.pi), 0.0, atol=1e-12)
    np.testing.assert_allclose(planar[-1, :2], [6.0, 3.0])
    guide = rblin(field, [2.0, 3.0, 1.0, math.pi], [6.0, 3.0], 0.0, config)
    np.testing.assert_allclose(guide[:, [0, 1, 3]], planar)
    np.testing.assert_allclose(guide[:, 2], 1.0, atol=1e-5)


def test_rblin_brakes_from_initial_speed_along_heading():
    planar = rblin_planar([2.0, 3.0, 0.0], [2.0, 5.0], 0.07, CONFIG)
    # 0.07 m/s at 0.1 m/s^2 stops in 0.7 s = 7 steps, covering 0.07^2 / 0.2 = 0.0245 m along +x.
    np.testing.assert_allclose(planar[7, :2], [2.0245, 3.0], atol=1e-12)
    np.testing.assert_allclose(planar[1:8, 2], 0.0)
    np.testing.assert_allclose(
        planar[8 + 99, 2], math.atan2(2.0, -0.0245), atol=1e-9
    )  # after 100 rotation steps
    assert len(rblin_planar([2.0, 3.0, 0.0], [2.0, 5.0], 0.07, CONFIG, brake=False)) == len(planar) - 7


def test_rblin_through_waypoints_visits_each(field):
    guide = rblin_through(
        field, [1.0, 1.0, 1.0, 0.0], [[3.0, 1.0], [3.0, 3.0]], 0.0, BaselineConfig(rotation_steps=10)
    )
    for point in ([3.0, 1.0], [3.0, 3.0]):
        assert np.hypot(*(guide[:, :2] - point).T).min() < 1e-9
    np.testing.assert_allclose(guide[-1, :2], [3.0, 3.0])
