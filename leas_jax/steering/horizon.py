"""How long LeaS may walk a route: its rollout horizon, from the route's length.

The horizon bounds how long LeaS may take, it is not a metric. Host code (NumPy), shared by
the evaluation and navigate, which both roll the policy out along routes.
"""

from __future__ import annotations

import math

import numpy as np

# LeaS horizon / time to walk the route at the target speed. The policy slows to ~0.06 m/s
# on eval_stairs, and with 1.5 (the first choice) 13 of 30 stairs guides were cut 0.3-0.8 m
# before the target with their whole length covered by the contact plan.
HORIZON_FACTOR = 2.5


def leas_horizon(
    start_xy, points, target_speed: float, timestep: float, minimum: int, factor: float = HORIZON_FACTOR
) -> int:
    """LeaS horizon (steps) for a route: `factor` x the time to walk it at the target speed,
    >= `minimum`.

    The paper's episodes last 400 steps (40 s, 7.2 m at 0.18 m/s); the bridge and
    circuit routes are longer, so the horizon grows with the route length.

    Args:
        start_xy: (x, y) world, where the route starts.
        points: [W, 2] the route's points, walked in order.
        target_speed: m/s; timestep: s per policy step.
        minimum: the fewest steps returned (the episode length).
        factor: horizon / time to walk the route.

    Returns:
        Number of policy steps.
    """
    polyline = np.concatenate(
        [np.asarray(start_xy, np.float64).reshape(1, 2), np.asarray(points).reshape(-1, 2)]
    )
    length = float(np.sum(np.hypot(*np.diff(polyline, axis=0).T)))
    return max(int(minimum), int(math.ceil(factor * length / (target_speed * timestep))))
