"""Interval statistics of proportions (success rates, sensitivities), host-only."""

from __future__ import annotations

import math


def wilson(successes: int, trials: int, z: float = 1.96) -> tuple[float, float]:
    """95 % (z = 1.96) Wilson score interval of a proportion, as fractions in [0, 1] (rounding
    would put the bounds of 0 or n successes a hair past them); (nan, nan) without trials."""
    if trials == 0:
        return math.nan, math.nan
    p = successes / trials
    centre = (p + z * z / (2 * trials)) / (1 + z * z / trials)
    half = z * math.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / (1 + z * z / trials)
    return max(0.0, centre - half), min(1.0, centre + half)


def newcombe_difference(a: tuple[int, int], b: tuple[int, int]) -> tuple[float, float, float]:
    """p_a - p_b with its 95 % interval from the two Wilson intervals (Newcombe 1998, method 10);
    a and b are (successes, trials) of two independent samples."""
    pa, pb = a[0] / a[1], b[0] / b[1]
    (la, ua), (lb, ub) = wilson(*a), wilson(*b)
    low = pa - pb - math.sqrt((pa - la) ** 2 + (ub - pb) ** 2)
    high = pa - pb + math.sqrt((ua - pa) ** 2 + (pb - lb) ** 2)
    return pa - pb, low, high
