"""Trains the `generalist` preset (curriculum arena, walkability condition, 80 M steps) with
another recipe, to tell which of its differences from the shipped paper-arena policy's recipe
(`checkpoints/leas_talos/pretrain`: the `paper` preset, 10 PPO epochs, the paper's five reward
terms, no clearance term) costs it progress:

  - no_clearance: the preset as it is, without the clearance term (RewardWeights.clearance 0);
  - paper_recipe: the same, with the `paper` preset's 10 epochs as well: the shipped policy's
    recipe, the curriculum arena and the walkability condition in place of the training arena
    and the arena-fitted condition;
  - direction_x4: the preset as it is (clearance term included), with the direction term's
    weight 4 instead of 1: standing still then costs 0.36 a step instead of 0.09 (the alive
    term pays 1), against a policy that slows down where the curriculum's tiles end episodes.

    python docs/results/2026-12-07-generalist-recipe/train_variant.py --variant no_clearance \
        --seed 0 --out runs/generalist_no_clearance_s0

Prints the wall time of the whole run (compile and checkpoints included).
"""

from __future__ import annotations

import argparse
import dataclasses
import time

from leas_jax.training.config import preset
from leas_jax.training.loop import train

VARIANTS = ("no_clearance", "paper_recipe", "direction_x4")


def variant_config(name: str, seed: int):
    """The generalist preset's TrainConfig with the variant's recipe."""
    config = preset("generalist", seed=seed)
    rewards = config.env.rewards
    if name == "direction_x4":
        rewards = dataclasses.replace(rewards, direction=4.0 * rewards.direction)
    else:
        rewards = dataclasses.replace(rewards, clearance=0.0)
    config = dataclasses.replace(config, env=dataclasses.replace(config.env, rewards=rewards))
    if name == "paper_recipe":
        config = dataclasses.replace(config, num_epochs=preset("paper").num_epochs)
    return config


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variant", choices=VARIANTS, required=True)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    config = variant_config(args.variant, args.seed)
    t0 = time.perf_counter()
    result = train(config, args.out, progress=False)
    print(
        f"{args.variant} seed {args.seed}: {result.env_steps:,} env steps in {time.perf_counter() - t0:.0f} s "
        f"of wall time (training {result.wall_s:.0f} s); policy: {result.policy_path}"
    )


if __name__ == "__main__":
    main()
