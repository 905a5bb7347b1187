"""RBKino: the kinodynamic steering method of HPP (Fernbach et al. 2017).

"Kinodynamic randomized planning for humanoid robots using the reachability
condition" connects two states (position, velocity) of the root with, on each
axis, a double integrator under per-axis bounds |v| <= v_max, |a| <= a_max.
This follows hpp-core's `steeringMethod::Kinodynamic` (src/steering-method/
steering-kinodynamic.cc) and `KinodynamicOrientedPath` (src/kinodynamic-
oriented-path.cc):

1. for every axis, the minimum-time trajectory (`computeMinTime`): accelerate
   at +-a_max, coast at +-v_max if the bound is hit, decelerate at -+a_max;
2. the duration T of the slowest axis is kept; every other axis is slowed down
   to last exactly T (`fixedTimeTrajectory`): a two-segment profile whose
   acceleration +-a (|a| <= a_max) is the larger root of eq. (20)
       T^2 a^2 + (2 T (v0 + v1) - 4 d) a - (v1 - v0)^2 = 0,
   or, when that profile would exceed v_max, three segments that coast at
   +-v_max with the acceleration that covers d in T. A slowed axis therefore
   changes its velocity gently over the whole duration: a start velocity
   across the goal direction decays over the path instead of within 0.1 s;
3. the root yaw is the direction of the horizontal velocity
   (`Kinodynamic/forceYawOrientation`, set by hpp-rbprm-corba's Talos
   flat-ground and navigation scenarios), held while the robot is still.

With non-zero end velocities some durations longer than an axis's minimum
time have no bounded trajectory at all (HPP's "infeasible intervals", e.g.
v0 = v1 = 0.1 m/s and 5 cm to go in 2 s); the synchronised duration is then
the smallest T >= the slowest minimum time at which every axis is feasible,
found by stepping T up and bisecting (exact where HPP's `computeMaxRequiredTime`
uses the intervals of the bang-bang family). The kinodynamic RRT (`rrt.py`)
keeps the former synchronisation, +-a_max with a lower cruise velocity
(`steer(..., sync="cruise")`): with HPP's, its search no longer crosses
tests/test_steering_rrt.py's 0.30 m beam at seed 0 within that test's 3000
iterations.

Decisions (document, not paper): the path starts with the initial velocity
along the start heading (paper §IV-B: "the initial velocity direction of the
robot is the same as its orientation"; HPP's `orienteInitAndGoal` turns the
start configuration to its velocity) and ends at rest at the goal, where the
last heading is held (HPP turns to the goal configuration's orientation; our
goal is a point); it works on x and y (z follows the terrain, as for the other
methods; HPP's Talos scripts bound the vertical velocity to 0); v_max defaults
to the target speed 0.18 m/s (`BaselineConfig`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from leas_jax.env.field import Heightfield
from leas_jax.steering.baselines import BaselineConfig, heading_from_velocity, lift

_BISECTION_STEPS = 80  # halvings of the cruise-velocity interval: far below float64 resolution
# Synchronisations of the faster axes: HPP's fixed-time profile, or +-a_max with a lower cruise velocity.
SYNCS = ("hpp", "cruise")


def min_time(p0, p1, v0, v1, v_max: float, a_max: float) -> np.ndarray:
    """Minimum time of the 1-D double integrator from (p0, v0) to (p1, v1). Broadcasts.

    For a direction s in {+1, -1} the profile accelerates at s a_max then
    decelerates at -s a_max; its peak velocity solves
        d = (vp^2 - v0^2) / (2 s a) + (vp^2 - v1^2) / (2 s a)   =>   vp^2 = s a d + (v0^2 + v1^2) / 2,
    capped at v_max with a coast phase. The feasible direction with the
    shortest time wins.

    Args:
        p0, p1, v0, v1: arrays (m, m/s); |v0|, |v1| <= v_max.
        v_max, a_max: bounds (m/s, m/s^2).

    Returns:
        minimum durations (s), same broadcast shape.
    """
    p0, p1, v0, v1 = np.broadcast_arrays(*(np.asarray(a, np.float64) for a in (p0, p1, v0, v1)))
    d = p1 - p0
    best = np.full(d.shape, np.inf)
    for s in (1.0, -1.0):
        a = s * a_max
        square = s * a_max * d + 0.5 * (v0**2 + v1**2)
        vp = s * np.sqrt(np.maximum(square, 0.0))
        capped = np.abs(vp) > v_max
        vp = np.where(capped, s * v_max, vp)
        t1 = (vp - v0) / a
        t2 = (vp - v1) / a
        ramps = (vp**2 - v0**2) / (2 * a) + (vp**2 - v1**2) / (2 * a)
        with np.errstate(divide="ignore", invalid="ignore"):
            tc = np.where(capped, (d - ramps) / np.where(capped, vp, 1.0), 0.0)
        ok = (square >= -1e-12) & (t1 >= -1e-9) & (t2 >= -1e-9) & (tc >= -1e-9)
        total = np.maximum(t1, 0) + np.maximum(tc, 0) + np.maximum(t2, 0)
        best = np.where(ok & (total < best), total, best)
    return best


def _three_phase(vc, v0, v1, duration, a_max):
    """Phase times and length of the profile v0 -> vc (ramp), coast, vc -> v1 (ramp) at +-a_max."""
    t1 = np.abs(vc - v0) / a_max
    t2 = np.abs(v1 - vc) / a_max
    tc = duration - t1 - t2
    length = 0.5 * (v0 + vc) * t1 + vc * tc + 0.5 * (vc + v1) * t2
    return t1, tc, t2, length


def _cruise_bounds(duration, v0, v1, v_max, a_max):
    """Feasible cruise velocities: |vc| <= v_max and |vc - v0| + |vc - v1| <= a_max T. -> (lo, hi) [A]."""
    lo = np.maximum(-v_max, 0.5 * (v0 + v1 - a_max * duration))
    hi = np.minimum(v_max, 0.5 * (v0 + v1 + a_max * duration))
    return lo, np.maximum(hi, lo)


def _feasible(duration, d, v0, v1, v_max, a_max, tol: float = 1e-9) -> bool:
    """True when every axis can cover d in exactly `duration` (D(lo) <= d <= D(hi), D monotone)."""
    lo, hi = _cruise_bounds(duration, v0, v1, v_max, a_max)
    shortest = _three_phase(lo, v0, v1, duration, a_max)[3]
    longest = _three_phase(hi, v0, v1, duration, a_max)[3]
    return bool(np.all((shortest <= d + tol) & (longest >= d - tol)))


def _first_feasible(start, d, v0, v1, v_max, a_max) -> float:
    """Smallest duration >= start at which every axis is feasible (step up, then bisect)."""
    step = 0.05  # s, finer than the 0.1 s guide timestep
    low, high = start, start + step
    while not _feasible(high, d, v0, v1, v_max, a_max):
        low, high, step = high, high + step, step * 1.5
        if high > start + 1e4:
            raise ValueError(f"rbkino: no common duration for d={d}, v0={v0}, v1={v1}")
    for _ in range(60):
        mid = 0.5 * (low + high)
        low, high = (low, mid) if _feasible(mid, d, v0, v1, v_max, a_max) else (mid, high)
    return high


def _cruise_velocity(duration, d, v0, v1, v_max, a_max) -> np.ndarray:
    """Per-axis cruise velocity covering d in `duration`: bisection on the monotone D(vc). [A]."""
    lo, hi = _cruise_bounds(duration, v0, v1, v_max, a_max)
    for _ in range(_BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        short = _three_phase(mid, v0, v1, duration, a_max)[3] < d
        lo = np.where(short, mid, lo)
        hi = np.where(short, hi, mid)
    return 0.5 * (lo + hi)


def _phase_end(v0, t1, tc, t2, a1, vc):
    """Distance and end velocity of the profile a1 for t1, coast at vc for tc, -a1 for t2. [A]."""
    distance = v0 * t1 + 0.5 * a1 * t1**2 + vc * tc + vc * t2 - 0.5 * a1 * t2**2
    return distance, vc - a1 * t2


def fixed_time_profile(duration, d, v0, v1, v_max: float, a_max: float, tol: float = 1e-7):
    """HPP's fixed-duration profile of each axis (`Kinodynamic::fixedTimeTrajectory`).

    Two segments, +a for t1 then -a for t2 = T - t1, reach (d, v1) when
        t1 = ((v1 - v0) / a + T) / 2   and   T^2 a^2 + (2 T (v0 + v1) - 4 d) a - (v1 - v0)^2 = 0
    (eq. 20 of Fernbach et al. 2017); the root of larger |a| is kept. If the peak
    velocity v0 + a t1 exceeds v_max, three segments coast at vL = sign(a) v_max:
        t1 = (vL - v0) / a,  t2 = (vL - v1) / a,  a = ((vL - v0)^2 + (vL - v1)^2) / (2 (vL T - d)).
    An axis with a = 0 (d = v0 T, v1 = v0) moves at constant velocity.

    Args:
        duration: T (s).
        d, v0, v1: [A] displacement (m), start and end velocity (m/s).
        v_max, a_max: bounds.
        tol: m and m/s, end-state error above which an axis has no such profile.

    Returns:
        (t1, tc, t2, a1, vc, ok): [A] phase times, first acceleration (the last
        one is -a1), coast velocity (the peak of a two-segment profile) and
        whether the profile is valid (phases >= 0, bounds kept, end state reached).
    """
    T = float(duration)
    d, v0, v1 = (np.asarray(a, np.float64) for a in (d, v0, v1))
    b = 2.0 * T * (v0 + v1) - 4.0 * d
    c = -((v1 - v0) ** 2)
    # Stable roots of T^2 a^2 + b a + c: q / T^2 and c / q (their product c / T^2 <= 0).
    q = -0.5 * (b + np.where(b >= 0, 1.0, -1.0) * np.sqrt(b * b - 4.0 * T * T * c))
    with np.errstate(divide="ignore", invalid="ignore"):
        x1 = q / (T * T)
        x2 = np.where(q != 0, c / q, 0.0)
    a = np.clip(np.where(np.abs(x1) >= np.abs(x2), x1, x2), -a_max, a_max)
    still = np.abs(a) < 1e-15
    safe_a = np.where(still, 1.0, a)
    t1 = np.where(still, 0.0, 0.5 * ((v1 - v0) / safe_a + T))
    peak = v0 + a * t1
    coast = np.abs(peak) > v_max
    # Three segments where the peak exceeds v_max.
    v_lim = np.where(a >= 0, v_max, -v_max)
    with np.errstate(divide="ignore", invalid="ignore"):
        a3 = ((v_lim - v0) ** 2 + (v_lim - v1) ** 2) / (2.0 * (v_lim * T - d))
    a3 = np.clip(np.where(np.isfinite(a3), a3, 0.0), -a_max, a_max)
    safe_a3 = np.where(np.abs(a3) < 1e-15, 1.0, a3)
    t1 = np.where(coast, (v_lim - v0) / safe_a3, t1)
    t2 = np.where(coast, (v_lim - v1) / safe_a3, np.where(still, 0.0, T - t1))
    tc = np.where(coast, T - t1 - t2, np.where(still, T, 0.0))
    a1 = np.where(coast, a3, np.where(still, 0.0, a))
    vc = np.where(coast, v_lim, np.where(still, v0, peak))
    distance, end_velocity = _phase_end(v0, t1, tc, t2, a1, vc)
    ok = (
        (np.minimum(np.minimum(t1, tc), t2) >= -1e-9)
        & (np.abs(vc) <= v_max + 1e-9)
        & (np.abs(distance - d) <= tol)
        & (np.abs(end_velocity - v1) <= tol)
    )
    return np.maximum(t1, 0.0), np.maximum(tc, 0.0), np.maximum(t2, 0.0), a1, vc, ok


@dataclass(frozen=True)
class KinoProfile:
    """Synchronised per-axis three-phase profiles, all of the same duration.

    Axis k: acceleration a1[k] for t1[k] (v0 -> vc), coast at vc[k] for tc[k],
    acceleration a2[k] for t2[k] (vc -> v1); t1 + tc + t2 = duration.

    Attributes:
        duration: s.
        p0, v0, v1: [A] start position, start and end velocity per axis.
        t1, tc, t2, a1, a2, vc: [A] phase durations, accelerations, cruise velocity.
    """

    duration: float
    p0: np.ndarray
    v0: np.ndarray
    v1: np.ndarray
    t1: np.ndarray
    tc: np.ndarray
    t2: np.ndarray
    a1: np.ndarray
    a2: np.ndarray
    vc: np.ndarray

    def state(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Position and velocity at times t (clipped to [0, duration]).

        Args:
            t: [M] times (s).

        Returns:
            (position [M, A], velocity [M, A]).
        """
        t = np.clip(np.asarray(t, np.float64).reshape(-1, 1), 0.0, self.duration)
        s1 = np.minimum(t, self.t1)
        sc = np.clip(t - self.t1, 0.0, self.tc)
        s2 = np.clip(t - self.t1 - self.tc, 0.0, self.t2)
        pos = (
            self.p0
            + self.v0 * s1
            + 0.5 * self.a1 * s1**2
            + self.vc * sc
            + self.vc * s2
            + 0.5 * self.a2 * s2**2
        )
        vel = np.where(
            t <= self.t1,
            self.v0 + self.a1 * s1,
            np.where(t <= self.t1 + self.tc, self.vc, self.vc + self.a2 * s2),
        )
        return pos, vel


