"""make_motion: phases, key postures, task tracking and the checks (leas_jax.motion.motion)."""

import numpy as np
import pytest
from motion_helpers import straight_plan

from leas_jax.contacts.plan import ContactPlan
from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.config import MotionConfig
from leas_jax.motion.motion import (
    ARM_DETOURS,
    Motion,
    MotionError,
    arm_detour,
    centred_postures,
    check_motion,
    colliding_arms,
    detour_profile,
    make_motion,
    off_centre_segments,
    posture_frames,
    pressure_margins,
)


@pytest.fixture(scope="module")
def plan():
    return straight_plan()


@pytest.fixture(scope="module")
def motion(plan):
    return make_motion(plan)


def test_key_instants_are_the_plan_postures(plan, motion):
    assert len(motion.key_index) == len(plan)
    assert motion.key_index[0] == 0 and motion.key_index[-1] == len(motion.q) - 1
    np.testing.assert_array_equal(motion.q[motion.key_index], plan.q)
    assert motion.moved_keys.size == 0  # every posture of this plan is well inside its support
    np.testing.assert_array_equal(motion.contact[motion.key_index], ~np.isnan(plan.feet[:, :, 0]))
    # at rest at every key posture
    assert np.abs(motion.v[motion.key_index]).max() < 1e-3 < np.abs(motion.v).max()


def test_phases_alternate_and_time_steps(plan, motion):
    assert np.allclose(np.diff(motion.time), MotionConfig().dt)
    assert motion.phases[0].start == 0 and motion.phases[-1].stop == len(motion.q) - 1
    for before, after in zip(motion.phases[:-1], motion.phases[1:]):
        assert before.stop == after.start
    kinds = [p.kind for p in motion.phases]
    steps = int(np.sum(np.isnan(plan.feet[:, 0, 0]) | np.isnan(plan.feet[:, 1, 0])))
    assert kinds.count("lift") == kinds.count("land") == steps > 0
    for phase in motion.phases:
        seconds = (phase.stop - phase.start) * motion.dt
        if phase.kind == "shift":
            assert seconds >= MotionConfig().min_double_support - 1e-9
        else:
            assert phase.single_support
    single = sum((p.stop - p.start) for p in motion.phases if p.single_support) * motion.dt / steps
    assert 1.2 <= single <= 1.6  # the HPP Talos demos' single support


def test_tasks_tracked(motion):
    talos = load_talos()
    for sample in range(0, len(motion.q), 37):
        feet, com, _ = posture_frames(talos, motion.q[sample])
        for side in (0, 1):
            np.testing.assert_allclose(feet[side][:3, 3], motion.feet[sample, side, :3], atol=1e-6)
        np.testing.assert_allclose(com, motion.com[sample], atol=1e-6)
    # a sole in support does not move
    for side in (0, 1):
        down = motion.contact[:, side]
        for start in np.flatnonzero(down[1:] & ~down[:-1]) + 1:
            stop = start + np.argmin(down[start:]) if not down[start:].all() else len(down)
            assert np.ptp(motion.feet[start:stop, side, :3], axis=0).max() < 1e-9


def test_swing_clears_the_ground(motion):
    for phase in motion.phases:
        if phase.single_support:
            sole_z = motion.feet[phase.start : phase.stop + 1, phase.swing, 2]
            assert sole_z.min() >= -1e-9
            if phase.kind == "land":
                assert sole_z.max() >= MotionConfig().swing_clearance - 1e-9


def test_motion_passes_its_checks(motion):
    assert check_motion(motion) == []
    talos = load_talos()
    assert (np.abs(motion.tau) / talos.model.effortLimit[6:]).max() < 1.0


def test_planned_sole_wrenches_keep_their_soles_down(motion):
    """Every sole in contact pushes with its centre of pressure on its sole rectangle, in double
    support too (a vertical load split with a least-squares remainder put it up to 9 N m of
    ankle torque past the sole's edge on this plan)."""
    from leas_jax.contacts.robot.model import SOLE_LENGTH, SOLE_WIDTH

    w = motion.wrenches[motion.contact]  # [M, 6] sole frame
    assert (w[:, 2] > 0.0).all()
    assert (np.abs(w[:, 3]) <= w[:, 2] * SOLE_WIDTH / 2).all()
    assert (np.abs(w[:, 4]) <= w[:, 2] * SOLE_LENGTH / 2).all()


