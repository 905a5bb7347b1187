"""Verifier: a generated plan passes; each kind of tampering is caught by its check."""

import numpy as np
import pytest

from leas_jax.contacts import ContactPlan, plan_contacts, verify
from leas_jax.contacts.robot.model import NOMINAL_ROOT_HEIGHT as H
from leas_jax.contacts.robot.model import load_talos
from leas_jax.terrain import loads_terrain

TEXT = (
    'name = "v"\nbounds = [[-1.0, -2.0], [4.0, 2.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
    "[[box]]\ncenter = [1.5, 0.0, -0.1]\nsize = [5.0, 4.0, 0.2]\n"
)


@pytest.fixture(scope="module")
def plan():
    # 2 m at 0.18 m/s, then 2 s standing still: the generator steps at nearly every
    # planning pose while walking, so the pause is where postures move only the root.
    count = int(round(2.0 / 0.018)) + 1
    x = np.concatenate([np.linspace(0.0, 2.0, count), np.full(20, 2.0)])
    guide = np.stack([x, np.zeros(len(x)), np.full(len(x), H), np.zeros(len(x))], axis=1)
    result = plan_contacts(loads_terrain(TEXT), guide, 0.1)
    assert result.coverage == 1.0
    return result


def _with(plan, **changes):
    fields = dict(
        q=plan.q,
        feet=plan.feet,
        guide_index=plan.guide_index,
        last_valid_index=plan.last_valid_index,
        coverage=plan.coverage,
        terrain=plan.terrain,
        guide=plan.guide,
    )
    fields.update(changes)
    return ContactPlan(**fields)


def _double_support(plan, start):
    """First posture index >= start with both feet down and both neighbours present."""
    for k in range(start, len(plan) - 1):
        if np.all(np.isfinite(plan.feet[k])) and k > 0:
            return k
    raise AssertionError("no double-support posture")


def _failed(report, posture):
    return {check for k, check, _ in report.failures if k == posture}


def test_untampered_plan_passes(plan):
    report = verify(plan)
    assert report.ok, str(report)
    assert report.postures == len(plan)


