"""Stand-ins for the contact generator in navigate's closed-loop tests (the pool's `plan_fn`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from leas_jax.contacts.plan import coverage_of


@dataclass(frozen=True)
class StandInPlan:
    """What metrics and the loop read of a plan: posture roots, coverage, last valid index."""

    q: np.ndarray
    coverage: float
    last_valid_index: int


def plan_until(guide: np.ndarray, last: int) -> StandInPlan:
    """A plan covering the guide [T, 4] up to pose `last`: a posture root every 5 poses and at
    `last` (the other 36 coordinates zero)."""
    picks = np.unique(np.append(np.arange(0, last + 1, 5), last))
    q = np.zeros((len(picks), 39))
    q[:, :3] = guide[picks, :3]
    return StandInPlan(q, coverage_of(guide, last), last)
