"""Training: configuration and presets, geometric PPO, checkpoints, policies.

Attributes are imported on first use (`leas_jax.lazy`), so that the presets can be read
(`leas train --help`) without starting JAX.
"""

from leas_jax.lazy import lazy_getattr

_LAZY = {
    "PRESETS": "leas_jax.training.config",
    "TrainConfig": "leas_jax.training.config",
    "preset": "leas_jax.training.config",
    "TrainResult": "leas_jax.training.loop",
    "train": "leas_jax.training.loop",
    "Policy": "leas_jax.training.policy",
    "load_policy": "leas_jax.training.policy",
}

__all__ = sorted(_LAZY)
__getattr__ = lazy_getattr(__name__, globals(), _LAZY)