def steer(
    p0, v0, p1, v1, v_max: float, a_max: float, duration: float | None = None, sync: str = "cruise"
) -> KinoProfile:
    """RBKino between two states: the slowest axis's minimum time, every axis lasting it.

    Args:
        p0, v0: [A] start position (m) and velocity (m/s).
        p1, v1: [A] end position and velocity.
        v_max, a_max: per-axis bounds.
        duration: force a duration (s) >= the minimum; default the slowest axis's minimum time.
        sync: how the faster axes are slowed to the duration: "hpp", HPP's fixed-time profile
            (`fixed_time_profile`, what `rbkino` uses by default: `BaselineConfig.rbkino_sync`);
            "cruise", +-a_max with a lower cruise velocity (bisection on the monotone length),
            which the RRT (`rrt.py`) calls with.

    Returns:
        the `KinoProfile`.
    """
    p0, v0, p1, v1 = (np.asarray(a, np.float64).reshape(-1) for a in (p0, v0, p1, v1))
    # A start velocity a hair above the bound (float32 inputs) would make no profile feasible.
    v0 = np.clip(v0, -v_max, v_max)
    v1 = np.clip(v1, -v_max, v_max)
    fastest = min_time(p0, p1, v0, v1, v_max, a_max)
    if not np.all(np.isfinite(fastest)):
        raise ValueError(f"rbkino: no profile from v0={v0} to v1={v1} within v_max={v_max}")
    T = float(np.max(fastest)) if duration is None else float(duration)
    if T < float(np.max(fastest)) - 1e-9:
        raise ValueError(f"rbkino: duration {T} below the minimum time {float(np.max(fastest))}")
    if duration is None and not _feasible(T, p1 - p0, v0, v1, v_max, a_max):
        T = _first_feasible(T, p1 - p0, v0, v1, v_max, a_max)
    if sync not in SYNCS:
        raise ValueError(f"rbkino: sync {sync!r} is not one of {SYNCS}")
    if sync == "hpp":
        t1, tc, t2, a1, vc, ok = fixed_time_profile(T, p1 - p0, v0, v1, v_max, a_max)
        if not np.all(ok):  # an error, not a wrong path
            raise ValueError(
                f"rbkino: no fixed-time profile of {T} s from v0={v0} to v1={v1} over {p1 - p0} m"
            )
        a2 = -a1
    else:
        vc = _cruise_velocity(T, p1 - p0, v0, v1, v_max, a_max)
        t1, tc, t2, _ = _three_phase(vc, v0, v1, T, a_max)
        tc = np.maximum(tc, 0.0)
        a1 = np.sign(vc - v0) * a_max
        a2 = np.sign(v1 - vc) * a_max
    return KinoProfile(duration=T, p0=p0, v0=v0, v1=v1, t1=t1, tc=tc, t2=t2, a1=a1, a2=a2, vc=vc)


