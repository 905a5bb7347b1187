"""make_motion: phases, key postures, task tracking and the checks (leas_jax.motion.motion)."""

import numpy as np
import pytest
from motion_helpers import straight_plan

from leas_jax.contacts.plan import ContactPlan
from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.config import MotionConfig
from leas_jax.motion.motion import Motion, MotionError, check_motion, make_motion, posture_frames


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


def _replace(motion, **changes):
    import dataclasses

    return dataclasses.replace(motion, failures=[], **changes)
