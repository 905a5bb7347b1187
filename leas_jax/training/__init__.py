"""Training: configuration and presets, geometric PPO, checkpoints, policies."""

from leas_jax.training.config import PRESETS, TrainConfig, preset
from leas_jax.training.loop import TrainResult, train
from leas_jax.training.policy import Policy, load_policy

__all__ = ["PRESETS", "TrainConfig", "preset", "TrainResult", "train", "Policy", "load_policy"]
