"""The planner phase of run.sh with the refits anchored (`TrainConfig.condition_anchor_poses`).

PYTHONPATH=$PWD python docs/results/2026-12-01-learned-paper/train_anchored.py runs/paper_learned runs/paper_learned_anchored
"""

import dataclasses
import sys

from leas_jax.training import train
from leas_jax.training.config import LEARNED_REFRESH_EVERY, learned_condition_env, preset

if __name__ == "__main__":  # the validation workers import this file again
    init, out = sys.argv[1], sys.argv[2]
    config = preset("paper", mode="planner", init_from=init)
    config = dataclasses.replace(
        config,
        env=learned_condition_env(config.env),
        condition_refresh_every=LEARNED_REFRESH_EVERY,
        condition_anchor_poses=4000,
    ).validate()
    result = train(config, out, progress=False, workers=2)
    print(f"trained {result.env_steps:,} kept env steps; policy: {result.policy_path}")
