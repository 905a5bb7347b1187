"""Steering methods: LeaS policy rollouts (and, later, the RBLin/RBKino baselines)."""

from leas_jax.steering.leas import RolloutResult, rollout, rollout_batch, start_poses

__all__ = ["RolloutResult", "rollout", "rollout_batch", "start_poses"]
