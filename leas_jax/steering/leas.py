"""LeaS steering: roll a trained policy out into guide paths.

`rollout_batch` is jitted over a batch of starts; `rollout` is the one-path
convenience the public API exposes. Targets are points (the target
direction is recomputed each step) or lists of waypoints followed in order,
switching to the next one within `switch_distance` (paper §IV-D).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from leas_jax.env import LeasEnv, heightfield_from_terrain
from leas_jax.env.config import EnvConfig
from leas_jax.env.field import Heightfield, sample_bilinear
from leas_jax.errors import UsageError


@dataclass(frozen=True)
class RolloutResult:
    """Batch of guide paths.

    Attributes:
        poses: [N, T + 1, 4] (x, y, z, yaw) world; entries after `lengths[n]` repeat the last pose.
        lengths: [N] number of valid poses of each path (start included).
        invalid: [N] the path met a pose the reachability condition rejects: with
            `stop_at_invalid` it ends before that pose, without it the pose is kept.
        reached: [N] the root came within the threshold of the last target.
        timestep: s between poses.
    """

    poses: np.ndarray
    lengths: np.ndarray
    invalid: np.ndarray
    reached: np.ndarray
    timestep: float

    def guide(self, n: int) -> np.ndarray:
        """[lengths[n], 4] guide path of start n."""
        return self.poses[n, : self.lengths[n]]


@functools.lru_cache(maxsize=16)
def _compiled_rollout(
    env_config: EnvConfig,
    policy_key,
    max_steps: int,
    switch_distance: float,
    stop_at_target: bool,
    stop_at_invalid: bool,
):
    """Jitted batch rollout for one env config and horizon (cached)."""
    policy = policy_key.policy
    env_config = dataclasses.replace(env_config, stop_at_target=False, episode_length=max_steps + 1)

    def run(field: Heightfield, starts, speeds, waypoints, n_waypoints):
        env = LeasEnv(field, env_config)

        def one(start, speed, wps, n_wp):
            state = env.reset_to(start, speed, target_point=wps[0])

            def step(carry, _):
                state, wp_index, alive, reached, invalid = carry
                root = state.pipeline_state
                action = policy(state.obs)
                new = env.step(state, action)
                new_root = new.pipeline_state
                dist = jnp.linalg.norm(new_root.pos[:2] - wps[wp_index])
                last = wp_index >= n_wp - 1
                hit_last = last & (dist < switch_distance)
                advance = (~last) & (dist < switch_distance)
                wp_index = wp_index + advance.astype(jnp.int32)
                new_root = new_root.replace(target_point=wps[wp_index])
                new = new.replace(pipeline_state=new_root)
                now_invalid = alive & (new.metrics["invalid"] > 0)
                keep = alive & ~(now_invalid & stop_at_invalid)
                state = jax.tree.map(lambda a, b: jnp.where(keep, a, b), new, state)
                pose = jnp.where(keep, new_root.pose, root.pose)
                reached = reached | (keep & hit_last)
                invalid = invalid | now_invalid
                alive_next = keep & ~(hit_last & stop_at_target)
                return (state, wp_index, alive_next, reached, invalid), (pose, keep)

            init = (
                state,
                jnp.zeros((), jnp.int32),
                jnp.asarray(True),
                jnp.asarray(False),
                jnp.asarray(False),
            )
            (_, _, _, reached, invalid), (poses, kept) = jax.lax.scan(step, init, None, length=max_steps)
            poses = jnp.concatenate([start[None], poses], axis=0)
            return poses, 1 + kept.sum(), invalid, reached

        return jax.vmap(one)(starts, speeds, waypoints, n_waypoints)

    return jax.jit(run)


@dataclass(frozen=True)
class _PolicyKey:
    """Hashable handle so that compiled rollouts are cached per policy object."""

    policy: object

    def __hash__(self):
        return id(self.policy)

    def __eq__(self, other):
        return isinstance(other, _PolicyKey) and other.policy is self.policy


def start_poses(field: Heightfield, starts_xy_yaw: np.ndarray, nominal_root_height: float) -> np.ndarray:
    """(x, y, yaw) starts -> [N, 4] poses at nominal height above the terrain."""
    starts = np.asarray(starts_xy_yaw, dtype=np.float32).reshape(-1, 3)
    z = np.asarray(sample_bilinear(field, jnp.asarray(starts[:, :2]))) + nominal_root_height
    return np.stack([starts[:, 0], starts[:, 1], z, starts[:, 2]], axis=1)


def rollout_batch(
    policy,
    field: Heightfield,
    starts: np.ndarray,
    targets,
    speeds=None,
    max_steps: int | None = None,
    switch_distance: float | None = None,
    stop_at_target: bool = True,
    stop_at_invalid: bool = True,
) -> RolloutResult:
    """Roll the deterministic policy from N starts.

    Args:
        policy: a `leas_jax.training.Policy`.
        field: terrain heightfield.
        starts: [N, 4] (x, y, z, yaw) world poses.
        targets: [N, 2] target points, or [N, W, 2] waypoint lists (same W for all;
            pad by repeating the last waypoint).
        speeds: [N] initial speeds along the heading (m/s); default 0.
        max_steps: horizon; default the policy's episode length (400).
        switch_distance: switch waypoints / count the target reached within this
            distance (m); default the env's target_reached_distance (0.20 m).
        stop_at_target: end a path when its last target is reached.
        stop_at_invalid: end a path before the first pose the reachability condition
            rejects (the training episode's termination); False rolls on through it,
            leaving the contact generator alone to judge the path, as it judges the
            baselines' paths.
    """
    env_config = policy.config.env
    starts = np.asarray(starts, np.float32).reshape(-1, 4)
    n = len(starts)
    waypoints = np.asarray(targets, np.float32)
    if waypoints.ndim == 2:
        waypoints = waypoints[:, None, :]
    if waypoints.shape[0] != n or waypoints.shape[-1] != 2:
        raise UsageError(f"targets must be [N, 2] or [N, W, 2] with N = {n}, got shape {waypoints.shape}")
    speeds = (
        np.zeros(n, np.float32) if speeds is None else np.broadcast_to(np.asarray(speeds, np.float32), (n,))
    )
    max_steps = int(max_steps or env_config.episode_length)
    switch = float(switch_distance or env_config.target_reached_distance)
    run = _compiled_rollout(
        env_config, _PolicyKey(policy), max_steps, switch, bool(stop_at_target), bool(stop_at_invalid)
    )
    n_wp = np.full(n, waypoints.shape[1], np.int32)
    poses, lengths, invalid, reached = jax.device_get(run(field, starts, speeds, waypoints, n_wp))
    return RolloutResult(
        poses=np.asarray(poses),
        lengths=np.asarray(lengths),
        invalid=np.asarray(invalid),
        reached=np.asarray(reached),
        timestep=env_config.timestep,
    )


def rollout(
    policy,
    terrain,
    start,
    target,
    speed: float = 0.0,
    max_steps: int | None = None,
    waypoints=None,
    stop_at_target: bool = True,
) -> np.ndarray:
    """Guide path of the policy from one start to a target.

    Args:
        policy: a `leas_jax.training.Policy` (see `load_policy`).
        terrain: a `leas_jax.terrain.Terrain`.
        start: (x, y, yaw) world; z is set at the nominal height above the terrain.
        target: (x, y) world target point (the last one when `waypoints` are given).
        speed: initial speed along the heading (m/s).
        max_steps: horizon (default 400).
        waypoints: optional [W, 2] points followed in order before `target`.
        stop_at_target: end the path within 0.20 m of the target.

    Returns:
        guide: [T, 4] (x, y, z, yaw) world, one pose every `policy.config.env.timestep` s.
    """
    field = heightfield_from_terrain(terrain, policy.config.env)
    pose = start_poses(field, np.asarray(start, np.float32)[None], policy.config.env.nominal_root_height)
    points = np.asarray(target, np.float32).reshape(1, 2)
    if waypoints is not None:
        points = np.concatenate([np.asarray(waypoints, np.float32).reshape(-1, 2), points])
    result = rollout_batch(
        policy, field, pose, points[None], [speed], max_steps, stop_at_target=stop_at_target
    )
    return result.guide(0)
