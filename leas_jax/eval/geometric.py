"""Geometric evaluation of a policy (no contact planner): speed and safety.

These are the foundation's acceptance figures: on flat ground, the mean speed
along the target direction over 400 steps from random headings; on the
training arena, the fraction of episodes (random starts and target
directions) that never reach an invalid configuration.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from leas_jax.env import LeasEnv
from leas_jax.env.field import Heightfield
from leas_jax.steering.leas import rollout_batch, start_poses


@dataclass(frozen=True)
class GroundSpeed:
    """Flat-ground speed test. mean_speed: m/s along the target direction; per_episode: [N]."""

    mean_speed: float
    invalid_fraction: float
    per_episode: np.ndarray
    guides: list


def ground_speed(policy, terrain, field: Heightfield, n: int = 256, seed: int = 0,
                 steps: int = 400) -> GroundSpeed:
    """Mean speed along the target direction over `steps` steps from random headings.

    Starts are drawn in the terrain's scenario start region with a uniform
    yaw in [-180°, 180°) and zero speed; the target direction is the
    direction from the start region's centre to the scenario target (a far
    point along it keeps the direction constant). Displacement along it over
    the whole horizon / horizon duration: a path that ends early on an invalid
    pose keeps the distance it made.
    """
    scenario = terrain.scenario
    rng = np.random.default_rng(seed)
    (x0, y0), (x1, y1) = scenario.start_region
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    direction = np.asarray(scenario.target) - centre
    direction = direction / np.linalg.norm(direction)
    xy = rng.uniform([x0, y0], [x1, y1], size=(n, 2))
    yaw = rng.uniform(-np.pi, np.pi, size=n)
    starts = start_poses(field, np.column_stack([xy, yaw]), policy.config.env.nominal_root_height)
    targets = xy + 1000.0 * direction
    result = rollout_batch(policy, field, starts, targets, max_steps=steps, stop_at_target=False)
    final = result.poses[np.arange(n), result.lengths - 1, :2]
    along = (final - xy) @ direction / (steps * result.timestep)
    return GroundSpeed(mean_speed=float(along.mean()), invalid_fraction=float(result.invalid.mean()),
                       per_episode=along, guides=[result.guide(k) for k in range(n)])


@dataclass(frozen=True)
class ArenaEpisodes:
    """Random episodes on a terrain with the deterministic policy.

    Attributes:
        valid_fraction: fraction of episodes that never reach an invalid pose.
        stopped_fraction: fraction of valid episodes whose last 50 steps moved < 0.1 m
            (stopped before an obstacle rather than walking on).
        poses: [N, steps + 1, 4] world poses (frozen after an invalid pose).
        lengths: [N] valid poses per episode.
    """

    valid_fraction: float
    stopped_fraction: float
    mean_progress: float
    poses: np.ndarray
    lengths: np.ndarray


def arena_episodes(policy, field: Heightfield, n: int = 256, seed: int = 0, steps: int = 400) -> ArenaEpisodes:
    """Run `n` episodes from the env's own random resets (random start, yaw, speed, target direction)."""
    config = dataclasses.replace(policy.config.env, episode_length=steps + 1)

    @jax.jit
    def run(field, keys):
        env = LeasEnv(field, config)

        def one(key):
            state = env.reset(key)

            def step(carry, _):
                state, alive = carry
                new = env.step(state, policy(state.obs))
                alive = alive & (new.metrics["invalid"] == 0)
                state = jax.tree.map(lambda a, b: jnp.where(alive, a, b), new, state)
                return (state, alive), (state.pipeline_state.pose, alive)

            start = state.pipeline_state.pose
            (final, alive), (poses, kept) = jax.lax.scan(step, (state, jnp.asarray(True)), None, length=steps)
            progress = jnp.dot(final.pipeline_state.pos[:2] - start[:2], state.pipeline_state.target_dir)
            return jnp.concatenate([start[None], poses]), 1 + kept.sum(), alive, progress

        return jax.vmap(one)(keys)

    poses, lengths, alive, progress = jax.device_get(run(field, jax.random.split(jax.random.PRNGKey(seed), n)))
    moved_late = np.linalg.norm(poses[:, -1, :2] - poses[:, -51, :2], axis=1)
    stopped = alive & (moved_late < 0.1)
    return ArenaEpisodes(valid_fraction=float(alive.mean()),
                         stopped_fraction=float(stopped.sum() / max(alive.sum(), 1)),
                         mean_progress=float(progress.mean()), poses=np.asarray(poses), lengths=np.asarray(lengths))
