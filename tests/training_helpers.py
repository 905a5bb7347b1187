"""Small training set-ups shared by the training tests and benchmarks/compile_cache.py."""

import numpy as np

from leas_jax.env import heightfield_from_raster
from leas_jax.training import preset


def tiny_config(**overrides):
    """A few-second smoke config: 64 envs x 8 steps, 2 iterations per call, 3 calls, a
    checkpoint after every call (`checkpoint_every_s` 0)."""
    base = dict(
        num_timesteps=64 * 8 * 2 * 3,
        num_envs=64,
        unroll_length=8,
        num_minibatches=2,
        num_epochs=2,
        iterations_per_call=2,
        checkpoint_every_s=0.0,
    )
    return preset("smoke", **{**base, **overrides})


def gap_field():
    """6 x 6 m of flat ground at 0.02 m with a 0.6 m gap to fall into (rows 200-229)."""
    heights = np.zeros((301, 301), np.float32)
    heights[200:230, :] = -2.0
    return heightfield_from_raster(heights, (0.0, 0.0), 0.02, -2.0)
