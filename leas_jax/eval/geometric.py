"""Geometric evaluation of a policy (no contact planner): speed and safety.

These are the foundation's acceptance figures: on flat ground, the mean speed
along the target direction over 400 steps from random headings; on the
training arena, the fraction of episodes (random starts and target
directions) that never reach an invalid configuration.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from leas_jax.env import LeasEnv, reachability
from leas_jax.env.field import Heightfield, sample_nearest
from leas_jax.steering.leas import rollout_batch, start_poses

# Acceptance figures of a geometric policy (the run report and `leas arena-check` test them):
GROUND_SPEED_TARGET = 0.12  # m/s, mean ground speed on flat ground
ARENA_VALID_TARGET = 0.90  # fraction of arena episodes without an invalid pose


@dataclass(frozen=True)
class GroundSpeed:
    """Flat-ground speed test. mean_speed: m/s along the target direction; per_episode: [N]."""

    mean_speed: float
    invalid_fraction: float
    per_episode: np.ndarray
    guides: list


def ground_speed(
    policy, terrain, field: Heightfield, n: int = 256, seed: int = 0, steps: int = 400
) -> GroundSpeed:
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
    return GroundSpeed(
        mean_speed=float(along.mean()),
        invalid_fraction=float(result.invalid.mean()),
        per_episode=along,
        guides=[result.guide(k) for k in range(n)],
    )


@dataclass(frozen=True)
class ArenaEpisodes:
    """Random episodes on a terrain with the deterministic policy.

    Attributes:
        valid_fraction: fraction of episodes that never reach an invalid pose.
        stopped_fraction: fraction of valid episodes whose last 50 steps moved < 0.1 m
            (stopped before an obstacle rather than walking on).
        poses: [N, steps + 1, 4] world poses (frozen after an invalid pose).
        lengths: [N] valid poses per episode.
        failure_poses: [N, 4] the first invalid pose (x, y, z, yaw) of each episode; NaN
            rows for the episodes that stay valid.
        failure_velocities: [N, 3] world root velocity at that pose; NaN rows likewise.
    """

    valid_fraction: float
    stopped_fraction: float
    mean_progress: float
    poses: np.ndarray
    lengths: np.ndarray
    failure_poses: np.ndarray
    failure_velocities: np.ndarray


def arena_episodes(
    policy, field: Heightfield, n: int = 256, seed: int = 0, steps: int = 400
) -> ArenaEpisodes:
    """Run `n` episodes from the env's own random resets (random start, yaw, speed, target direction)."""
    config = dataclasses.replace(policy.config.env, episode_length=steps + 1)

    @jax.jit
    def run(field, keys):
        env = LeasEnv(field, config)

        def one(key):
            state = env.reset(key)

            def step(carry, _):
                state, alive, failure = carry
                new = env.step(state, policy(state.obs))
                ends = alive & (new.metrics["invalid"] > 0)
                failure = jnp.where(
                    ends, jnp.concatenate([new.pipeline_state.pose, new.pipeline_state.vel]), failure
                )
                alive = alive & ~ends
                state = jax.tree.map(lambda a, b: jnp.where(alive, a, b), new, state)
                return (state, alive, failure), (state.pipeline_state.pose, alive)

            start = state.pipeline_state.pose
            carry = (state, jnp.asarray(True), jnp.full(7, jnp.nan))
            (final, alive, failure), (poses, kept) = jax.lax.scan(step, carry, None, length=steps)
            progress = jnp.dot(final.pipeline_state.pos[:2] - start[:2], state.pipeline_state.target_dir)
            return jnp.concatenate([start[None], poses]), 1 + kept.sum(), alive, progress, failure

        return jax.vmap(one)(keys)

    poses, lengths, alive, progress, failure = jax.device_get(
        run(field, jax.random.split(jax.random.PRNGKey(seed), n))
    )
    moved_late = np.linalg.norm(poses[:, -1, :2] - poses[:, -51, :2], axis=1)
    stopped = alive & (moved_late < 0.1)
    return ArenaEpisodes(
        valid_fraction=float(alive.mean()),
        stopped_fraction=float(stopped.sum() / max(alive.sum(), 1)),
        mean_progress=float(progress.mean()),
        poses=np.asarray(poses),
        lengths=np.asarray(lengths),
        failure_poses=np.asarray(failure[:, :4]),
        failure_velocities=np.asarray(failure[:, 4:]),
    )


# Sectors of a bearing in the root frame (degrees, 0 = heading, counter-clockwise = left).
BEARING_SECTORS = ("ahead", "left", "behind", "right")


