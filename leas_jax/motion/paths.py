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


# Windows (rise, travel, descend) of a swing phase's normalised time [0, 1], each move on a
# minimum-jerk scaling: the sole rises from its start to the apex, travels horizontally, and
# comes down from the apex to its end. A lift travels once the sole has left the contact's
# surroundings (the toe of a sole before a riser can be a centimetre from it, and the
# plan's lifted foot is as little as 3.5 cm above the step's edge); a landing rises over
# 0.7 of its time (from a key posture at rest, as slowly as a Bezier arc over all of it)
# and has arrived above its contact before the last of the descent (a step down or back).
LIFT_WINDOWS = ((0.0, 0.5), (0.3, 1.0), (0.5, 1.0))
LAND_WINDOWS = ((0.0, 0.7), (0.35, 0.85), (0.6, 1.0))


# Spans (out, back) of normalised time of a held bulge (`swing_path`): where a swing foot
# passes the stance leg close by (eval_bridge's beam), a bump over the travel
# window comes back while the swing shin is still beside the stance shin; a held bulge is out
# before the knees pass and back once the sole is over its contact. A lift moves out while
# its sole rises its first centimetres and comes back once high; a landing stays out until
# the last of its descent.
HELD_BULGES = {"lift": ((0.0, 0.2), (0.5, 1.0)), "land": ((0.0, 0.35), (0.85, 1.0))}


def window(t, span: tuple[float, float]) -> np.ndarray:
    """Minimum-jerk progress in [0, 1] at normalised times t [N] of a move over span = (t0, t1)."""
    t0, t1 = span
    return min_jerk((np.asarray(t, dtype=np.float64) - t0) / (t1 - t0))


def swing_path(
    start: np.ndarray,
    end: np.ndarray,
    apex: float,
    t,
    windows: tuple,
    offset: float = 0.0,
    away: np.ndarray | None = None,
    held: tuple | None = None,
) -> np.ndarray:
    """Positions [N, 3] (world) of a swing sole at normalised times t [N] in [0, 1].

    The height rises from start's to `apex` in the rise window and comes down to end's in
    the descent window; the horizontal position moves from start's to end's in the travel
    window, bulging `offset` m along away [2] (a horizontal unit vector) at its middle
    (16 p^2 (1 - p)^2 of the travel's progress p: no bulge, velocity or acceleration at its
    ends), or, with held = (out, back) two spans of t, going out over the first and back over
    the second (`bulge_profile`). Every coordinate has zero velocity and acceleration at
    t = 0 and 1; the sole is at start at t = 0, at end at t = 1, and never above `apex`.

    Args:
        start, end: [3] sole positions, world; apex: m, at least both ends' heights.
        windows: (rise, travel, descend) spans, LIFT_WINDOWS or LAND_WINDOWS.
        offset, away: the bulge, m, and its direction (unused where offset is 0).
        held: None (the bump), or the (out, back) spans of a held bulge (`HELD_BULGES`).
    """
    rise, travel, descend = windows
    start, end = np.asarray(start, dtype=np.float64), np.asarray(end, dtype=np.float64)
    out = np.empty((len(np.atleast_1d(t)), 3))
    progress = window(t, travel)
    out[:, :2] = start[:2] + progress[:, None] * (end[:2] - start[:2])
    if offset:
        out[:, :2] += (offset * bulge_profile(t, travel, held))[:, None] * np.asarray(away)
    out[:, 2] = start[2] + (apex - start[2]) * window(t, rise) + (end[2] - apex) * window(t, descend)
    return out


def bulge_profile(t, travel: tuple[float, float], held: tuple | None = None) -> np.ndarray:
    """Fraction [N] in [0, 1] of a swing bulge at normalised times t [N]: the bump
    16 p^2 (1 - p)^2 of the travel window's progress p (1 at its middle), or a held bulge
    going out over held[0] and back over held[1] (1 in between); zero velocity and
    acceleration at its ends either way."""
    if held is None:
        progress = window(t, travel)
        return 16.0 * progress**2 * (1.0 - progress) ** 2
    out, back = held
    return window(t, out) * (1.0 - window(t, back))


def slerp(rot0: np.ndarray, rot1: np.ndarray, s) -> np.ndarray:
    """Rotations [N, 3, 3] along the geodesic from rot0 [3, 3] to rot1 [3, 3] at fractions s [N]."""
    import pinocchio as pin

    rel = pin.log3(rot0.T @ rot1)
    return np.array([rot0 @ pin.exp3(rel * float(t)) for t in np.atleast_1d(s)])


def lerp(x0: np.ndarray, x1: np.ndarray, s) -> np.ndarray:
    """Points [N, D] from x0 [D] to x1 [D] at fractions s [N]."""
    s = np.asarray(s, dtype=np.float64)[:, None]
    return (1.0 - s) * np.asarray(x0, dtype=np.float64) + s * np.asarray(x1, dtype=np.float64)
