"""Steering methods: LeaS policy rollouts and the RBLin, RBKino and RBKino+RRT baselines.

Attributes are imported on first use (`leas_jax.lazy`). The functions `rbkino` and `rblin`
share their names with their modules, so `leas_jax.steering.rbkino` is the module: import
the functions from it (`from leas_jax.steering.rbkino import rbkino`).
"""

from leas_jax.lazy import lazy_getattr

_LAZY = {
    "BaselineConfig": "leas_jax.steering.baselines",
    "RolloutResult": "leas_jax.steering.leas",
    "rollout": "leas_jax.steering.leas",
    "rollout_batch": "leas_jax.steering.leas",
    "start_poses": "leas_jax.steering.leas",
    "rbkino_through": "leas_jax.steering.rbkino",
    "rblin_through": "leas_jax.steering.rblin",
    "RRTConfig": "leas_jax.steering.rrt",
    "RRTResult": "leas_jax.steering.rrt",
    "plan_rrt": "leas_jax.steering.rrt",
}

__all__ = sorted(_LAZY)
__getattr__ = lazy_getattr(__name__, globals(), _LAZY)
