"""RBLin: the straight-line steering method of the RB-PRM contact planner.

Paper §IV-B.1: "RBLin rotates in a fixed number of steps that needs to be
tuned (here 100 steps) and fails with rotations of high angular velocity".
The guide path is, one pose every `timestep`:

1. braking: with an initial speed v0 > 0 along the heading, the root slows down
   along its heading at a_max to rest, ceil(v0 / (a_max dt)) steps. RBLin is a
   geometric method without velocities, but a guide that starts moving and
   stops dead within one step is not one a humanoid can follow; braking at
   the bound the other methods use is the smallest change that keeps the
   guide continuous with the start state (v0 <= 0.07 m/s moves the root at
   most 2.5 cm). `brake=False` drops this phase (v0 is then ignored);
2. rotation in place to face the goal, over exactly `rotation_steps` steps
   at constant angular velocity (shortest direction);
3. the straight line to the goal at `target_speed`, the last pose on the goal.

HPP's own straight-line steering method (hpp-core src/steering-method/straight.cc,
`StraightPath::impl_compute`: `space_->interpolate(initial_, end_, u)`) turns
the root while it translates, over the whole path; the paper's RBLin turns
first, in a tuned number of steps, which is what this follows. At 100 steps a
180 degree turn runs at 18 deg/s, under the pi/9 rad/s (20 deg/s) yaw rate the
contact generator's step triggers are sized for (`GeneratorConfig.step_trigger_yaw`);
docs/results/2026-12-01-table2-baselines/ measures where it stops following.
"""

from __future__ import annotations

import math

import numpy as np

from leas_jax.env.field import Heightfield
from leas_jax.steering.baselines import BaselineConfig, lift, unwrap_from, wrap_angle


def braking_distance_steps(speed: float, a_max: float, timestep: float) -> tuple[np.ndarray, np.ndarray]:
    """Distances travelled along the heading while braking from `speed` to rest.

    Args:
        speed: initial speed along the heading (m/s), >= 0.
        a_max: deceleration (m/s^2).
        timestep: s between poses.

    Returns:
        (distances [B] at times dt, 2 dt, ..., the last one at rest; speeds [B]).
        B = ceil(speed / (a_max dt)); empty when speed is 0.
    """
    if speed <= 0.0:
        return np.zeros(0), np.zeros(0)
    stop_time = speed / a_max
    steps = int(math.ceil(stop_time / timestep - 1e-9))
    t = np.minimum(np.arange(1, steps + 1) * timestep, stop_time)
    # x(t) = v0 t - a t^2 / 2 for t <= v0 / a
    return speed * t - 0.5 * a_max * t**2, speed - a_max * t


def rblin_planar(
    start, goal, initial_speed: float = 0.0, config: BaselineConfig = BaselineConfig(), brake: bool = True
) -> np.ndarray:
    """RBLin planar path from a start pose to a goal point.

    Args:
        start: (x, y, yaw) or (x, y, z, yaw), world; z is ignored.
        goal: (x, y) world.
        initial_speed: speed along the start heading (m/s).
        config: timestep, target speed, a_max, rotation_steps.
        brake: brake to rest along the heading first (see module docstring).

    Returns:
        [T, 3] (x, y, yaw) world, T = 1 + braking steps + rotation_steps +
        ceil(distance / (target_speed dt)); the last pose is on the goal.
    """
    start = np.asarray(start, np.float64).reshape(-1)
    x, y, yaw0 = (start[0], start[1], start[-1])
    goal = np.asarray(goal, np.float64).reshape(2)
    poses = [(x, y, yaw0)]
    if brake:
        distances, _ = braking_distance_steps(float(initial_speed), config.a_max, config.timestep)
        for d in distances:
            poses.append((x + d * math.cos(yaw0), y + d * math.sin(yaw0), yaw0))
        x, y = poses[-1][0], poses[-1][1]
    delta = goal - np.array([x, y])
    distance = float(np.hypot(*delta))
    heading = math.atan2(delta[1], delta[0]) if distance > 1e-9 else yaw0
    turn = float(wrap_angle(heading - yaw0))
    steps = int(config.rotation_steps)
    for k in range(1, steps + 1):
        poses.append((x, y, yaw0 + turn * k / steps))
    walk_steps = int(math.ceil(distance / (config.target_speed * config.timestep) - 1e-9))
    for k in range(1, walk_steps + 1):
        s = min(k * config.target_speed * config.timestep, distance)
        poses.append((x + s * math.cos(heading), y + s * math.sin(heading), yaw0 + turn))
    planar = np.array(poses, np.float64)
    planar[:, 2] = unwrap_from(planar[:, 2], yaw0)
    return planar


def rblin(
    field: Heightfield,
    start,
    goal,
    initial_speed: float = 0.0,
    config: BaselineConfig = BaselineConfig(),
    brake: bool = True,
) -> np.ndarray:
    """RBLin guide path on the terrain.

    Args:
        field: the heightfield (z of every pose = terrain + nominal root height).
        start: (x, y, z, yaw) world start pose.
        goal: (x, y) world.
        initial_speed: speed along the start heading (m/s).
        config, brake: see `rblin_planar`.

    Returns:
        [T, 4] (x, y, z, yaw) world, one pose every `config.timestep`.
    """
    planar = rblin_planar(start, goal, initial_speed, config, brake)
    return lift(field, planar, config.nominal_root_height)


def rblin_through(
    field: Heightfield,
    start,
    points,
    initial_speed: float = 0.0,
    config: BaselineConfig = BaselineConfig(),
    brake: bool = True,
) -> np.ndarray:
    """RBLin chained through waypoints: rotate, walk, rotate, walk, ... ending on the last point.

    Args:
        field: the heightfield.
        start: (x, y, z, yaw) world.
        points: [W, 2] waypoints, the last one the goal.
        initial_speed, config, brake: see `rblin_planar` (braking happens once, at the start).

    Returns:
        [T, 4] guide path, world.
    """
    points = np.asarray(points, np.float64).reshape(-1, 2)
    pose = np.asarray(start, np.float64).reshape(-1)
    current = np.array([pose[0], pose[1], pose[-1]])
    parts = []
    for k, point in enumerate(points):
        part = rblin_planar(current, point, initial_speed if k == 0 else 0.0, config, brake)
        parts.append(part if k == 0 else part[1:])
        current = part[-1]
    return lift(field, np.concatenate(parts), config.nominal_root_height)
