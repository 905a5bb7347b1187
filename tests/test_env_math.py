"""Hand-computed cases for the pure functions of the environment."""

import dataclasses
import math

import jax.numpy as jnp
import numpy as np
import pytest

from leas_jax.env import EnvConfig, heightfield_from_raster, heightmap, kinematics, reachability, reward
from leas_jax.env.field import (
    disk_filter,
    sample_bilinear,
    sample_bilinear_xy,
    sample_nearest,
    sample_nearest_xy,
)

RES = 0.02
CFG = EnvConfig()


def flat(size_m=10.0, height=0.0):
    n = int(round(size_m / RES)) + 1
    return np.full((n, n), height, np.float32)


def field_of(heights, require_spawn=True):
    return heightfield_from_raster(heights, (0.0, 0.0), RES, -2.0, CFG, require_spawn=require_spawn)


def cell(x):
    return int(round(x / RES))


# -- kinematics -------------------------------------------------------------


def test_integrate_one_step_by_hand():
    pos, vel, yaw = jnp.array([0.0, 0.0, 1.0]), jnp.array([0.1, 0.0, 0.0]), jnp.array(0.0)
    accel, omega = kinematics.scale_action(jnp.array([1.0, 0.0, 0.0, 0.5]), yaw, CFG)
    new_pos, new_vel, new_yaw = kinematics.integrate(pos, vel, yaw, accel, omega, CFG)
    # (1) pos = 0 + 0.1 * 0.1 = 0.01; (2) vel = 0.1 + 0.1 * 0.1 = 0.11; (3) yaw = 0.5 * pi/9 * 0.1
    np.testing.assert_allclose(new_pos, [0.01, 0.0, 1.0], atol=1e-7)
    np.testing.assert_allclose(new_vel, [0.11, 0.0, 0.0], atol=1e-7)
    np.testing.assert_allclose(new_yaw, 0.5 * math.pi / 9 * 0.1, atol=1e-7)


def test_velocity_norm_is_clipped_at_v_max():
    vel = jnp.array([0.3, 0.0, 0.0])
    _, new_vel, _ = kinematics.integrate(
        jnp.zeros(3), vel, jnp.array(0.0), jnp.array([0.1, 0.1, 0.0]), jnp.array(0.0), CFG
    )
    # 0.3 + 0.01 along x, 0.01 along y -> norm > 0.3, rescaled to exactly 0.3
    assert float(jnp.linalg.norm(new_vel)) == pytest.approx(0.30, abs=1e-6)
    assert float(new_vel[1] / new_vel[0]) == pytest.approx(0.01 / 0.31, rel=1e-5)


def test_actions_accelerate_in_the_root_frame_and_are_clipped():
    accel, omega = kinematics.scale_action(jnp.array([2.0, 0.0, -0.5, -3.0]), jnp.array(math.pi / 2), CFG)
    # a_x clipped to 1 -> 0.1 m/s^2 along the heading (+y at yaw 90 deg); a_z = -0.05; omega = -pi/9
    np.testing.assert_allclose(accel, [0.0, 0.1, -0.05], atol=1e-7)
    assert float(omega) == pytest.approx(-math.pi / 9)


def test_vertical_acceleration_has_its_own_bound():
    import dataclasses

    config = dataclasses.replace(CFG, vertical_a_max=3.0)
    accel, _ = kinematics.scale_action(jnp.array([1.0, -0.5, -0.5, 0.0]), jnp.array(0.0), config)
    # x, y keep a_max = 0.1 m/s^2 per action unit; z: 3.0 m/s^2 per unit (HPP's verticalAccelerationBound)
    np.testing.assert_allclose(accel, [0.1, -0.05, -1.5], atol=1e-6)
    _, new_vel, _ = kinematics.integrate(
        jnp.zeros(3), jnp.zeros(3), jnp.array(0.0), accel, jnp.array(0.0), config
    )
    np.testing.assert_allclose(new_vel, [0.01, -0.005, -0.15], atol=1e-6)


def test_yaw_wraps_to_minus_pi_pi():
    assert float(kinematics.wrap_angle(jnp.array(3 * math.pi / 2))) == pytest.approx(-math.pi / 2)


# -- heightfield sampling ----------------------------------------------------