def test_checks_catch_broken_motions(plan, motion):
    talos = load_talos()
    knee = 3  # leg_left_4_joint in the 32 joints
    broken_q = motion.q.copy()
    broken_q[50, 7 + knee] = talos.model.upperPositionLimit[7 + knee] + 0.1
    names = {name for _, _, name, _ in check_motion(_replace(motion, q=broken_q))}
    assert "joint limits" in names
    tau = motion.tau.copy()
    tau[80] *= 3.0
    names = {name for _, _, name, _ in check_motion(_replace(motion, tau=tau))}
    assert "inverse dynamics" in names
    sunk = motion.q.copy()
    sunk[60, 2] -= 0.1  # the whole robot 10 cm into the floor at one sample
    failures = [(sample, name) for sample, _, name, _ in check_motion(_replace(motion, q=sunk))]
    assert (60, "collisions") in failures and all(sample == 60 for sample, _ in failures)
    rushed = make_motion(
        plan, MotionConfig(min_double_support=0.1, com_acceleration=20.0, lift_duration=0.2, land_duration=0.25),
        check=False,
    )  # fmt: skip
    names = {name for _, _, name, _ in rushed.failures}
    assert {"torque limits", "equilibrium"} <= names
    with pytest.raises(MotionError, match="fails at t ="):
        make_motion(plan, MotionConfig(min_double_support=0.1, com_acceleration=20.0, lift_duration=0.2))


def test_unmakeable_plan_names_the_postures(plan):
    broken = ContactPlan(
        q=plan.q[[0, 3]], feet=np.stack([plan.feet[0], plan.feet[0] + [0.3, 0, 0, 0, 0, 0, 0]]),
        guide_index=plan.guide_index[[0, 3]], last_valid_index=plan.last_valid_index,
        coverage=plan.coverage, terrain=plan.terrain, guide=plan.guide,
    )  # fmt: skip
    with pytest.raises(MotionError, match="postures 0 and 1"):
        make_motion(broken)


def test_save_load_round_trip(motion, tmp_path):
    path = tmp_path / "motion.npz"
    motion.save(path)
    loaded = Motion.load(path)
    np.testing.assert_array_equal(loaded.q, motion.q)
    np.testing.assert_array_equal(loaded.tau, motion.tau)
    assert loaded.phases == motion.phases
    (tmp_path / "bad.npz").write_bytes(b"not a zip")
    with pytest.raises(MotionError, match="not a readable motion file"):
        Motion.load(tmp_path / "bad.npz")


def test_arm_detours_are_smooth_mirrored_and_within_limits(plan):
    profile = detour_profile(np.linspace(0.0, 1.0, 101))
    assert profile[0] == 0.0 and abs(profile[-1]) < 1e-30 and profile[50] == pytest.approx(1.0)
    assert colliding_arms(["leg_left_3_link_0 collides with gripper_left_motor_single_link_0"]) == {0}
    assert colliding_arms([None, "gripper_right_fingertip_2_link_0 collides with terrain box 1"]) == {1}
    assert colliding_arms(["leg_left_4_link_0 collides with leg_right_6_link_0", None]) == set()
    model = load_talos().model
    spec = _Spec(plan.q[0], plan.q[0])
    index = {name: model.joints[model.getJointId(name)].idx_q for name in model.names[1:]}
    both = arm_detour(model, spec, {0, 1}, (0.4, 0.3, -0.5))
    moved = np.flatnonzero(both)
    assert sorted(moved) == sorted(
        index[f"arm_{side}_{j}_joint"] for side in ("left", "right") for j in (1, 2, 4)
    )
    assert both[index["arm_left_2_joint"]] == -both[index["arm_right_2_joint"]] == pytest.approx(0.3)
    right = arm_detour(model, spec, {1}, (0.4, 0.3, -0.5))
    assert not right[index["arm_left_1_joint"]] and right[index["arm_right_1_joint"]] == pytest.approx(0.4)
    # an offset past a joint's limit is cut LIMIT_MARGIN inside it
    huge = arm_detour(model, spec, {0}, (0.0, 0.0, -9.0))
    elbow = index["arm_left_4_joint"]
    assert plan.q[0][elbow] + huge[elbow] == pytest.approx(model.lowerPositionLimit[elbow] + 0.03)
    assert len(set(ARM_DETOURS)) == len(ARM_DETOURS) and (0.0, 0.0, 0.0) not in ARM_DETOURS