def sample_times(duration: float, timestep: float) -> np.ndarray:
    """0, dt, 2 dt, ... and `duration` itself as the last time. [ceil(duration / dt) + 1]."""
    steps = int(math.ceil(duration / timestep - 1e-9))
    return np.minimum(np.arange(steps + 1) * timestep, duration)


def rbkino_states(
    start_xy, start_velocity, goal_xy, goal_velocity=(0.0, 0.0), config: BaselineConfig = BaselineConfig()
) -> tuple[np.ndarray, np.ndarray]:
    """Sampled RBKino states between two planar states.

    Args:
        start_xy, start_velocity: [2] world position (m), velocity (m/s).
        goal_xy, goal_velocity: [2].
        config: v_max, a_max, timestep.

    Returns:
        (positions [T, 2], velocities [T, 2]) at t = k dt, the last at the full duration.
    """
    profile = steer(
        start_xy, start_velocity, goal_xy, goal_velocity, config.v_max, config.a_max, sync=config.rbkino_sync
    )
    return profile.state(sample_times(profile.duration, config.timestep))


def rbkino_planar(
    start, goal, initial_speed: float = 0.0, config: BaselineConfig = BaselineConfig()
) -> np.ndarray:
    """RBKino planar path: start at `initial_speed` along the start yaw, end at rest on the goal.

    Args:
        start: (x, y, yaw) or (x, y, z, yaw) world.
        goal: (x, y) world.
        initial_speed: m/s along the start yaw.
        config: v_max, a_max, timestep.

    Returns:
        [T, 3] (x, y, yaw), yaw along the velocity (the start yaw until the robot moves).
    """
    start = np.asarray(start, np.float64).reshape(-1)
    yaw0 = start[-1]
    velocity0 = initial_speed * np.array([math.cos(yaw0), math.sin(yaw0)])
    pos, vel = rbkino_states(start[:2], velocity0, goal, (0.0, 0.0), config)
    yaw = heading_from_velocity(vel, yaw0)
    yaw[0] = yaw0  # the start velocity, if any, is along the start yaw
    return np.column_stack([pos, yaw])


