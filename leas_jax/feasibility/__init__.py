"""Learned feasibility models: the fitting of the env's learned condition (the condition itself:
`leas_jax.env.learned_feasibility`), their data and `leas feasibility`.

Attributes are imported on first use (`leas_jax.lazy`), so that `leas --help` builds the
`feasibility` command without starting JAX.
"""

from leas_jax.lazy import lazy_getattr

_LAZY = {name: "leas_jax.feasibility.fit" for name in ("FitConfig", "features_of", "fit", "predict")}

__all__ = sorted(_LAZY)
__getattr__ = lazy_getattr(__name__, globals(), _LAZY)