def test_bilinear_is_exact_on_a_plane_and_void_outside():
    n = 101
    x = np.arange(n) * RES
    heights = (0.2 * x[:, None] + 0.1 * x[None, :]).astype(np.float32)  # plane z = 0.2 x + 0.1 y
    field = field_of(heights)
    pts = jnp.array([[0.513, 1.007], [1.333, 0.25], [5.0, 1.0]])
    got = sample_bilinear(field, pts)
    np.testing.assert_allclose(got[:2], [0.2 * 0.513 + 0.1 * 1.007, 0.2 * 1.333 + 0.1 * 0.25], atol=1e-5)
    assert float(got[2]) == -2.0  # beyond the 2 m grid: void


def test_disk_filter_matches_brute_force():
    rng = np.random.default_rng(0)
    heights = rng.normal(size=(40, 30)).astype(np.float32)
    r = 4.3
    got_max = disk_filter(heights, r, "max", -9.0)
    got_min = disk_filter(heights, r, "min", 9.0)
    ii, jj = np.meshgrid(np.arange(40), np.arange(30), indexing="ij")
    for i, j in [(0, 0), (5, 7), (39, 29), (20, 3)]:
        inside = (ii - i) ** 2 + (jj - j) ** 2 <= r * r
        # cells of the disk beyond the raster count as the fill value
        full_disk = sum(1 for di in range(-4, 5) for dj in range(-4, 5) if di * di + dj * dj <= r * r)
        pad_max = -9.0 if inside.sum() < full_disk else -np.inf
        pad_min = 9.0 if inside.sum() < full_disk else np.inf
        assert got_max[i, j] == pytest.approx(max(heights[inside].max(), pad_max))
        assert got_min[i, j] == pytest.approx(min(heights[inside].min(), pad_min))


# -- heightmap ---------------------------------------------------------------


def test_heightmap_grid_matches_the_paper():
    offsets = heightmap.grid_offsets()
    assert offsets.shape == (77, 2)
    xs = sorted(set(np.round(offsets[:, 0], 4)))
    ys = sorted(set(np.round(offsets[:, 1], 4)))
    # 9 points ahead every 8 cm, 2 behind every 20 cm, 7 columns every 15 cm
    assert xs == pytest.approx([-0.4, -0.2] + [0.08 * k for k in range(1, 10)])
    assert ys == pytest.approx([0.15 * j for j in range(-3, 4)])


def test_heightmap_flat_step_and_clipping():
    heights = flat()
    heights[cell(5.3) :, :] = 0.3  # a 0.3 m step starting at x = 5.3
    heights[:, cell(6.0) :] = 2.0  # a tall wall from y = 6.0 (clipped at -0.2)
    field = field_of(heights)
    hmap = np.asarray(heightmap.sample(field, jnp.array([5.0, 5.0, 1.0, 0.0]))).reshape(11, 7)
    # rows: x = 0.72 ... 0.08 ahead (rows 0..8), then -0.2, -0.4; points with x >= 5.3 see 0.3 - 1.0
    ahead_x = 5.0 + 0.08 * np.arange(9, 0, -1)
    expected_rows = np.where(ahead_x > 5.3 + RES, -0.7, np.where(ahead_x < 5.3 - RES, -1.0, np.nan))
    for row, value in enumerate(expected_rows):
        if not np.isnan(value):
            np.testing.assert_allclose(hmap[row, :], value, atol=1e-5)
    np.testing.assert_allclose(hmap[9:, :], -1.0, atol=1e-5)
    # turned to face +y at y = 5.7: points ahead beyond y = 6.0 see the wall, clipped to -0.2
    hmap_wall = np.asarray(heightmap.sample(field, jnp.array([3.0, 5.7, 1.0, math.pi / 2]))).reshape(11, 7)
    assert hmap_wall[0, 3] == pytest.approx(-0.2)  # 0.72 m ahead: y = 6.42
    void = field_of(np.full((11, 11), -2.0, np.float32), require_spawn=False)
    assert float(heightmap.sample(void, jnp.array([0.1, 0.1, 1.0, 0.0]))[0]) == pytest.approx(-1.4)


# -- reachability ------------------------------------------------------------


def pose(x, y, z, yaw=0.0):
    return jnp.array([x, y, z, yaw])


