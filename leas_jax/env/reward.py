"""Reward terms of the LeaS MDP (paper §III-E). Pure and jittable."""

import jax
import jax.numpy as jnp

from leas_jax.env.config import EnvConfig


def terms(
    vel: jax.Array, yaw: jax.Array, action: jax.Array, target_dir: jax.Array, config: EnvConfig
) -> dict:
    """Named reward terms, unweighted.

    Args:
        vel: [3] world velocity after the step (m/s).
        yaw: [] heading after the step (rad).
        action: [4] normalised action (a_x, a_y, a_z, omega) in [-1, 1].
        target_dir: [2] unit target direction, world, horizontal.
        config: speeds and limits.

    Returns:
        dict of [] floats:
          direction   = -(|v - v*| / (2 v_max))^2, v* = target_speed * target_dir
          orientation = -(1 - u_ori . u_target)
          effort_orientation  = -(omega / omega_max)^2
          effort_acceleration = -(|a| / a_max)^2
          alive = 1
        The clearance term needs the terrain: `LeasEnv.transition` adds it.
    """
    action = jnp.clip(action, -1.0, 1.0)
    desired = jnp.concatenate([config.target_speed * target_dir, jnp.zeros(1)])
    heading = jnp.stack([jnp.cos(yaw), jnp.sin(yaw)])
    return {
        "direction": -((jnp.linalg.norm(vel - desired) / (2.0 * config.v_max)) ** 2),
        "orientation": -(1.0 - jnp.dot(heading, target_dir)),
        "effort_orientation": -(action[3] ** 2),
        "effort_acceleration": -jnp.sum(action[:3] ** 2),
        "alive": jnp.ones(()),
    }


def total(reward_terms: dict, config: EnvConfig) -> jax.Array:
    """Weighted sum of the terms with the paper's Table I weights."""
    w = config.rewards
    weights = {
        "direction": w.direction,
        "orientation": w.orientation,
        "effort_orientation": w.effort_orientation,
        "effort_acceleration": w.effort_acceleration,
        "alive": w.alive,
        "clearance": w.clearance,
    }
    return sum(weights[name] * value for name, value in reward_terms.items())