def test_an_arm_swept_into_an_obstacle_detours_round_it(plan, motion):
    """A 3 cm cube where a gripper passes in the middle of a shift, clear of every key posture:
    the motion's arm goes round it, every key posture stays the plan's."""
    import dataclasses

    from leas_jax.contacts.robot.clearance import BodyClearance
    from leas_jax.terrain import loads_terrain

    talos = load_talos()
    frame = talos.model.getFrameId("gripper_right_fingertip_2_link")

    def fingertip(q):
        import pinocchio as pin

        pin.framesForwardKinematics(talos.model, talos.data, q)
        return talos.data.oMf[frame].translation.copy()

    def sweep(phase):
        middle = (phase.start + phase.stop) // 2
        ends = min(
            np.linalg.norm(fingertip(motion.q[i]) - fingertip(motion.q[middle])) for i in motion.key_index
        )
        return ends, middle

    ends, middle = max(sweep(p) for p in motion.phases if p.kind == "shift")
    assert ends > 0.05  # the gripper passes 5 cm or more from where any key posture holds it
    x, y, z = fingertip(motion.q[middle])
    box = f"\n[[box]]\ncenter = [{x}, {y}, {z}]\nsize = [0.03, 0.03, 0.03]\n"
    blocked = dataclasses.replace(plan, terrain=plan.terrain.replace("\n[scenario]", box + "\n[scenario]", 1))
    clearance = BodyClearance(talos, loads_terrain(blocked.terrain))
    assert colliding_arms([clearance.collisions(motion.q[middle])]) == {1}
    assert not any(clearance.collisions(q) for q in plan.q)
    detoured = make_motion(blocked)  # raises where a sample collides
    np.testing.assert_array_equal(detoured.q[detoured.key_index], plan.q)
    assert not any(clearance.collisions(q) for q in detoured.q[::5])
    assert np.abs(detoured.q[:, 7:19] - motion.q[:, 7:19]).max() < 0.05  # the legs as before, or near


def test_centre_of_pressure_is_checked_and_remade_slower(plan, motion):
    margins = pressure_margins(motion)
    single = motion.contact.sum(axis=1) == 1
    assert np.isnan(margins[~single]).all() and (margins[single] >= 0.0).all()
    assert off_centre_segments(motion, -1.0) == set()
    steps = {p.postures[0] for p in motion.phases if p.single_support}
    assert off_centre_segments(motion, 1.0) == steps
    # the stance sole's centre of pressure 5 cm past its toe at one sample
    sample = int(np.flatnonzero(single)[40])
    wrenches = motion.wrenches.copy()
    side = int(np.argmax(motion.contact[sample]))
    wrenches[sample, side, 4] = -0.15 * wrenches[sample, side, 2]
    failures = check_motion(_replace(motion, wrenches=wrenches))
    assert [(s, name) for s, _, name, _ in failures] == [(sample, "centre of pressure")]
    # a margin over some single supports' own: those are made again, then slower
    tightest = sorted(np.nanmin(margins[p.start + 1 : p.stop + 1]) for p in motion.phases if p.single_support)
    config = MotionConfig(pressure_margin=float(tightest[1]))
    remade = make_motion(plan, config, check=False)
    np.testing.assert_array_equal(remade.q[remade.key_index], plan.q)
    lengths = {p.postures: p.stop - p.start for p in motion.phases if p.single_support}
    longer = [p for p in remade.phases if p.single_support and p.stop - p.start > 1.5 * lengths[p.postures]]
    assert longer and {p.postures[0] for p in longer} <= off_centre_segments(motion, config.pressure_margin)


def test_one_foot_postures_near_their_sole_edge_are_centred(plan):
    from leas_jax.motion.motion import sole_corners, support_margin
    from leas_jax.motion.wbik import WholeBodyIK

    talos = load_talos()
    config = MotionConfig()
    ik = WholeBodyIK(talos, config.ik_iterations, config.ik_damping, config.ik_tolerance)
    frames = [posture_frames(talos, q) for q in plan.q]
    on = ~np.isnan(plan.feet[:, :, 0])
    single = [k for k in range(1, len(plan)) if on[k].sum() == 1]
    margins = _one_foot_margins(plan)
    wanted = float(np.median(list(margins.values())))  # half the one-foot postures are nearer their edge
    q, moved = centred_postures(talos, plan, frames, 0.0, ik, single_margin=wanted)
    assert moved and set(moved) == {k for k in single if margins[k] < wanted}
    for k in range(len(plan)):
        feet, com, _ = posture_frames(talos, q[k])
        np.testing.assert_allclose(feet[on[k]], frames[k][0][on[k]], atol=1e-6)  # soles kept
        if k in moved:
            assert support_margin(sole_corners(feet, on[k]), com[:2]) >= wanted - 1e-6
        else:
            np.testing.assert_array_equal(q[k], plan.q[k])

    class Blocked:  # every configuration collides
        def collisions(self, q):
            return "arm_left_1_link_0 collides with a test wall"

    assert centred_postures(talos, plan, frames, 0.0, ik, wanted, Blocked())[1] == []


