"""Reward terms of the LeaS MDP (paper §III-E). Pure and jittable.

The terms are the fields of `config.RewardWeights` (`NAMES`, in that order): each term
is computed here under its weight's name, `total` weighs them, and the env's metrics
report them as "reward/<name>". A new term is a new weight field and its line in `terms`.
"""

import dataclasses

import jax
import jax.numpy as jnp

from leas_jax.env import reachability
from leas_jax.env.config import EnvConfig, RewardWeights
from leas_jax.env.field import Heightfield

NAMES = tuple(f.name for f in dataclasses.fields(RewardWeights))


def terms(
    field: Heightfield,
    pose: jax.Array,
    vel: jax.Array,
    action: jax.Array,
    target_dir: jax.Array,
    config: EnvConfig,
) -> dict:
    """Named reward terms, unweighted, one per name of `NAMES`.

    Args:
        field: the terrain's heightfield (for the clearance term).
        pose: [4] (x, y, z, yaw) root pose after the step, world.
        vel: [3] world velocity after the step (m/s).
        action: [4] normalised action (a_x, a_y, a_z, omega) in [-1, 1].
        target_dir: [2] unit target direction, world, horizontal.
        config: speeds, limits and weights.

    Returns:
        dict of [] floats:
          direction   = -(|v - v*| / (2 v_max))^2, v* = target_speed * target_dir
          orientation = -(1 - u_ori . u_target)
          effort_orientation  = -(omega / omega_max)^2
          effort_acceleration = -(|a| / a_max)^2
          alive = 1
          clearance = -(fraction of the six poses `clearance_margin` away along the root
            frame's axes that are invalid), `reachability.clearance_shortfall`; not in the
            paper, computed only when its weight is not 0 (else 0).
    """
    action = jnp.clip(action, -1.0, 1.0)
    yaw = pose[3]
    desired = jnp.concatenate([config.target_speed * target_dir, jnp.zeros(1)])
    heading = jnp.stack([jnp.cos(yaw), jnp.sin(yaw)])
    clearance = (
        -reachability.clearance_shortfall(field, pose, config.clearance_margin, config.reachability)
        if config.rewards.clearance != 0.0
        else jnp.zeros(())
    )
    return {
        "direction": -((jnp.linalg.norm(vel - desired) / (2.0 * config.v_max)) ** 2),
        "orientation": -(1.0 - jnp.dot(heading, target_dir)),
        "effort_orientation": -(action[3] ** 2),
        "effort_acceleration": -jnp.sum(action[:3] ** 2),
        "alive": jnp.ones(()),
        "clearance": clearance,
    }


def zeros() -> dict:
    """Every term at 0 ([] floats): the metrics of a fresh episode."""
    return {name: jnp.zeros(()) for name in NAMES}


def total(reward_terms: dict, config: EnvConfig) -> jax.Array:
    """[] weighted sum of the terms (`NAMES`) with the weights of `config.rewards` (paper Table I)."""
    return sum(getattr(config.rewards, name) * reward_terms[name] for name in NAMES)
