"""Balance margins of motions: key postures whose CoM sits at the soles' edge are reached with
the CoM moved inside (MotionConfig.support_margin), the tracking controller lands each
sole on its planned world placement when the robot has crept (SimulationConfig.landing_correction),
crouched single supports rise and keep their CoM's acceleration, and the planned sole wrenches
keep their centres of pressure on their soles (dynamics.static_wrenches)."""

import dataclasses

import numpy as np
import pytest
from motion_helpers import straight_plan

from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.config import MotionConfig, SimulationConfig
from leas_jax.motion.motion import (
    centred_com,
    make_motion,
    posture_frames,
    sole_corners,
    support_margin,
)


def test_support_margin_and_centred_com_on_a_square():
    square = np.array([[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]])
    assert support_margin(square, np.array([0.1, 0.1])) == pytest.approx(0.1)
    assert support_margin(square, np.array([0.195, 0.1])) == pytest.approx(0.005)
    assert support_margin(square, np.array([0.25, 0.1])) == pytest.approx(-0.05)
    com = np.array([0.195, 0.15, 0.9])
    moved = centred_com(square, com, 0.03)
    assert support_margin(square, moved[:2]) == pytest.approx(0.03, abs=1e-6)
    assert moved[2] == com[2]
    # it moved along the line to the centre
    direction = np.array([0.1, 0.1]) - com[:2]
    step = moved[:2] - com[:2]
    assert abs(direction[0] * step[1] - direction[1] * step[0]) < 1e-9
    np.testing.assert_array_equal(centred_com(square, np.array([0.1, 0.1, 0.9]), 0.03), [0.1, 0.1, 0.9])
    # a margin no point reaches: the centre
    np.testing.assert_allclose(centred_com(square, com, 0.5)[:2], [0.1, 0.1])


@pytest.fixture(scope="module")
def edge_plan():
    """A flat-ground plan whose first double-support posture after a landing has its CoM moved
    (IK, soles and upper body kept) to 5 mm inside its soles' support polygon, at the heels."""
    from leas_jax.motion.wbik import Targets, WholeBodyIK

    plan = straight_plan(0.3)
    talos = load_talos()
    on = ~np.isnan(plan.feet[:, :, 0])
    k = next(i for i in range(1, len(plan)) if on[i].all() and not on[i - 1].all())
    feet, com, rotation = posture_frames(talos, plan.q[k])
    corners = sole_corners(feet, on[k])
    heel = com.copy()
    for _ in range(300):  # walk the CoM backwards until 5 mm from the edge
        if support_margin(corners, heel[:2] - [0.001, 0.0]) < 0.005:
            break
        heel[0] -= 0.001
    ik = WholeBodyIK(talos, 50, 1e-8, 1e-9)
    q = np.array(plan.q)
    q[k] = ik.solve(q[k], Targets(feet, heel, rotation, q[k]))
    assert support_margin(corners, posture_frames(talos, q[k])[1][:2]) == pytest.approx(0.005, abs=1.5e-3)
    return dataclasses.replace(plan, q=q), k


def test_edge_posture_is_reached_with_its_com_inside(edge_plan):
    plan, k = edge_plan
    talos = load_talos()
    margin = MotionConfig().support_margin
    motion = make_motion(plan)
    assert motion.moved_keys.tolist() == [k]
    reached = motion.q[motion.key_index[k]]
    feet, com, _ = posture_frames(talos, reached)
    on = ~np.isnan(plan.feet[k, :, 0])
    assert support_margin(sole_corners(feet, on), com[:2]) == pytest.approx(margin, abs=1e-4)
    # same soles, root orientation and upper body as the plan's posture; the others untouched
    plan_feet, _, plan_rotation = posture_frames(talos, plan.q[k])
    np.testing.assert_allclose(feet, plan_feet, atol=1e-7)
    np.testing.assert_allclose(posture_frames(talos, reached)[2], plan_rotation, atol=1e-7)
    others = np.delete(np.arange(len(plan)), k)
    np.testing.assert_array_equal(motion.q[motion.key_index[others]], plan.q[others])
    np.testing.assert_array_equal(motion.plan_q, plan.q)
    # without the margin the plan's own posture is reached
    plain = make_motion(plan, MotionConfig(support_margin=0.0), check=False)
    assert plain.moved_keys.size == 0
    np.testing.assert_array_equal(plain.q[plain.key_index], plan.q)


def test_moved_keys_survive_save_and_load(edge_plan, tmp_path):
    from leas_jax.motion.motion import Motion

    motion = make_motion(edge_plan[0])
    motion.save(tmp_path / "m.npz")
    np.testing.assert_array_equal(Motion.load(tmp_path / "m.npz").moved_keys, [edge_plan[1]])


@pytest.fixture(scope="module")
def shifted_motion():
    """The flat-ground motion with its planned sole placements 2 cm further along +x than where
    the robot stands: as if it had crept 2 cm backwards before its first step."""
    motion = make_motion(straight_plan(0.3))
    feet, plan_feet = motion.feet.copy(), motion.plan_feet.copy()
    feet[..., 0] += 0.02
    plan_feet[..., 0] += 0.02
    return dataclasses.replace(motion, feet=feet, plan_feet=plan_feet)


def test_landing_correction_lands_on_the_world_placements(shifted_motion):
    from leas_jax.motion.simulate import simulate

    corrected = simulate(shifted_motion, config=SimulationConfig(settle=0.0))
    plain = simulate(shifted_motion, config=SimulationConfig(settle=0.0, landing_correction=False))
    assert not corrected.fallen and not plain.fallen
    errors = [[p.landing_position for p in r.phases if p.kind == "land"] for r in (corrected, plain)]
    # joint references alone land every sole 2 cm off; the correction lands both soles on theirs
    assert min(errors[1]) > 0.017
    assert max(errors[0][2:]) < 0.005 and max(errors[0]) < 0.012, errors[0]
    assert corrected.success, corrected.message


def test_a_crouched_stance_rises_for_a_swing_sole_behind_it():
    """Crouched (root 0.13 m below the plan's, knees at 1.6 rad), a sole lifted 0.1 m and put
    0.15 m back needs its ankle past its pitch limit: no lowering reaches it, a 3 cm rise does,
    and the reaching configuration keeps its leg joints LIMIT_MARGIN inside their limits."""
    from leas_jax.motion.motion import LIMIT_MARGIN, MAX_RISE, held_root_configuration, root_dip

    talos = load_talos()
    q = straight_plan(0.3).q[0]
    feet, _, rotation = posture_frames(talos, q)
    crouched = held_root_configuration(talos, q, feet, rotation, np.array([0.0, 0.0, -0.13]), np.zeros(2))
    assert crouched is not None
    behind = feet.copy()
    behind[0] = feet[0].copy()
    behind[0][0, 3] -= 0.15
    behind[0][2, 3] += 0.10
    zero, knees = np.zeros(2), np.zeros(2)
    assert np.isnan(root_dip(talos, crouched, behind, rotation, zero, knees))
    rise = root_dip(talos, crouched, behind, rotation, zero, knees, direction=-1.0, margin=LIMIT_MARGIN)
    assert 0.0 < rise < MAX_RISE
    risen = held_root_configuration(
        talos, crouched, behind, rotation, np.array([0.0, 0.0, rise + 1e-6]), knees, LIMIT_MARGIN
    )
    assert risen is not None
    lower = talos.model.lowerPositionLimit[talos.legs[0].q_index]
    assert (risen[talos.legs[0].q_index] >= lower + LIMIT_MARGIN - 1e-9).all()
    # the same rise without the margin's room is not needed: a lower one reaches
    assert root_dip(talos, crouched, behind, rotation, zero, knees, direction=-1.0) < rise


def test_a_crouched_landing_behind_keeps_its_com_acceleration():
    """Crouched (root 0.13 m below the plan's), a sole landing 0.25 m behind the stance needs the
    root to rise (no lowering reaches it); the CoM then follows the swing leg's own path, and the
    landing lasts long enough for its horizontal acceleration to stay within
    single_support_acceleration (over the 0.8 s landing: 0.86 m/s^2, and eval_bridge's plans
    failed the equilibrium check there)."""
    from leas_jax.motion.motion import (
        _PhaseSpec,
        _single_support,
        held_root_configuration,
        peak_horizontal_acceleration,
    )

    talos, config = load_talos(), MotionConfig()
    q = straight_plan(0.3).q[0]
    feet, _, rotation = posture_frames(talos, q)
    crouched = held_root_configuration(talos, q, feet, rotation, np.array([0.0, 0.0, -0.13]), np.zeros(2))
    lifted, landed = feet.copy(), feet.copy()
    lifted[0][2, 3] += 0.02
    landed[0][0, 3] -= 0.25
    start = held_root_configuration(talos, crouched, lifted, rotation, np.zeros(3), np.zeros(2))
    com = posture_frames(talos, start)[1]
    samples = round(config.land_duration / config.dt)
    spec = _PhaseSpec(
        "land", (0, 1), 0, samples, lifted, landed, com, com, rotation, rotation, start, start, 0.07
    )
    lengthened, coms = _single_support(talos, spec, 0, config)
    assert coms[-1, 2] > coms[0, 2] + 0.01  # the root rose
    assert lengthened.samples > samples
    assert len(coms) == lengthened.samples + 1
    assert peak_horizontal_acceleration(coms, config.dt) <= config.single_support_acceleration


def test_static_wrenches_hold_the_weight_on_both_soles():
    """Soles apart and turned, the CoM off the segment between them: the static split carries the
    weight, balances it about the CoM, and keeps each centre of pressure on its sole."""
    from leas_jax.contacts.robot.model import SOLE_LENGTH, SOLE_WIDTH
    from leas_jax.motion.dynamics import static_wrenches

    soles = np.array([np.eye(4), np.eye(4)])
    soles[0][:3, 3] = [0.0, 0.1, 0.0]
    soles[1][:3, 3] = [0.25, -0.05, 0.0]
    yaw = 0.4
    soles[1][:2, :2] = [[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]
    com = np.array([0.1, 0.0])
    corners = sole_corners(soles, np.array([True, True]))
    assert support_margin(corners, com) > 0.0
    weight = 900.0
    wrenches = static_wrenches(com, soles, weight)
    forces = np.array([soles[s][:3, :3] @ wrenches[s, :3] for s in (0, 1)])
    torques = np.array([soles[s][:3, :3] @ wrenches[s, 3:] for s in (0, 1)])
    np.testing.assert_allclose(forces.sum(axis=0), [0.0, 0.0, weight], atol=1e-9)
    levers = soles[:, :3, 3] - np.r_[com, 0.0]
    moment = torques.sum(axis=0) + np.cross(levers, forces).sum(axis=0)
    np.testing.assert_allclose(moment, 0.0, atol=1e-9)
    assert (wrenches[:, 2] > 0.0).all()
    centres = np.stack([-wrenches[:, 4], wrenches[:, 3]], axis=1) / wrenches[:, 2:3]  # sole frames
    assert (np.abs(centres[:, 0]) < SOLE_LENGTH / 2).all() and (np.abs(centres[:, 1]) < SOLE_WIDTH / 2).all()
