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
