"""Training: configuration and presets, geometric PPO, checkpoints, policies."""

from leas_jax.train.config import PRESETS, TrainConfig, preset
from leas_jax.train.loop import TrainResult, train
from leas_jax.train.policy import Policy, load_policy

__all__ = ["PRESETS", "TrainConfig", "preset", "TrainResult", "train", "Policy", "load_policy"]
