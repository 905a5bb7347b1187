"""How far a guide's contact plan got: the metrics of docs/design.md §8 and their aggregates.

The evaluation and navigate both judge a guide by them. Host code (NumPy).

coverage: arc-length fraction of the guide covered by the contact plan (the
    generator's `coverage`; Table II's "success rate").
success: the plan covers the whole guide (its last valid index is the guide's
    last pose) and one of its key postures has its root (`plan.q[k, :2]`)
    within 0.30 m of the target (paper §IV-B: "we consider that the goal is
    reached if a contact configuration is within a 30cm radius around it").
    The evaluation asks the pool for the plans, so this is exact; without a
    plan (an error, or a caller that did not keep it) the guide pose at the
    last valid index stands in for the posture roots (the generator keeps
    roots within max_root_offset_xy = 0.12 m of the guide).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SUCCESS_RADIUS = 0.30  # m, paper §IV-B


@dataclass(frozen=True)
class Outcome:
    """Metrics of one guide path.

    Attributes:
        coverage: in [0, 1].
        success: docs/design.md §8.
        last_valid_index: guide index of the last valid posture (-1: none).
        final_distance: m from the closest posture root (or guide pose) to the target.
        error: None, or why there is no plan ("rrt: no path", a planner error).
    """

    coverage: float
    success: bool
    last_valid_index: int
    final_distance: float
    error: str | None = None


def outcome(
    guide: np.ndarray | None,
    target,
    coverage: float,
    last_valid_index: int,
    plan=None,
    error: str | None = None,
    radius: float = SUCCESS_RADIUS,
) -> Outcome:
    """Metrics of one guide from the contact generator's answer.

    Args:
        guide: [T, 4] guide path (None: no guide was produced, e.g. the RRT failed).
        target: (x, y) world.
        coverage, last_valid_index: from the generator's `PathResult`.
        plan: the `ContactPlan` (its `q[:, :2]` are the posture roots), or None.
        error: a reason there is no plan.
        radius: success radius (m).

    Returns:
        `Outcome`.
    """
    target = np.asarray(target, np.float64).reshape(2)
    if guide is None or error is not None:
        return Outcome(
            float(coverage) if guide is not None else 0.0,
            False,
            int(last_valid_index),
            float("nan"),
            error or "no guide",
        )
    guide = np.asarray(guide, np.float64).reshape(-1, 4)
    if plan is not None and len(plan.q):
        roots = np.asarray(plan.q, np.float64)[:, :2]
    elif last_valid_index >= 0:
        roots = guide[last_valid_index : last_valid_index + 1, :2]
    else:
        roots = np.zeros((0, 2))
    distance = float(np.min(np.hypot(*(roots - target).T))) if len(roots) else float("nan")
    covered = last_valid_index >= len(guide) - 1
    return Outcome(float(coverage), bool(covered and distance <= radius), int(last_valid_index), distance)


def summarize(outcomes) -> dict:
    """Aggregate of a list of `Outcome`: n, mean coverage (%), success rate (%), errors."""
    outcomes = list(outcomes)
    n = len(outcomes)
    if n == 0:
        return {"n": 0, "coverage": float("nan"), "success": float("nan"), "errors": 0}
    return {
        "n": n,
        "coverage": 100.0 * float(np.mean([o.coverage for o in outcomes])),
        "success": 100.0 * float(np.mean([o.success for o in outcomes])),
        "errors": int(sum(o.error is not None for o in outcomes)),
    }
