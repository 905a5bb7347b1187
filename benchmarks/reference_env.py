"""A bare reference env: the least an env with LeaS's observation must compute per step.

`benchmarks/env_throughput.py` times it in the same run as `LeasEnv` and reports
the env's throughput as a ratio to it, so that a figure measured on this shared
machine says how far the env is from the cost of its gathers, whatever the load.

Per env and step: point kinematics (velocity, position, yaw), 77 bilinear height
samples on the env's 11 x 7 heightmap grid (`HeightmapConfig`), and an 8-point disk
check (8 bilinear samples on the trunk cylinder's circle: free above the trunk's
bottom, and some ground within the legs' reach); an env whose check fails restarts
from its first pose (Brax's auto-reset). No reward terms, no reachability rasters,
no random restarts.

The bilinear sampler is written here on purpose, not imported from `leas_jax.env`:
a yardstick must not move when the env's code changes (`tests/test_benchmarks.py`
checks that both give the same heights).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
from flax import struct

from leas_jax.env import EnvConfig, Heightfield
from leas_jax.env.heightmap import grid_offsets

DISK_POINTS = 8


@struct.dataclass
class ReferenceState:
    """State of one reference env (no batch axis).

    Attributes:
        pos: [3] world position of the root (m).
        vel: [3] world velocity (m/s).
        yaw: [] heading (rad).
        start: [4] (x, y, z, yaw) of the first pose, restored when the check fails.
        obs: [81] root-frame velocity [3], yaw [1], heightmap [77] (terrain minus root z).
        reward: [] velocity along the heading (m/s).
        done: [] 1.0 when the disk check failed this step.
    """

    pos: jax.Array
    vel: jax.Array
    yaw: jax.Array
    start: jax.Array
    obs: jax.Array
    reward: jax.Array
    done: jax.Array


def bilinear(field: Heightfield, xy: jax.Array) -> jax.Array:
    """Terrain height at world points, bilinear between grid points, void outside.

    xy: [..., 2] world (x, y) -> [...] heights (m). `heights[i, j]` is at
    `origin + (i, j) * resolution`.
    """
    nx, ny = field.heights.shape
    u = (xy[..., 0] - field.origin[0]) / field.resolution
    v = (xy[..., 1] - field.origin[1]) / field.resolution
    i = jnp.clip(jnp.floor(u).astype(jnp.int32), 0, nx - 2)
    j = jnp.clip(jnp.floor(v).astype(jnp.int32), 0, ny - 2)
    fu = jnp.clip(u - i, 0.0, 1.0)
    fv = jnp.clip(v - j, 0.0, 1.0)
    h = field.heights
    top = h[i, j] * (1 - fv) + h[i, j + 1] * fv
    bottom = h[i + 1, j] * (1 - fv) + h[i + 1, j + 1] * fv
    inside = (u >= 0) & (u <= nx - 1) & (v >= 0) & (v <= ny - 1)
    return jnp.where(inside, top * (1 - fu) + bottom * fu, field.void_height)


class ReferenceEnv:
    """The bare env on a `Heightfield` (its heights only). Observation [81], action [4] in [-1, 1]."""

    def __init__(self, field: Heightfield, config: EnvConfig = EnvConfig()):
        self.field = field
        self.config = config
        self.offsets = np.asarray(grid_offsets(config.heightmap))  # [77, 2], root frame
        angles = 2 * np.pi * np.arange(DISK_POINTS) / DISK_POINTS
        radius = config.reachability.trunk_radius
        self.disk = (radius * np.stack([np.cos(angles), np.sin(angles)], -1)).astype(np.float32)  # [8, 2]

    def _rotate(self, xy: np.ndarray, yaw: jax.Array) -> jax.Array:
        c, s = jnp.cos(yaw), jnp.sin(yaw)
        return jnp.stack([c * xy[..., 0] - s * xy[..., 1], s * xy[..., 0] + c * xy[..., 1]], -1)

    def _observe(self, pos, vel, yaw) -> jax.Array:
        heights = bilinear(self.field, pos[:2] + self._rotate(self.offsets, yaw)) - pos[2]  # [77]
        vel_root = jnp.concatenate([self._rotate(vel[:2], -yaw), vel[2:]])
        hm = self.config.heightmap
        return jnp.concatenate([vel_root, yaw[None], jnp.clip(heights, hm.clip_low, hm.clip_high)])

    def _valid(self, pos) -> jax.Array:
        heights = bilinear(self.field, pos[:2] + self.disk)  # [8]
        reach = self.config.reachability
        return jnp.all(heights < pos[2] + reach.trunk_bottom) & jnp.any(heights > pos[2] + reach.leg_bottom)

    def _state(self, pos, vel, yaw, start, reward, done) -> ReferenceState:
        obs = self._observe(pos, vel, yaw)
        return ReferenceState(pos=pos, vel=vel, yaw=yaw, start=start, obs=obs, reward=reward, done=done)

    def reset(self, key: jax.Array) -> ReferenceState:
        """A spawn point of the field, random yaw, at rest. key: [2] -> state."""
        pick, turn = jax.random.split(key)
        xy = self.field.spawn_xy[jax.random.randint(pick, (), 0, self.field.spawn_xy.shape[0])]
        yaw = jax.random.uniform(turn, (), minval=-jnp.pi, maxval=jnp.pi)
        z = bilinear(self.field, xy) + self.config.nominal_root_height
        start = jnp.concatenate([xy, z[None], yaw[None]])
        zero = jnp.zeros(())
        return self._state(start[:3], jnp.zeros(3), yaw, start, zero, zero)

    def step(self, state: ReferenceState, action: jax.Array) -> ReferenceState:
        """Point kinematics, then the disk check (restart on failure), then the observation."""
        cfg = self.config
        action = jnp.clip(action, -1.0, 1.0)
        accel = jnp.concatenate([self._rotate(action[:2], state.yaw), action[2:3]]) * cfg.a_max
        pos = state.pos + state.vel * cfg.timestep
        vel = state.vel + accel * cfg.timestep
        vel = vel * jnp.minimum(1.0, cfg.v_max / jnp.maximum(jnp.linalg.norm(vel), 1e-12))
        yaw = state.yaw + action[3] * cfg.omega_max * cfg.timestep
        reward = vel[0] * jnp.cos(yaw) + vel[1] * jnp.sin(yaw)
        ok = self._valid(pos)
        start = state.start
        pos = jnp.where(ok, pos, start[:3])
        vel = jnp.where(ok, vel, jnp.zeros(3))
        yaw = jnp.where(ok, yaw, start[3])
        return self._state(pos, vel, yaw, start, reward, (~ok).astype(jnp.float32))
