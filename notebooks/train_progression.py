"""The training run that notebooks/learning_progression.ipynb shows (paper Fig. 4).

The `quick` preset's geometric PPO cut to its first 8 M env steps (its return levels off
after about 5 M: checkpoints/leas_talos/pretrain/metrics.jsonl), keeping a full-state
checkpoint every 15 s of training so that the notebook can spread several from the first
to the last.

    python notebooks/train_progression.py runs/progression
"""

import sys

from leas_jax.training import preset, train


def main(out: str) -> None:
    config = preset("quick", num_timesteps=8_000_000, checkpoint_every_s=15.0, keep_checkpoints=1000)
    result = train(config, out, progress=False)
    print(f"trained {result.env_steps:,} env steps in {result.wall_s:.0f} s into {out}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "runs/progression")
