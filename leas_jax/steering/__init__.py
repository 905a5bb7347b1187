"""Steering methods: LeaS policy rollouts and the RBLin, RBKino and RBKino+RRT baselines."""

from leas_jax.steering.baselines import BaselineConfig
from leas_jax.steering.leas import RolloutResult, rollout, rollout_batch, start_poses
from leas_jax.steering.rbkino import rbkino, rbkino_through
from leas_jax.steering.rblin import rblin, rblin_through
from leas_jax.steering.rrt import RRTConfig, RRTResult, plan_rrt

__all__ = ["RolloutResult", "rollout", "rollout_batch", "start_poses"]
__all__ += [
    "BaselineConfig",
    "rblin",
    "rblin_through",
    "rbkino",
    "rbkino_through",
    "RRTConfig",
    "RRTResult",
    "plan_rrt",
]
