"""The LeaS environment: pure, jitted root kinematics, heightmap, reachability and reward.

Attributes are imported on first use (`leas_jax.lazy`), so that `leas_jax.env.config` can
be read without starting JAX.
"""

from leas_jax.lazy import lazy_getattr

_LAZY = {
    "EnvConfig": "leas_jax.env.config",
    # name of the public API (gymnax's `EnvParams` habit)
    "EnvParams": "leas_jax.env.config:EnvConfig",
    "HeightmapConfig": "leas_jax.env.config",
    "ReachabilityConfig": "leas_jax.env.config",
    "RewardWeights": "leas_jax.env.config",
    "LeasEnv": "leas_jax.env.env",
    "RootState": "leas_jax.env.env",
    "Heightfield": "leas_jax.env.field",
    "heightfield_from_raster": "leas_jax.env.field",
    "heightfield_from_terrain": "leas_jax.env.field",
    "FreshResetVmap": "leas_jax.env.wrappers",
}

__all__ = sorted(_LAZY)
__getattr__ = lazy_getattr(__name__, globals(), _LAZY)