def bearing_sector(bearing_deg: np.ndarray) -> np.ndarray:
    """[...] sector names of bearings (deg, root frame): ahead within 45 degrees of the heading,
    left 45-135 degrees counter-clockwise, behind, right 45-135 degrees clockwise."""
    wrapped = (np.asarray(bearing_deg, np.float64) + 45.0) % 360.0  # ahead -> [0, 90)
    return np.asarray(BEARING_SECTORS)[(wrapped // 90.0).astype(int) % 4]


@dataclass(frozen=True)
class FailureBreakdown:
    """Why and where the episodes of an `ArenaEpisodes` end invalid.

    Attributes:
        invalid: number of episodes that end invalid.
        terms: {label: count}, label the reachability terms failed at the first invalid
            pose joined by "+" ("trunk_free", "left_touch", "left_touch+right_touch", ...).
        trunk_bearing: {sector: count} over the trunk failures: where the terrain inside
            the trunk cylinder lies around the root (centroid of the offending points,
            root frame; `bearing_sector`); "unlocated" counts those whose polar samples
            find no offending point.
        motion_bearing: {sector: count}: direction of the root's horizontal velocity in
            its own frame at the failure.
        speed_quartiles: [3] 25th, 50th, 75th percentiles of the horizontal speed at the
            failure (m/s).
        step_quartiles: [3] the same of the step at which the episode fails.
    """

    invalid: int
    terms: dict
    trunk_bearing: dict
    motion_bearing: dict
    speed_quartiles: list
    step_quartiles: list


@functools.partial(jax.jit, static_argnames="config")
def _terms_at(field: Heightfield, poses: jax.Array, config) -> dict:
    return jax.vmap(lambda pose: reachability.terms(field, pose, config))(poses)


def reachability_terms(field: Heightfield, poses: np.ndarray, config) -> dict:
    """{term name: bool [N] satisfied} of the reachability condition at poses [N, 4] (jitted once
    per `config` and shape)."""
    return jax.device_get(_terms_at(field, jnp.asarray(poses, jnp.float32), config))


# The label of an invalid pose at which every term of the cylinders holds: a policy trained with
# the learned condition (`EnvConfig.condition`) ends there because the network alone rejects it.
NO_CYLINDER_TERM = "no cylinder term"


def failure_breakdown(field: Heightfield, episodes: ArenaEpisodes, config) -> FailureBreakdown:
    """Classify the invalid episodes of `episodes` (host; the terms are evaluated jitted): by the
    terms of `config`'s cylinders that fail at the first invalid pose (`NO_CYLINDER_TERM` if none).

    Args:
        field: the heightfield the episodes ran on (built with `config`'s radii).
        episodes: from `arena_episodes`.
        config: the `ReachabilityConfig` the episodes were judged with.
    """
    failed = np.flatnonzero(~np.isnan(episodes.failure_poses[:, 0]))
    counts = lambda labels: {str(k): int(v) for k, v in zip(*np.unique(labels, return_counts=True))}  # noqa: E731
    if len(failed) == 0:
        return FailureBreakdown(0, {}, {}, {}, [], [])
    terms = reachability_terms(field, episodes.failure_poses[failed], config)
    labels = [
        "+".join(name for name, ok in terms.items() if not ok[k]) or NO_CYLINDER_TERM
        for k in range(len(failed))
    ]
    # Offending terrain of a trunk failure: polar samples of the trunk disk above its bottom.
    # (the raster of the condition takes the disk on the grid: reach one cell beyond the radius)
    radius = np.linspace(0.0, config.trunk_radius + float(field.resolution), 17)[1:]
    angle = np.linspace(-np.pi, np.pi, 144, endpoint=False)
    r, a = np.meshgrid(radius, angle)
    local = np.stack([r * np.cos(a), r * np.sin(a)], axis=-1).reshape(-1, 2)  # [P, 2] root frame
    yaw = episodes.failure_poses[failed, 3]
    rot = np.stack([np.stack([np.cos(yaw), -np.sin(yaw)], -1), np.stack([np.sin(yaw), np.cos(yaw)], -1)], -2)
    world = episodes.failure_poses[failed, None, :2] + np.einsum("nij,pj->npi", rot, local)  # [F, P, 2]
    heights = np.asarray(sample_nearest(field, field.heights, jnp.asarray(world, jnp.float32)))
    inside = heights > (episodes.failure_poses[failed, 2] + config.trunk_bottom)[:, None]  # [F, P]
    trunk = np.flatnonzero(~terms["trunk_free"])
    located = inside[trunk].any(axis=1)
    trunk, unlocated = trunk[located], int((~located).sum())
    weights = inside[trunk].astype(np.float64)  # [T, P]
    centroid = weights @ local / weights.sum(axis=1, keepdims=True)  # [T, 2] root frame
    velocity = episodes.failure_velocities[failed]
    local_velocity = np.einsum("nji,nj->ni", rot, velocity[:, :2])
    speed = np.linalg.norm(velocity[:, :2], axis=1)
    steps = episodes.lengths[failed]
    return FailureBreakdown(
        invalid=int(len(failed)),
        terms=counts(labels),
        trunk_bearing={
            **counts(bearing_sector(np.degrees(np.arctan2(centroid[:, 1], centroid[:, 0])))),
            **({"unlocated": unlocated} if unlocated else {}),
        },
        motion_bearing=counts(
            bearing_sector(np.degrees(np.arctan2(local_velocity[:, 1], local_velocity[:, 0])))
        ),
        speed_quartiles=[round(float(v), 4) for v in np.percentile(speed, [25, 50, 75])],
        step_quartiles=[float(v) for v in np.percentile(steps, [25, 50, 75])],
    )