def test_a_one_foot_posture_whose_swing_leg_is_at_its_reach_is_centred_with_its_swing_sole_carried(plan):
    from leas_jax.motion.motion import _centred_configuration, centred_com, sole_corners
    from leas_jax.motion.wbik import IKError, WholeBodyIK

    talos = load_talos()
    config = MotionConfig()
    ik = WholeBodyIK(talos, config.ik_iterations, config.ik_damping, config.ik_tolerance)
    on = ~np.isnan(plan.feet[:, :, 0])
    k = next(k for k in range(1, len(plan)) if on[k].sum() == 1)
    feet, com, rotation = posture_frames(talos, plan.q[k])
    target = centred_com(sole_corners(feet, on[k]), com, 0.065)  # the sole's centre line
    swing = int(np.flatnonzero(~on[k])[0])
    assert np.linalg.norm(target[:2] - com[:2]) > 1e-3

    class AtReach:  # the real IK, but the swing sole cannot stay where it is
        def solve(self, q, targets):
            if np.allclose(targets.feet[swing], feet[swing]):
                raise IKError("IK residual on the swing sole (the test's leg at its reach)")
            return ik.solve(q, targets)

    q = _centred_configuration(AtReach(), plan.q[k], feet, com, target, rotation, on[k])
    moved_feet, moved_com, moved_rotation = posture_frames(talos, q)
    np.testing.assert_allclose(moved_com, target, atol=1e-6)
    np.testing.assert_allclose(moved_feet[1 - swing], feet[1 - swing], atol=1e-6)  # stance sole kept
    carried = feet[swing].copy()
    carried[:2, 3] += target[:2] - com[:2]
    np.testing.assert_allclose(moved_feet[swing], carried, atol=1e-6)  # the swing sole moved as the CoM
    np.testing.assert_allclose(moved_rotation, rotation, atol=1e-6)

    class Unreachable:
        def solve(self, q, targets):
            raise IKError("nothing reaches")

    assert _centred_configuration(Unreachable(), plan.q[k], feet, com, target, rotation, on[k]) is None
    both = next(j for j in range(1, len(plan)) if on[j].all())  # both soles down: nothing to carry
    feet2, com2, rotation2 = posture_frames(talos, plan.q[both])
    calls = []

    class Counting:
        def solve(self, q, targets):
            calls.append(targets)
            raise IKError("nothing reaches")

    assert _centred_configuration(Counting(), plan.q[both], feet2, com2, com2, rotation2, on[both]) is None
    assert len(calls) == 1  # a two-foot posture keeps its soles: one try


def test_a_centred_one_foot_posture_whose_step_cannot_be_made_is_the_plans(plan, monkeypatch):
    """Where a single support next to a one-foot posture centred in its sole cannot be made, the
    motion takes that posture as the plan has it, and every other centred one stays centred."""
    from leas_jax.motion import motion as module

    # the median of this plan's one-foot postures' margins (6.3 cm of the sole's 6.5): some are centred
    config = MotionConfig(single_support_margin=float(np.median(list(_one_foot_margins(plan).values()))))
    centred = make_motion(plan, config, check=False)
    assert centred.moved_keys.size > 1
    refused = int(centred.moved_keys[0])
    real = module._segment_phases

    def segment(made, k, *args, **kwargs):
        if refused in (k, k + 1) and not np.array_equal(made.q[refused], plan.q[refused]):
            raise MotionError(f"postures {k} and {k + 1}: refused by the test")
        return real(made, k, *args, **kwargs)

    monkeypatch.setattr(module, "_segment_phases", segment)
    made = make_motion(plan, config, check=False)
    assert refused not in made.moved_keys and set(made.moved_keys) == set(centred.moved_keys) - {refused}
    np.testing.assert_array_equal(made.q[made.key_index[refused]], plan.q[refused])


def _one_foot_margins(plan) -> dict:
    """{k: m} how far inside its stance sole each one-foot posture k holds its CoM."""
    from leas_jax.motion.motion import sole_corners, support_margin

    talos = load_talos()
    on = ~np.isnan(plan.feet[:, :, 0])
    margins = {}
    for k in range(1, len(plan)):
        if on[k].sum() == 1:
            feet, com, _ = posture_frames(talos, plan.q[k])
            margins[k] = support_margin(sole_corners(feet, on[k]), com[:2])
    return margins


def _Spec(upper0, upper1):
    """The two upper bodies of a phase, as `arm_detour` reads them."""
    from types import SimpleNamespace

    return SimpleNamespace(upper0=upper0, upper1=upper1)


def _replace(motion, **changes):
    import dataclasses

    return dataclasses.replace(motion, failures=[], **changes)
