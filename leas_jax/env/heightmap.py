"""The local heightmap of the observation (paper §III-B, Fig. 3). Pure and jittable."""

import jax
import jax.numpy as jnp
import numpy as np

from leas_jax.env.config import HeightmapConfig
from leas_jax.env.field import Heightfield, sample_bilinear_xy
from leas_jax.env.kinematics import world_xy


def grid_offsets(config: HeightmapConfig = HeightmapConfig()) -> np.ndarray:
    """Sample points of the heightmap in the root frame.

    Rows go from the farthest point ahead (x = +0.72 m) to the farthest behind
    (x = -0.40 m); columns from y = -0.45 m to +0.45 m.

    Returns:
        [11 * 7, 2] (x, y) offsets, root frame, row-major.
    """
    ahead = config.forward_step * np.arange(config.forward_count, 0, -1)
    behind = -config.backward_step * np.arange(1, config.backward_count + 1)
    xs = np.concatenate([ahead, behind])
    ys = config.lateral_step * np.arange(-config.lateral_half_count, config.lateral_half_count + 1)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.stack([gx.ravel(), gy.ravel()], axis=-1).astype(np.float32)


def sample(field: Heightfield, pose: jax.Array, config: HeightmapConfig = HeightmapConfig()) -> jax.Array:
    """Heightmap observation: terrain height minus root z, clipped.

    Args:
        field: terrain.
        pose: [4] (x, y, z, yaw), world.
        config: grid and clipping.

    Returns:
        [77] relative heights (m) in [clip_low, clip_high], row-major as `grid_offsets`.
    """
    heights = sample_bilinear_xy(field, *world_xy(pose, jnp.asarray(grid_offsets(config))))
    return jnp.clip(heights - pose[2], config.clip_low, config.clip_high)