@pytest.fixture(scope="module")
def scene():
    """10 x 10 m: ground at 0; a 2 x 2 m hole; a 1.5 m wall; a 0.30 m bridge over void."""
    heights = flat()
    heights[cell(6.0) : cell(8.0), cell(1.0) : cell(3.0)] = -2.0  # hole x 6-8, y 1-3
    heights[cell(1.0) : cell(1.2), cell(5.0) : cell(9.0)] = 1.5  # wall x 1.0-1.2, y 5-9
    heights[cell(5.0) : cell(9.0), cell(5.0) : cell(9.5)] = -2.0  # void x 5-9, y 5-9.5 ...
    heights[cell(5.0) : cell(9.0), cell(6.85) : cell(7.15) + 1] = 0.0  # ... crossed by a bridge y 6.85-7.15
    return field_of(heights)


@pytest.mark.parametrize(
    "case, p, expected",
    [
        ("flat ground at 1.0 m", pose(3.0, 2.0, 1.0), True),
        ("too high above the ground", pose(3.0, 2.0, 1.7), False),
        ("too low: trunk in the ground", pose(3.0, 2.0, 0.5), False),
        ("over the middle of a hole", pose(7.0, 2.0, 1.0), False),
        ("sunk into the hole, 1 m above the void: the void is no floor", pose(7.0, 2.0, -1.0), False),
        ("beyond the terrain border", pose(10.6, 5.0, 1.0), False),
        ("beside a wall, 0.2 m away", pose(1.4, 7.0, 1.0), False),
        ("0.5 m from the wall", pose(1.7, 7.0, 1.0), True),
        ("on the bridge, facing along it", pose(7.0, 7.0, 1.0, 0.0), True),
        ("beside the bridge over the void", pose(7.0, 7.6, 1.0, 0.0), False),
    ],
)
def test_reachability_cases(scene, case, p, expected):
    assert bool(reachability.valid(scene, p)) is expected, case


def test_reachability_terms_name_the_failure(scene):
    high = reachability.terms(scene, pose(3.0, 2.0, 1.7))
    assert bool(high["trunk_free"]) and not bool(high["left_touch"]) and not bool(high["right_touch"])
    low = reachability.terms(scene, pose(3.0, 2.0, 0.4))  # the default trunk reaches 0.475 m below the root
    assert not bool(low["trunk_free"]) and not bool(low["left_touch"])


def test_clearance_shortfall_counts_the_probes_that_fail(scene):
    """With the presets' condition (TRAINING_REACHABILITY: the cylinders alone, the trunk from
    0.825 m below the root). The wall's last raster column is x = 1.18: at x = 1.50 the trunk
    disk (r 0.30) is 0.32 m from it, free; shifted 0.05 m towards the wall it is 0.27 m from it.
    One of the six probes fails, whichever way the root faces; in the open, none at 0.05 m;
    beside the wall too close, the pose itself fails and so do most probes."""
    from leas_jax.training.config import TRAINING_REACHABILITY as reach

    for yaw in (0.0, math.pi):
        p = pose(1.50, 7.0, 1.0, yaw)
        assert bool(reachability.valid(scene, p, reach))
        assert float(reachability.clearance_shortfall(scene, p, 0.05, reach)) == pytest.approx(1.0 / 6.0)
    assert float(reachability.clearance_shortfall(scene, pose(3.0, 2.0, 1.0), 0.05, reach)) == 0.0
    # 0.2 m up, the legs (down to 1.175 m below the root) miss the ground; 0.2 m down, the
    # trunk (from 0.825 m below the root) enters it
    assert float(reachability.clearance_shortfall(scene, pose(3.0, 2.0, 1.0), 0.2, reach)) == pytest.approx(
        2.0 / 6.0
    )
    assert float(reachability.clearance_shortfall(scene, pose(1.40, 7.0, 1.0), 0.05, reach)) >= 0.5


def test_leg_cylinders_turn_with_the_yaw():
    centers = reachability.leg_centers(pose(1.0, 1.0, 1.0, math.pi / 2))
    np.testing.assert_allclose(centers, [[1.0 - 0.085, 1.0], [1.0 + 0.085, 1.0]], atol=1e-6)


