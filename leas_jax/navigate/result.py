"""What `navigate` returns: the verified plan, how it was found and why the query stopped."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# Why a query stopped (NavigationResult.reason).
REACHED = "reached"  # the plan covers the whole guide and a posture stands within 0.30 m of the goal
GOAL_INVALID = "goal-invalid"  # no valid root pose within the goal radius (inside a wall, over the void)
NO_PATH = "no-path"  # valid poses at the goal, but no lattice path reaches them
REPLAN_LIMIT = "replan-limit"  # the contact generator still fails after max_replans searches
NO_STANCE = "no-initial-stance"  # the contact generator finds no first posture at the start
GENERATOR_ERROR = "generator-error"  # the contact generator raised or its worker died


@dataclass(frozen=True)
class Attempt:
    """One search + rollout + contact planning of a query.

    Attributes:
        begin: guide index this attempt's segment starts at (0 for the first).
        guide_length: poses of the whole guide it produced.
        last_valid_index: the contact generator's answer on that guide (-1: none).
        coverage: its coverage.
        failure: (x, y) world of where the generator stopped (penalised after it unless the
            searched path is walked through it next), or None.
        search_reason: the search's reason it did not reach the goal, or None.
        kind: what walked its segment: "policy" (the LeaS rollout) or "path" (the searched
            lattice path itself, `loop.path_guide`, after the generator stopped on the policy's).
    """

    begin: int
    guide_length: int
    last_valid_index: int
    coverage: float
    failure: tuple[float, float] | None
    search_reason: str | None
    kind: str = "policy"


@dataclass(frozen=True)
class NavigationResult:
    """A navigate query's answer.

    Attributes:
        success: `reason == REACHED`.
        reason: one of the module's constants.
        message: one line for a person: what happened and, when not reached, how far the
            verified plan ends from the goal.
        plan: the best `ContactPlan` (the whole plan when reached, else the one whose valid
            part ends nearest the goal), or None when the generator gave none.
        guide: [T, 4] (x, y, z, yaw) world, the plan's guide path (None with no plan).
        waypoints: [W, 2] world, the points the policy followed last (the search's path,
            every `waypoint_spacing`).
        path: [P, 3] (x, y, yaw) world, the last lattice path.
        replans: searches after the first that the policy walked (what `max_replans` bounds;
            `attempts` holds those whose path was walked itself too).
        attempts: every `Attempt`, in order.
        final_distance: m from the plan's nearest posture root to the goal (nan: no plan).
        seconds: wall time per part: lattice, search, rollout, contact_planning, total.
        timestep: s between guide poses.
    """

    success: bool
    reason: str
    message: str
    plan: object
    guide: np.ndarray | None
    waypoints: np.ndarray
    path: np.ndarray
    replans: int
    attempts: tuple[Attempt, ...]
    final_distance: float
    seconds: dict = field(default_factory=dict)
    timestep: float = 0.1
