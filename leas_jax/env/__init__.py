"""The LeaS environment: pure, jitted root kinematics, heightmap, reachability and reward."""

from leas_jax.env.config import EnvConfig, HeightmapConfig, ReachabilityConfig, RewardWeights
from leas_jax.env.env import LeasEnv, RootState
from leas_jax.env.field import Heightfield, heightfield_from_raster, heightfield_from_terrain
from leas_jax.env.wrappers import FreshResetVmap

EnvParams = EnvConfig  # name of the public API (gymnax's `EnvParams` habit)

__all__ = [
    "EnvConfig",
    "EnvParams",
    "HeightmapConfig",
    "ReachabilityConfig",
    "RewardWeights",
    "LeasEnv",
    "RootState",
    "Heightfield",
    "heightfield_from_raster",
    "heightfield_from_terrain",
    "FreshResetVmap",
]
