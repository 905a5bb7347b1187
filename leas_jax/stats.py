"""Interval statistics of proportions (success rates, sensitivities) and confusion counts of a
condition against a ground truth, host-only."""

from __future__ import annotations

import math

import numpy as np


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


def confusion(predicted, truth) -> dict:
    """Confusion counts and rates of a condition against a ground truth ([..., N] bool each).

    Returns:
        dict: tp, fn, fp, tn (condition true/false among feasible/infeasible poses),
        sensitivity tp / (tp + fn) and specificity tn / (tn + fp) (NaN when undefined),
        as Python numbers for a single condition, arrays for a batch.
    """
    predicted = np.asarray(predicted, dtype=bool)
    truth = np.asarray(truth, dtype=bool)
    tp = np.sum(predicted & truth, axis=-1)
    fn = np.sum(~predicted & truth, axis=-1)
    fp = np.sum(predicted & ~truth, axis=-1)
    tn = np.sum(~predicted & ~truth, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        sensitivity = np.where(tp + fn > 0, tp / np.maximum(tp + fn, 1), np.nan)
        specificity = np.where(tn + fp > 0, tn / np.maximum(tn + fp, 1), np.nan)
    out = {"tp": tp, "fn": fn, "fp": fp, "tn": tn, "sensitivity": sensitivity, "specificity": specificity}
    if np.ndim(tp) == 0:
        out = {k: (int(v) if k in ("tp", "fn", "fp", "tn") else float(v)) for k, v in out.items()}
    return out


def rates(predicted, truth) -> dict:
    """`confusion` of one condition ([N] bool each) plus the 95 % Wilson intervals of its
    sensitivity and specificity (`sensitivity_95ci`, `specificity_95ci`)."""
    c = confusion(predicted, truth)
    return {
        **c,
        "sensitivity_95ci": wilson(c["tp"], c["tp"] + c["fn"]),
        "specificity_95ci": wilson(c["tn"], c["tn"] + c["fp"]),
    }
