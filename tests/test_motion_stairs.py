"""Motions up eval_stairs (0.12 m risers): the root comes down where a sole cannot be reached,
the swing sole clears the risers, and Talos climbs in MuJoCo; the pieces as pure functions."""

import math

import numpy as np
import pytest
from motion_helpers import straight_plan

from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.config import MotionConfig, SimulationConfig
from leas_jax.motion.motion import (
    MotionError,
    contact_weight,
    dip_depth,
    held_root_configuration,
    make_motion,
    posture_frames,
    root_dip,
)
from leas_jax.motion.paths import LAND_WINDOWS, LIFT_WINDOWS, swing_path


def stairs_plan(x0: float, y: float, speed: float):
    """Contact plan of a straight guide up eval_stairs at `speed` m/s from (x0, y) to x = 5.9,
    the root 1 m above the terrain under it (the top platform is 0.72 m up)."""
    from leas_jax.contacts import plan_contacts
    from leas_jax.terrain import load_terrain

    terrain = load_terrain("terrains/eval_stairs.toml")
    seconds = (5.9 - x0) / speed
    t = np.arange(0, round(seconds / 0.1) + 6) * 0.1
    x = x0 + speed * np.minimum(t, seconds)
    xy = np.stack([x, np.full_like(x, y)], axis=1)
    guide = np.c_[xy, terrain.height_at(xy) + 1.0, np.zeros_like(x)]
    plan = plan_contacts(terrain, guide, timestep=0.1)
    assert plan.coverage == 1.0 and plan.q[-1, 2] > 1.7
    return plan


def test_swing_paths_start_and_end_at_rest_below_the_apex():
    start, end, apex = np.array([0.0, 0.0, 0.0]), np.array([0.2, 0.05, 0.12]), 0.17
    for windows in (LIFT_WINDOWS, LAND_WINDOWS):
        t = np.linspace(0.0, 1.0, 401)
        path = swing_path(start, end, apex, t, windows)
        np.testing.assert_allclose(path[0], start, atol=1e-12)
        np.testing.assert_allclose(path[-1], end, atol=1e-12)
        assert path[:, 2].max() <= apex + 1e-12 and path[:, 2].max() > end[2]
        speed = np.linalg.norm(np.diff(path, axis=0), axis=1) / np.diff(t)
        assert speed[0] < 1e-3 and speed[-1] < 1e-3 < speed.max()
    # a lift leaves its contact vertically: no horizontal travel until 0.3 of the phase
    lifted = swing_path(start, end, apex, np.array([0.3, 0.35]), LIFT_WINDOWS)
    assert np.abs(lifted[0, :2]).max() < 1e-12 and lifted[0, 2] > 0.08 and lifted[1, 0] > 0.0


def test_dip_depth_covers_every_need_on_the_contact_weight():
    weight = contact_weight(61, lifting=True)
    assert weight[0] == 1.0 and weight[-1] == 0.0 and np.all(np.diff(weight) <= 0.0)
    needs = np.where(np.arange(61) < 20, 0.1 * weight, 0.0)
    needs[5] = 0.12
    depth = dip_depth(needs, weight)
    assert np.all(depth * weight >= needs - 1e-12) and np.isclose(depth, 0.12 / weight[5])
    assert dip_depth(np.zeros(61), weight) == 0.0
    needs[-1] = 0.01  # the key posture itself out of reach
    assert dip_depth(needs, weight) == math.inf


def test_held_root_configuration_reproduces_a_posture_and_the_dip_reaches_a_lower_sole():
    talos = load_talos()
    plan = straight_plan(0.3)
    q = plan.q[1]
    feet, _, rotation = posture_frames(talos, q)
    knees = np.array([0.0, 0.0])
    same = held_root_configuration(talos, q, feet, rotation, np.zeros(3), knees)
    np.testing.assert_allclose(same, q, atol=1e-9)
    assert root_dip(talos, q, feet, rotation, np.zeros(2), knees) == 0.0
    lower = feet.copy()
    lower[0, 2, 3] -= 0.2  # the left sole 0.2 m lower: out of reach from the posture's root
    assert held_root_configuration(talos, q, lower, rotation, np.zeros(3), knees) is None
    dip = root_dip(talos, q, lower, rotation, np.zeros(2), knees)
    assert 0.05 < dip < 0.3
    reached = held_root_configuration(talos, q, lower, rotation, np.array([0.0, 0.0, -dip]), knees)
    np.testing.assert_allclose(posture_frames(talos, reached)[0], lower, atol=1e-9)
    assert (
        held_root_configuration(talos, q, lower, rotation, np.array([0.0, 0.0, -dip + 1e-4]), knees) is None
    )


@pytest.mark.slow
def test_talos_climbs_eval_stairs_in_mujoco():
    from leas_jax.motion.simulate import simulate

    plan = stairs_plan(3.4, 3.2, 0.2)
    motion = make_motion(plan)
    config = MotionConfig()
    single = [p for p in motion.phases if p.single_support]
    # lift-offs from a lower step take longer than lift_duration: the root comes down and up
    assert max((p.stop - p.start) * motion.dt for p in single if p.kind == "lift") > config.lift_duration
    rollout = simulate(motion)
    summary = rollout.summary()
    assert rollout.success, rollout.message
    assert not rollout.fallen and summary["phases_reached"] == len(motion.phases)
    assert summary["max_landing_position_m"] < SimulationConfig().landing_position
    assert summary["max_slip_m"] < SimulationConfig().max_slip and summary["max_torque_ratio"] < 1.0
    assert rollout.q[-1, 2] > 1.65  # the root on the top platform (0.72 m up)


@pytest.mark.slow
def test_a_posture_on_the_edge_of_its_support_is_reached_with_its_com_inside():
    """The generator's posture 16 of this plan has its CoM near the soles' edge (hpp robustness 6.8,
    most postures ~95): as the plan's own, the CoM cannot leave it with an acceleration (and
    MuJoCo's Talos falls in that shift, measured with check=False); with the support margin the
    motion reaches it with its CoM moved inside and passes every check."""
    plan = stairs_plan(3.5, 2.8, 0.18)
    with pytest.raises(MotionError, match="shift between postures 16 and 17 .*equilibrium fails"):
        make_motion(plan, MotionConfig(support_margin=0.0))
    motion = make_motion(plan)
    assert 16 in motion.moved_keys.tolist()
