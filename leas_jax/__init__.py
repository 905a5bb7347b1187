"""leas-jax: learning to steer a locomotion contact planner (LeaS) in JAX.

Public API (imported lazily so that `import leas_jax` stays fast and host-only
users do not pay for JAX start-up):

    from leas_jax import load_terrain, LeasEnv, TrainConfig, train, load_policy, rollout
"""

from leas_jax.lazy import lazy_getattr
from leas_jax.quiet import silence_warp_notice

silence_warp_notice()

__version__ = "0.1.0"

_LAZY = {
    "load_terrain": "leas_jax.terrain",
    "loads_terrain": "leas_jax.terrain",
    "Terrain": "leas_jax.terrain",
    "LeasEnv": "leas_jax.env",
    "EnvParams": "leas_jax.env",
    "TrainConfig": "leas_jax.training",
    "train": "leas_jax.training",
    "load_policy": "leas_jax.training",
    "rollout": "leas_jax.steering",
}

__all__ = sorted(_LAZY)


__getattr__ = lazy_getattr(__name__, globals(), _LAZY)