def test_nearest_sampling_of_rasters():
    heights = flat(1.0)
    heights[cell(0.5), cell(0.5)] = 1.0
    field = field_of(heights, require_spawn=False)  # 1 m wide: the hands and lookahead reach past it
    assert float(sample_nearest(field, field.heights, jnp.array([0.505, 0.495]))) == 1.0
    assert float(sample_nearest(field, field.heights, jnp.array([-0.5, 0.5]))) == -2.0


def test_world_xy_and_the_column_samplers_agree_with_the_stacked_forms():
    rng = np.random.default_rng(1)
    n = 101
    heights = rng.uniform(-0.5, 0.5, (n, n)).astype(np.float32)
    field = field_of(heights, require_spawn=False)
    offsets = jnp.asarray(rng.uniform(-0.6, 0.6, (40, 2)), jnp.float32)
    for p in (pose(1.0, 1.2, 0.9, 0.7), pose(0.1, 1.9, 0.9, -2.5)):  # the second reaches past the grid
        x, y = kinematics.world_xy(p, offsets)
        stacked = p[:2] + kinematics.rotate_z(offsets, p[3])
        np.testing.assert_allclose(np.stack([x, y], -1), stacked, atol=1e-6)
        assert x.shape == y.shape == (40,)
        np.testing.assert_array_equal(
            sample_nearest_xy(field, field.heights, x, y, outside=7.0),
            sample_nearest(field, field.heights, stacked, outside=7.0),
        )
        np.testing.assert_allclose(
            sample_bilinear_xy(field, x, y), sample_bilinear(field, stacked), atol=1e-6
        )
    assert bool(jnp.any(sample_nearest_xy(field, field.heights, x, y, outside=7.0) == 7.0))


# -- reward ------------------------------------------------------------------


def test_reward_terms_by_hand():
    target = jnp.array([1.0, 0.0])
    field = field_of(flat(height=0.0))
    pose = jnp.array([5.0, 5.0, 1.0, 0.0])
    at_speed = reward.terms(field, pose, jnp.array([0.18, 0.0, 0.0]), jnp.zeros(4), target, CFG)
    assert tuple(at_speed) == reward.NAMES  # every weight has its term, in the weights' order
    assert float(at_speed["direction"]) == pytest.approx(0.0, abs=1e-7)
    assert float(at_speed["orientation"]) == pytest.approx(0.0, abs=1e-7)
    assert float(reward.total(at_speed, CFG)) == pytest.approx(1.0)  # only alive, weight 1
    # standing still, facing +y, full actions: direction -(0.18/0.6)^2 = -0.09, orientation -(1 - 0) = -1,
    # effort_ori -(1)^2, effort_acc -(sqrt(1+1+0))^2 = -2
    facing_y = pose.at[3].set(math.pi / 2)
    t = reward.terms(field, facing_y, jnp.zeros(3), jnp.array([1.0, 1.0, 0.0, -1.0]), target, CFG)
    assert float(t["direction"]) == pytest.approx(-0.09)
    assert float(t["orientation"]) == pytest.approx(-1.0, abs=1e-6)
    assert float(t["effort_orientation"]) == pytest.approx(-1.0)
    assert float(t["effort_acceleration"]) == pytest.approx(-2.0)
    # 1.0 * -0.09 + 0.4 * -1 + 0.1 * -1 + 0.1 * -2 + 1.0 * 1 = 0.21
    assert float(reward.total(t, CFG)) == pytest.approx(0.21, abs=1e-6)
    # The clearance term: 0 with its weight 0, else minus the invalid fraction of six probes.
    assert float(t["clearance"]) == 0.0
    weighted = dataclasses.replace(CFG, rewards=dataclasses.replace(CFG.rewards, clearance=2.0))
    low = pose.at[2].set(0.80)  # 0.80 m above flat ground: valid, but 0.10 m lower is not
    c = reward.terms(field, low, jnp.zeros(3), jnp.zeros(4), target, weighted)
    shortfall = reachability.clearance_shortfall(field, low, weighted.clearance_margin, weighted.reachability)
    assert float(c["clearance"]) == pytest.approx(-float(shortfall)) and float(shortfall) > 0.0
    assert float(reward.total(c, weighted)) == pytest.approx(
        float(reward.total(c, CFG)) + 2.0 * float(c["clearance"])
    )
