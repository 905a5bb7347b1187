"""`LeasEnv`: the LeaS MDP as a Brax environment (one env, no batch axis).

The env composes the pure functions of `kinematics`, `heightmap`,
`condition` (reachability) and `reward`. Its terrain is a `Heightfield` pytree held as
data: build the env inside a jitted function from a traced field
(`env.with_field(field)`) to keep the rasters out of the compiled constants.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
from brax.envs.base import Env, State
from flax import struct

from leas_jax.env import condition, heightmap, kinematics, reward
from leas_jax.env.config import EnvConfig
from leas_jax.env.field import Heightfield, heightfield_from_terrain, sample_bilinear
from leas_jax.errors import TerrainError
from leas_jax.terrain.model import Terrain


@struct.dataclass
class RootState:
    """Guide-path state of one environment (Brax `State.pipeline_state`).

    Attributes:
        pos: [3] world position of base_link (m).
        vel: [3] world velocity (m/s).
        yaw: [] heading (rad).
        target_dir: [2] unit target direction, world, horizontal.
        target_point: [2] world target (x, y); used when `follow_point`.
        follow_point: bool[]; True: the target direction points at `target_point` each step.
        steps: int32[] steps taken in this episode.
        rng: [2] uint32 PRNG key for the next reset.
        start: [2] world (x, y) where the episode started.
        level: int32[] the env's curriculum row (0 on a field without a curriculum).
    """

    pos: jax.Array
    vel: jax.Array
    yaw: jax.Array
    target_dir: jax.Array
    target_point: jax.Array
    follow_point: jax.Array
    steps: jax.Array
    rng: jax.Array
    start: jax.Array
    level: jax.Array

    @property
    def pose(self) -> jax.Array:
        """[4] (x, y, z, yaw), world."""
        return jnp.concatenate([self.pos, self.yaw[..., None]], axis=-1)


def _unit(v: jax.Array) -> jax.Array:
    return v / jnp.maximum(jnp.linalg.norm(v), 1e-9)


def _heading(yaw: jax.Array) -> jax.Array:
    return jnp.stack([jnp.cos(yaw), jnp.sin(yaw)])


class LeasEnv(Env):
    """LeaS guide-path environment (paper §III, docs/design.md §5).

    Observation [81]: root-frame velocity [3], target angle [1] (target
    direction minus heading, wrapped to [-pi, pi)), heightmap [77].
    Action [4]: (a_x, a_y, a_z, omega) in [-1, 1].
    Episodes end on an invalid pose (`condition.valid`: the cylinders or the learned condition), after `episode_length`
    steps (info['truncation'] = 1), and with `stop_at_target` when the root is
    within `target_reached_distance` of the target point.
    """

    def __init__(self, field: Heightfield | Terrain, config: EnvConfig = EnvConfig()):
        """Args:
        field: the terrain's `Heightfield` (`heightfield_from_terrain`), or a loaded
            `Terrain` (`load_terrain(path)`), whose heightfield is then built here (host-side,
            once; build it yourself to share it between envs or configs).
        config: the MDP's parameters.

        Raises:
            TypeError: `field` is neither.
        """
        if isinstance(field, Terrain):
            field = heightfield_from_terrain(field, config)
        elif not isinstance(field, Heightfield):
            raise TypeError(
                f"LeasEnv(field): expected a Heightfield or a Terrain, got {type(field).__name__}; "
                "pass load_terrain(path) or heightfield_from_terrain(terrain, config)"
            )
        self.field = field
        self.config = config

    def with_field(self, field: Heightfield) -> LeasEnv:
        """The same env on another (possibly traced) heightfield."""
        return LeasEnv(field, self.config)

    @property
    def observation_size(self) -> int:
        return self.config.observation_size

    @property
    def action_size(self) -> int:
        return 4

    @property
    def backend(self) -> str:
        return "leas"

    # -- observation -------------------------------------------------------
    def observe(self, root: RootState) -> jax.Array:
        """[81] observation of a root state."""
        vel_root = jnp.concatenate([kinematics.rotate_z(root.vel[:2], -root.yaw), root.vel[2:]])
        target_angle = kinematics.wrap_angle(jnp.arctan2(root.target_dir[1], root.target_dir[0]) - root.yaw)
        hmap = heightmap.sample(self.field, root.pose, self.config.heightmap)
        return jnp.concatenate([vel_root, target_angle[None], hmap])

    def _state(self, root: RootState, reward_value, done, metrics, truncation) -> State:
        return State(
            pipeline_state=root,
            obs=self.observe(root),
            reward=reward_value,
            done=done,
            metrics=metrics,
            info={"truncation": truncation},
        )

    def _zero_metrics(self) -> dict:
        metrics = {f"reward/{n}": v for n, v in reward.zeros().items()}
        metrics.update(invalid=jnp.zeros(()), reached=jnp.zeros(()))
        return metrics

    # -- reset -------------------------------------------------------------
    def reset(self, rng: jax.Array) -> State:
        """Fresh random start: valid position near a spawn point, random yaw,
        speed along the heading in [0, reset_max_speed], random target direction."""
        root = self.random_root(rng)
        return self._state(root, jnp.zeros(()), jnp.zeros(()), self._zero_metrics(), jnp.zeros(()))

    def next_root(self, root: RootState) -> RootState:
        """The start of the episode after `root`'s (which has ended): `random_root` with its key,
        on a curriculum arena on the row its walk earns (`EnvConfig.curriculum`)."""
        if not self.field.curriculum:
            return self.random_root(root.rng)
        rule = self.config.curriculum
        walked = jnp.linalg.norm(root.pos[:2] - root.start)
        up = walked >= rule.level_up_distance
        down = (walked < rule.level_down_distance) & ~up
        level = root.level + up.astype(jnp.int32) - down.astype(jnp.int32)
        levels = self.field.curriculum["level_count"].shape[0]
        anywhere = jax.random.randint(jax.random.fold_in(root.rng, 1), (), 0, levels)
        level = jnp.where(level >= levels, anywhere, jnp.maximum(level, 0))
        return self.random_root(root.rng, level)

    def random_root(self, rng: jax.Array, level=None) -> RootState:
        """Root state of a fresh random start (no observation; see `reset`).

        One uniform draw feeds every random quantity (each threefry call
        costs about as much as a reachability test on a CPU).

        Args:
            rng: PRNG key.
            level: int32[] curriculum row to start on (a field with a curriculum only); None:
                a random row up to `CurriculumConfig.initial_max_level`.

        Raises:
            TerrainError: the field has no spawn points (when traced: its shape says so).
        """
        if self.field.spawn_xy.shape[0] == 0:
            raise TerrainError(
                "random resets start at the field's spawn points and it has none (the terrain is too "
                "small or too rough); start rollouts from given poses (`reset_to`) instead"
            )
        cfg = self.config
        next_rng, key = jax.random.split(rng)
        n = cfg.reset_attempts
        curriculum = self.field.curriculum
        u = jax.random.uniform(key, (4 * n + 2 + bool(curriculum),))
        cand, speed_u, target_u = u[: 4 * n].reshape(n, 4), u[4 * n], u[4 * n + 1]
        if curriculum:
            if level is None:
                rows = min(cfg.curriculum.initial_max_level + 1, curriculum["level_count"].shape[0])
                level = jnp.minimum((u[-1] * rows).astype(jnp.int32), rows - 1)
            count = curriculum["level_count"][level]
            first = curriculum["level_start"][level]
        else:
            level, count, first = 0, self.field.spawn_xy.shape[0], 0
        idx = first + jnp.minimum((cand[:, 0] * count).astype(jnp.int32), count - 1)
        jitter = (cand[:, 1:3] - 0.5) * self.field.spawn_spacing
        # the last candidate is the spawn point itself (masks, not scatters: scatters are slow
        # on CPU), and so is every verified start pose (a spawn with its own yaw)
        last = jnp.arange(n) == n - 1
        spawn_yaw = self.field.spawn_yaw[idx]
        verified = ~jnp.isnan(spawn_yaw)
        exact = last | verified
        xy = self.field.spawn_xy[idx] + jnp.where(exact[:, None], 0.0, jitter)
        yaw = jnp.where(verified, spawn_yaw, (2.0 * cand[:, 3] - 1.0) * jnp.pi)
        z = sample_bilinear(self.field, xy) + cfg.nominal_root_height
        poses = jnp.concatenate([xy, z[:, None], yaw[:, None]], axis=1)
        ok = jax.vmap(lambda p: condition.valid(self.field, p, cfg))(poses)
        ok = ok | exact  # spawn points are valid for every yaw by construction, verified poses as they are
        pose = poses[jnp.argmax(ok)]
        target_angle = (2.0 * target_u - 1.0) * jnp.pi
        return self._root(
            pose,
            speed_u * cfg.reset_max_speed,
            _heading(target_angle),
            jnp.zeros(2),
            jnp.asarray(False),
            next_rng,
            level,
        )

    def _root(self, pose, speed, target_dir, target_point, follow_point, rng, level=0) -> RootState:
        return RootState(
            pos=pose[:3],
            vel=jnp.concatenate([speed * _heading(pose[3]), jnp.zeros(1)]),
            yaw=pose[3],
            target_dir=target_dir,
            target_point=target_point,
            follow_point=follow_point,
            steps=jnp.zeros((), jnp.int32),
            rng=rng,
            start=pose[:2],
            level=jnp.asarray(level, jnp.int32),
        )

    def reset_to(self, pose: jax.Array, speed, target_dir=None, target_point=None, rng=None) -> State:
        """Start from a given pose.

        Args:
            pose: [4] (x, y, z, yaw), world.
            speed: [] initial speed along the heading (m/s).
            target_dir: [2] world direction to follow (normalised here), or
            target_point: [2] world point to walk to (the direction is recomputed each step).
            rng: PRNG key stored for later resets (default: key 0).
        """
        if (target_dir is None) == (target_point is None):
            raise ValueError("give exactly one of target_dir and target_point")
        pose = jnp.asarray(pose, jnp.float32)
        follow = target_point is not None
        point = jnp.asarray(target_point if follow else jnp.zeros(2), jnp.float32)
        direction = _unit(point - pose[:2]) if follow else _unit(jnp.asarray(target_dir, jnp.float32))
        root = self._root(
            pose,
            jnp.asarray(speed, jnp.float32),
            direction,
            point,
            jnp.asarray(follow),
            jax.random.PRNGKey(0) if rng is None else rng,
        )
        return self._state(root, jnp.zeros(()), jnp.zeros(()), self._zero_metrics(), jnp.zeros(()))

    # -- step --------------------------------------------------------------
    def step(self, state: State, action: jax.Array) -> State:
        root, reward_value, done, metrics, truncation = self.transition(state.pipeline_state, action)
        return self._state(root, reward_value, done, metrics, truncation)

    def transition(self, root: RootState, action: jax.Array):
        """One step without the observation.

        Returns:
            (root, reward [], done [] float, metrics dict, truncation [] float).
        """
        cfg = self.config
        accel, omega = kinematics.scale_action(action, root.yaw, cfg)
        pos, vel, yaw = kinematics.integrate(root.pos, root.vel, root.yaw, accel, omega, cfg)
        target_dir = jnp.where(root.follow_point, _unit(root.target_point - pos[:2]), root.target_dir)
        steps = root.steps + 1
        root = root.replace(pos=pos, vel=vel, yaw=yaw, target_dir=target_dir, steps=steps)

        terms = reward.terms(self.field, root.pose, vel, action, target_dir, cfg)
        ok = condition.valid(self.field, root.pose, cfg)
        reached = root.follow_point & (
            jnp.linalg.norm(root.target_point - pos[:2]) < cfg.target_reached_distance
        )
        reached = reached & cfg.stop_at_target
        timeout = steps >= cfg.episode_length
        done = (~ok) | reached | timeout
        truncation = (timeout & ok & ~reached).astype(jnp.float32)
        metrics = {f"reward/{k}": v for k, v in terms.items()}
        metrics.update(invalid=(~ok).astype(jnp.float32), reached=reached.astype(jnp.float32))
        return root, reward.total(terms, cfg), done.astype(jnp.float32), metrics, truncation
