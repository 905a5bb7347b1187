"""simulate: Talos executes a motion in MuJoCo; falls and failed phases are reported."""

import math

import numpy as np
import pytest
from motion_helpers import straight_plan

from leas_jax.motion.config import SimulationConfig
from leas_jax.motion.motion import make_motion
from leas_jax.motion.simulate import simulate


@pytest.fixture(scope="module")
def motion():
    return make_motion(straight_plan(0.6))


def test_flat_ground_motion_executes(motion):
    rollout = simulate(motion)
    config = SimulationConfig()
    assert rollout.success, rollout.message
    assert not rollout.fallen and math.isnan(rollout.fall_time)
    assert all(p.reached and not p.problems(config) for p in rollout.phases)
    summary = rollout.summary()
    assert summary["landings"] == sum(p.kind == "land" for p in motion.phases) > 0
    assert summary["max_landing_position_m"] < config.landing_position
    assert summary["max_landing_angle_deg"] < math.degrees(config.landing_angle)
    assert summary["max_slip_m"] < config.max_slip
    assert summary["max_torque_ratio"] < 1.0
    assert rollout.root_height.min() > config.min_root_height and rollout.tilt.max() < config.max_tilt
    # the simulated root ends where the plan's last posture puts it
    assert np.linalg.norm(rollout.q[-1, :2] - motion.plan_q[-1, :2]) < 0.03


def test_limp_robot_is_reported_fallen(motion):
    rollout = simulate(motion, torque_scale=0.0)
    assert rollout.fallen and not rollout.success
    assert rollout.fall_time < 2.0
    assert "fell" in rollout.message
    fell = [p for p in rollout.phases if p.fallen]
    assert len(fell) == 1 and not fell[0].reached
    assert not rollout.phases[-1].reached


def test_soft_legs_fall_in_single_support(motion):
    """Leg stiffness below gravity's (780 N m/rad) lets the stance tip over, as measured."""
    rollout = simulate(motion, config=SimulationConfig(leg_stiffness=0.0, settle=0.0))
    assert not rollout.success
    failing = [p for p in rollout.phases if p.problems(SimulationConfig())]
    assert failing and failing[0].kind in ("lift", "land", "shift")


def test_peak_torque_ratio_per_joint_group(motion):
    """Every joint's peak commanded torque over its limit is kept; the groups partition the 32
    joints, the legs carry the largest ratio on flat ground and the run's CPU time is measured."""
    from leas_jax.contacts.robot.model import load_talos
    from leas_jax.motion.simulate import JOINT_GROUPS

    rollout = simulate(motion, config=SimulationConfig(settle=0.0))
    names = [load_talos().model.names[i] for i in range(2, 34)]
    assert sorted(i for group in JOINT_GROUPS.values() for i in group) == list(range(32))
    for group, index in JOINT_GROUPS.items():
        prefix = {"legs": "leg_", "torso": "torso_", "arms": "arm_", "grippers": "gripper_", "head": "head_"}[
            group
        ]
        assert all(names[i].startswith(prefix) for i in index), (group, [names[i] for i in index])
    ratios = rollout.group_torque_ratios()
    assert rollout.joint_torque_ratio.shape == (32,) and (rollout.joint_torque_ratio > 0).all()
    assert max(ratios.values()) == pytest.approx(max(p.torque_ratio for p in rollout.phases))
    assert ratios["legs"] == max(ratios.values()) < 1.0
    assert 0.0 < rollout.cpu_seconds