def rbkino(
    field: Heightfield, start, goal, initial_speed: float = 0.0, config: BaselineConfig = BaselineConfig()
) -> np.ndarray:
    """RBKino guide path on the terrain.

    Args:
        field: the heightfield (z = terrain + nominal root height).
        start: (x, y, z, yaw) world.
        goal: (x, y) world.
        initial_speed: m/s along the start yaw.
        config: see `BaselineConfig`.

    Returns:
        [T, 4] (x, y, z, yaw), world, one pose every `config.timestep` (the last at the goal, at rest).
    """
    return lift(field, rbkino_planar(start, goal, initial_speed, config), config.nominal_root_height)


def rbkino_through(
    field: Heightfield, start, points, initial_speed: float = 0.0, config: BaselineConfig = BaselineConfig()
) -> np.ndarray:
    """RBKino chained through waypoints, stopping at each one (HPP connects waypoints at rest).

    Args:
        field: the heightfield.
        start: (x, y, z, yaw) world.
        points: [W, 2] waypoints, the last one the goal.
        initial_speed, config: see `rbkino`.

    Returns:
        [T, 4] guide path.
    """
    points = np.asarray(points, np.float64).reshape(-1, 2)
    current = np.asarray(start, np.float64).reshape(-1)
    current = np.array([current[0], current[1], current[-1]])
    parts = []
    for k, point in enumerate(points):
        part = rbkino_planar(current, point, initial_speed if k == 0 else 0.0, config)
        parts.append(part if k == 0 else part[1:])
        current = part[-1]
    planar = np.concatenate(parts)
    planar[:, 2] = np.unwrap(planar[:, 2])
    return lift(field, planar, config.nominal_root_height)
