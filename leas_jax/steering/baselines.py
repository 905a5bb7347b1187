"""Pieces shared by the baseline steering methods (RBLin, RBKino, RBKino+RRT).

The baselines build planar paths `(x, y, yaw)` in NumPy; `lift` puts them on
the terrain (z = terrain height + nominal root height, the same rule LeaS
rollouts start from) and `valid_poses` runs the reachability condition of
the LeaS environment on many poses at once (jitted, vmapped), so that every
method is judged by the same geometric test.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from leas_jax.env import reachability
from leas_jax.env.config import EnvConfig, ReachabilityConfig
from leas_jax.env.field import Heightfield, sample_bilinear, sample_nearest

# Poses are padded to a multiple of this before the jitted checks so that
# paths of any length share a handful of compiled shapes.
_PAD = 256
# Speeds below this (m/s) give no heading: the previous yaw is held.
_STILL_SPEED = 1e-6
# m: terrain within this of void_height counts as void (boxes never sit that low).
_VOID_MARGIN = 1e-3


@dataclass(frozen=True)
class BaselineConfig:
    """Parameters of the baseline steering methods.

    Defaults are the LeaS environment's (docs/design.md §5) so that every method shares
    the timestep and the target speed (paper §IV-B: "The timestep and the norm
    of target velocities are the same for all three methods").
    """

    timestep: float = 0.10  # s, paper Table I
    target_speed: float = 0.18  # m/s, paper §IV: RBLin's walking speed
    # m/s, RBKino's per-axis velocity bound. HPP's Talos scripts use vMax = 0.30,
    # but the paper runs all methods at the same target speed norm (§IV-B), and
    # the contact generator is reliable below 0.18 m/s (§III-C); see DECISIONS
    # in rbkino.py.
    v_max: float = 0.18
    a_max: float = 0.10  # m/s^2, per-axis acceleration bound, HPP Talos scripts (aMax)
    # How RBKino slows its faster axes (`rbkino.steer`): "hpp", hpp-core's
    # Kinodynamic::fixedTimeTrajectory (a start velocity across the goal direction decays
    # over the whole path), or "cruise", +-a_max with a lower cruise velocity (that
    # velocity dies within ~0.1 s, turning the velocity-following yaw by up to 90 degrees
    # in one step). The RRT (rrt.py) keeps "cruise" (see rbkino.py).
    rbkino_sync: str = "hpp"
    rotation_steps: int = 100  # RBLin's in-place rotation, paper §IV-B.1 ("here 100 steps")
    # s between the poses of RBKino's continuous paths (RBKino, RBKino+RRT) handed to the
    # contact generator: HPP's generator samples a path every 0.01 s (hpp-rbprm-corba,
    # scenarios/abstract_contact_generator.py, `interpolate(0.01, ...)`). At `timestep` a root
    # starting turned away from its goal turns 30-75 degrees between two poses, more than
    # the generator follows (docs/results/2026-12-03-table2-hpp-sampling). RBLin's and
    # LeaS's guides are their poses at `timestep`; the RRT checks its edges at `timestep`.
    rbkino_timestep: float = 0.01
    nominal_root_height: float = 1.0  # m above the terrain, EnvConfig.nominal_root_height

    @classmethod
    def from_env(cls, env: EnvConfig, **overrides) -> BaselineConfig:
        """Config sharing the env's timestep, target speed, a_max and root height."""
        values = dict(
            timestep=env.timestep,
            target_speed=env.target_speed,
            v_max=env.target_speed,
            a_max=env.a_max,
            nominal_root_height=env.nominal_root_height,
        )
        values.update(overrides)
        return cls(**values)


@jax.jit
def _heights(field: Heightfield, xy: jax.Array) -> jax.Array:
    return sample_bilinear(field, xy)


def _padded(array: np.ndarray) -> tuple[np.ndarray, int]:
    """Pad rows to a multiple of _PAD by repeating the last row (or zeros if empty)."""
    n = len(array)
    size = max(_PAD, -(-n // _PAD) * _PAD)
    if n == 0:
        return np.zeros((size,) + array.shape[1:], np.float32), 0
    pad = np.repeat(array[-1:], size - n, axis=0)
    return np.concatenate([array, pad]).astype(np.float32), n


@functools.partial(jax.jit, static_argnums=(2, 3, 4))
def _lift_valid(
    field: Heightfield, planar: jax.Array, height: float, config: ReachabilityConfig, solid_ground: bool
):
    ground = sample_bilinear(field, planar[:, :2])
    poses = jnp.stack([planar[:, 0], planar[:, 1], ground + height, planar[:, 2]], axis=1)
    ok = jax.vmap(lambda pose: reachability.valid(field, pose, config))(poses)
    if solid_ground:
        ok = ok & (sample_nearest(field, field.heights, planar[:, :2]) > field.void_height + _VOID_MARGIN)
    return poses, ok


def lift_checked(
    field: Heightfield,
    planar,
    nominal_root_height: float,
    config: ReachabilityConfig = ReachabilityConfig(),
    solid_ground: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """`lift` and `valid_poses` in one jitted call (the RRT's inner loop).

    The reachability rasters treat the void under the terrain (`void_height`)
    as a floor: a root 1 m above the bottom of a hole has both legs "touching"
    it. The contact generator has no support surface there, so with
    `solid_ground` a pose whose root stands over the void is invalid too.

    Args:
        field: the heightfield.
        planar: [M, 3] (x, y, yaw), world.
        nominal_root_height: root height above the terrain (m).
        config: the reachability cylinders.
        solid_ground: also require terrain (not the void) under the root.

    Returns:
        (guide [M, 4] (x, y, z, yaw) float64, valid [M] bool).
    """
    planar = np.asarray(planar, np.float64).reshape(-1, 3)
    padded, n = _padded(planar.astype(np.float32))
    poses, ok = _lift_valid(
        field, jnp.asarray(padded), float(nominal_root_height), config, bool(solid_ground)
    )
    # to NumPy before slicing: slicing the jax array by a new `n` compiles a new XLA slice each time
    z = np.asarray(poses, np.float64)[:n, 2]
    return np.column_stack([planar[:, 0], planar[:, 1], z, planar[:, 2]]), np.asarray(ok)[:n]


def terrain_height(field: Heightfield, xy) -> np.ndarray:
    """Terrain height at world points, bilinear (host wrapper of a jitted gather).

    Args:
        field: the heightfield.
        xy: [M, 2] world points.

    Returns:
        [M] heights (m), float64.
    """
    xy = np.asarray(xy, np.float32).reshape(-1, 2)
    padded, n = _padded(xy)
    return np.asarray(_heights(field, jnp.asarray(padded)), np.float64)[:n]


def lift(field: Heightfield, planar, nominal_root_height: float) -> np.ndarray:
    """Planar path -> guide path on the terrain.

    Args:
        field: the heightfield.
        planar: [T, 3] (x, y, yaw), world.
        nominal_root_height: root height above the terrain (m).

    Returns:
        [T, 4] (x, y, z, yaw), world, z = terrain height + nominal_root_height.
    """
    planar = np.asarray(planar, np.float64).reshape(-1, 3)
    z = terrain_height(field, planar[:, :2]) + nominal_root_height
    return np.stack([planar[:, 0], planar[:, 1], z, planar[:, 2]], axis=1)


def valid_poses(field: Heightfield, poses, config: ReachabilityConfig = ReachabilityConfig()) -> np.ndarray:
    """Reachability condition (docs/design.md §5) of many root poses at once.

    Args:
        field: heightfield with reachability rasters built with `config`'s radii.
        poses: [M, 4] (x, y, z, yaw), world.
        config: the reachability cylinders.

    Returns:
        [M] bool.
    """
    poses = np.asarray(poses, np.float32).reshape(-1, 4)
    padded, n = _padded(poses)
    return np.asarray(reachability.valid_poses(field, jnp.asarray(padded), config))[:n]


def heading_from_velocity(velocity, initial_yaw: float) -> np.ndarray:
    """Yaw along the horizontal velocity, continuous (unwrapped).

    Where the robot is (almost) still the heading is undefined: the previous
    yaw is held, starting from `initial_yaw`.

    Args:
        velocity: [M, 2] world (vx, vy), m/s.
        initial_yaw: yaw (rad) held until the robot first moves.

    Returns:
        [M] yaw (rad), each value within pi of the previous one.
    """
    velocity = np.asarray(velocity, np.float64).reshape(-1, 2)
    moving = np.hypot(velocity[:, 0], velocity[:, 1]) > _STILL_SPEED
    raw = np.arctan2(velocity[:, 1], velocity[:, 0])
    # Hold: index of the last moving sample at or before each sample.
    last = np.where(moving, np.arange(len(raw)), -1)
    last = np.maximum.accumulate(last) if len(last) else last
    held = np.where(last >= 0, raw[np.maximum(last, 0)], initial_yaw)
    return unwrap_from(held, initial_yaw)


def unwrap_from(yaw, reference: float) -> np.ndarray:
    """Unwrap a yaw sequence so that its first value is within pi of `reference`. [M] -> [M]."""
    yaw = np.asarray(yaw, np.float64)
    if len(yaw) == 0:
        return yaw
    first = reference + wrap_angle(yaw[0] - reference)
    return np.unwrap(np.concatenate([[first], yaw[1:]]))


def wrap_angle(angle):
    """Angle(s) wrapped to [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi
