"""Time scalings and paths of the motion's task references (pure NumPy)."""

from __future__ import annotations

import math

import numpy as np


def min_jerk(s) -> np.ndarray:
    """Minimum-jerk time scaling 10 s^3 - 15 s^4 + 6 s^5 of normalised times s [...] in [0, 1].

    Zero velocity and acceleration at both ends; peak velocity 1.875, peak acceleration
    10 / sqrt(3) = 5.774 (per unit time squared).
    """
    s = np.clip(np.asarray(s, dtype=np.float64), 0.0, 1.0)
    return s**3 * (10.0 - 15.0 * s + 6.0 * s * s)


MIN_JERK_PEAK_ACCELERATION = 10.0 / math.sqrt(3.0)


def shift_duration(distance: float, acceleration: float, minimum: float, dt: float) -> float:
    """Duration of a minimum-jerk move of `distance` m with peak acceleration <= `acceleration` m/s^2.

    Returns:
        seconds, at least `minimum`, rounded up to a multiple of `dt`.
    """
    needed = math.sqrt(MIN_JERK_PEAK_ACCELERATION * max(distance, 0.0) / acceleration)
    return math.ceil(max(needed, minimum) / dt - 1e-9) * dt


def bezier(points: np.ndarray, s) -> np.ndarray:
    """Bezier curve of control points [P, 3] at parameters s [N] in [0, 1] -> [N, 3] (de Casteljau)."""
    points = np.asarray(points, dtype=np.float64)
    s = np.asarray(s, dtype=np.float64)[:, None]
    layer = [np.broadcast_to(p, (len(s), 3)) for p in points]
    while len(layer) > 1:
        layer = [(1.0 - s) * a + s * b for a, b in zip(layer[:-1], layer[1:])]
    return np.array(layer[0])


def lift_path(start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Control points [3, 3] of a lift-off: leave the contact along +z, end at the lifted position.

    Args:
        start: [3] sole position in contact, world; end: [3] lifted sole position, world.
    """
    return np.array([start, [start[0], start[1], max(end[2], start[2])], end])


def landing_path(start: np.ndarray, end: np.ndarray, apex: float) -> np.ndarray:
    """Control points [4, 3] of a landing: rise to `apex` m, travel, come down along -z onto `end`.

    Args:
        start: [3] lifted sole position, world; end: [3] landing sole position, world;
        apex: height of the middle control points, m (the curve stays below it).
    """
    return np.array([start, [start[0], start[1], apex], [end[0], end[1], apex], end])


def slerp(rot0: np.ndarray, rot1: np.ndarray, s) -> np.ndarray:
    """Rotations [N, 3, 3] along the geodesic from rot0 [3, 3] to rot1 [3, 3] at fractions s [N]."""
    import pinocchio as pin

    rel = pin.log3(rot0.T @ rot1)
    return np.array([rot0 @ pin.exp3(rel * float(t)) for t in np.atleast_1d(s)])


def lerp(x0: np.ndarray, x1: np.ndarray, s) -> np.ndarray:
    """Points [N, D] from x0 [D] to x1 [D] at fractions s [N]."""
    s = np.asarray(s, dtype=np.float64)[:, None]
    return (1.0 - s) * np.asarray(x0, dtype=np.float64) + s * np.asarray(x1, dtype=np.float64)
