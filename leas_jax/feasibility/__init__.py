"""The learned feasibility condition's fitting (the condition itself: `leas_jax.env.learned_feasibility`)."""

from leas_jax.feasibility.fit import FitConfig, features_of, fit, predict

__all__ = ["FitConfig", "features_of", "fit", "predict"]