def test_moved_foot(plan):
    # A double-support posture whose left foot was already down in the one before.
    k = next(
        k
        for k in range(len(plan) // 2, len(plan) - 1)
        if np.all(np.isfinite(plan.feet[k])) and np.all(np.isfinite(plan.feet[k - 1, 0]))
    )
    feet = plan.feet.copy()
    feet[k, 0, 0] += 0.03  # 3 cm forward in the file, q unchanged
    report = verify(_with(plan, feet=feet))
    assert 2 in _failed(report, k)  # FK no longer puts the sole there
    assert 5 in _failed(report, k)  # and it moved without lifting
    assert report.checks_failed() <= {2, 5}


def test_joint_beyond_limit(plan):
    talos = load_talos()
    k = _double_support(plan, len(plan) // 3)
    idx = talos.model.joints[talos.model.getJointId("arm_right_4_joint")].idx_q
    q = plan.q.copy()
    q[k, idx] = talos.upper[idx] + 0.05
    report = verify(_with(plan, q=q))
    assert report.checks_failed() == {3}
    assert [m for p, c, m in report.failures if p == k and "arm_right_4_joint" in m]


def test_com_outside_support(plan):
    """A double-support posture relabelled as single support on the right foot: the CoM
    stays between the feet, outside the right sole (the steps are still legal, check 5)."""
    feet = plan.feet.copy()
    # A posture that only moves the root: both neighbours have the same feet down.
    k = next(
        k
        for k in range(len(plan) // 2, len(plan) - 1)
        if np.all(np.isfinite(feet[k - 1 : k + 2])) and np.array_equal(feet[k - 1], feet[k + 1])
    )
    feet[k, 0] = np.nan
    report = verify(_with(plan, feet=feet))
    assert report.checks_failed() == {4}
    assert _failed(report, k) == {4}


def test_posture_in_collision(plan):
    """A bar at chest height across the robot at one posture's root position."""
    k = _double_support(plan, len(plan) // 2)
    x, y = plan.q[k, 0], plan.q[k, 1]
    bar = f"[[box]]\ncenter = [{x}, {y}, {H + 0.3}]\nsize = [0.04, 1.0, 0.04]\n"
    report = verify(_with(plan, terrain=plan.terrain + bar))
    assert report.checks_failed() == {3}
    assert 3 in _failed(report, k)
    far = [p for p, _, _ in report.failures if abs(plan.q[p, 0] - x) > 0.5]
    assert far == []  # only postures near the bar


def test_two_feet_moved_at_once(plan):
    """Drop the postures between two double-support postures where both feet differ."""
    feet = plan.feet
    start = _double_support(plan, 1)
    for end in range(start + 1, len(plan)):
        if np.all(np.isfinite(feet[end])) and np.all(np.abs(feet[end, :, 0] - feet[start, :, 0]) > 1e-3):
            break
    keep = np.r_[0 : start + 1, end : len(plan)]
    report = verify(_with(plan, q=plan.q[keep], feet=feet[keep], guide_index=plan.guide_index[keep]))
    assert report.checks_failed() == {5}
    messages = [m for p, c, m in report.failures if p == start + 1]
    assert any("both feet" in m for m in messages)


def test_coverage_tampering(plan):
    report = verify(_with(plan, coverage=0.5))
    assert report.checks_failed() == {0}


def test_report_text(plan):
    feet = plan.feet.copy()
    k = _double_support(plan, 2)
    feet[k, 1, 2] += 0.02
    text = str(verify(_with(plan, feet=feet)))
    assert f"posture {k}: check 1" in text and "FAILED" in text


def _prefix(plan, count):
    """The plan's first `count` postures as a consistent plan of their own."""
    from leas_jax.contacts.plan import coverage_of

    last = int(plan.guide_index[count - 1])
    return _with(
        plan,
        q=plan.q[:count],
        feet=plan.feet[:count],
        guide_index=plan.guide_index[:count],
        last_valid_index=last,
        coverage=coverage_of(plan.guide, last),
    )


def _consistency_messages(report):
    return [m for _, c, m in report.failures if c == 0]


def test_relabelled_last_guide_index_is_caught(plan):
    """A 4-posture plan claiming the whole guide (last index relabelled to the end, coverage 1)."""
    short = _prefix(plan, 4)
    assert verify(short).ok
    end = len(plan.guide) - 1
    index = short.guide_index.copy()
    index[-1] = end
    forged = _with(short, guide_index=index, last_valid_index=end, coverage=1.0)
    report = verify(forged)
    assert not report.ok and any(f"off guide pose {end}" in m for m in _consistency_messages(report))


def test_shifted_nan_guides_and_non_unit_quaternions_are_caught(plan):
    short = _prefix(plan, 6)
    shifted = verify(_with(short, guide=short.guide + np.array([3.0, 0.0, 0.0, 0.0])))
    messages = _consistency_messages(shifted)
    assert any("off guide pose" in m for m in messages) and any("m from guide pose" in m for m in messages)
    guide = short.guide.copy()
    guide[len(guide) // 2, 1] = np.nan
    assert "guide has NaN or inf" in _consistency_messages(verify(_with(short, guide=guide)))
    q = short.q.copy()
    q[2, 3:7] *= 1.02
    assert any("root quaternion has norm 1.02" in m for m in _consistency_messages(verify(_with(short, q=q))))
    feet = short.feet.copy()
    feet[0, 0, 3:] *= 1.02
    assert any(
        "left foot quaternion has norm 1.02" in m
        for m in _consistency_messages(verify(_with(short, feet=feet)))
    )


def test_random_tampering_is_caught(plan):
    """Property: each of 24 seeded random tamperings of a plan (a foot, a joint, the root, a guide
    index, the guide, a quaternion, NaN, coverage, last index, order) makes verify fail."""
    from leas_jax.contacts.plan import coverage_of

    base = _prefix(plan, 10)
    assert verify(base).ok
    rng = np.random.default_rng(7)
    talos = load_talos()
    lower, upper = talos.model.lowerPositionLimit, talos.model.upperPositionLimit

    def tamper(kind):
        q, feet, index, guide = base.q.copy(), base.feet.copy(), base.guide_index.copy(), base.guide.copy()
        k = int(rng.integers(1, len(q)))
        change = {}
        if kind == "foot":
            side = int(np.flatnonzero(np.isfinite(feet[k, :, 0]))[0])
            feet[k, side, int(rng.integers(3))] += rng.choice([-1, 1]) * rng.uniform(0.02, 0.2)
            change["feet"] = feet
        elif kind == "joint":
            j = int(rng.integers(7, talos.model.nq))
            q[k, j] = (
                upper[j] + rng.uniform(0.05, 0.5) if rng.random() < 0.5 else lower[j] - rng.uniform(0.05, 0.5)
            )
            change["q"] = q
        elif kind == "root":
            q[k, int(rng.integers(3))] += rng.choice([-1, 1]) * rng.uniform(0.05, 0.3)
            change["q"] = q
        elif kind == "guide index":
            far = np.flatnonzero(np.hypot(*(guide[:, :2] - guide[index[k], :2]).T) > 0.3)
            index[k] = int(rng.choice(far))
            change["guide_index"] = index
        elif kind == "guide":
            guide[:, int(rng.integers(2))] += rng.choice([-1, 1]) * rng.uniform(0.3, 3.0)
            change["guide"] = guide
        elif kind == "quaternion":
            q[k, 3:7] *= rng.uniform(1.01, 1.1)
            change["q"] = q
        elif kind == "nan":
            q[k, int(rng.integers(q.shape[1]))] = np.nan
            change["q"] = q
        elif kind == "coverage":
            change["coverage"] = float(
                np.clip(base.coverage + rng.choice([-1, 1]) * rng.uniform(0.01, 0.5), 0, 1)
            )
        elif kind == "last index":
            last = int(rng.integers(len(guide)))
            last = last if last != base.last_valid_index else last + 1
            change.update(last_valid_index=last, coverage=coverage_of(guide, last))
        else:  # order
            q[[k - 1, k]], feet[[k - 1, k]] = q[[k, k - 1]], feet[[k, k - 1]]
            change.update(q=q, feet=feet)
        return change

    kinds = [
        "foot",
        "joint",
        "root",
        "guide index",
        "guide",
        "quaternion",
        "nan",
        "coverage",
        "last index",
        "order",
    ]
    for trial in range(24):
        kind = kinds[trial % len(kinds)]
        change = tamper(kind)
        report = verify(_with(base, **change))
        assert not report.ok, f"trial {trial}: {kind} tampering passed"


def test_single_support_root_may_stand_farther_off_the_guide(plan):
    """Check 0 holds a root within max_root_offset_xy (0.12 m) of its guide pose with both feet
    down, within max_single_support_offset_xy (0.20 m) on one foot."""
    from leas_jax.contacts import GeneratorConfig

    config = GeneratorConfig()
    one_foot = int(np.flatnonzero(~np.all(np.isfinite(plan.feet[:, :, 0]), axis=1))[0])
    two_feet = _double_support(plan, one_foot + 1)

    def root_off_guide(k, distance):
        q = plan.q.copy()
        q[k, :2] = plan.guide[plan.guide_index[k], :2] + np.array([0.0, distance])
        return any("off guide pose" in m for m in _consistency_messages(verify(_with(plan, q=q))))

    between = 0.5 * (config.max_root_offset_xy + config.max_single_support_offset_xy)
    assert not root_off_guide(one_foot, between)
    assert root_off_guide(two_feet, between)
    assert root_off_guide(one_foot, config.max_single_support_offset_xy + 0.01)
