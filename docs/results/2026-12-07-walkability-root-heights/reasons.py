"""Why does the generator not walk from poses a walkability model accepts? For terrains of one
family (seeds FIRST..LAST-1), the build's pose draws (DRAWS each) and labels (the label cache),
the first 6 poses per terrain that the model accepts and the generator does not walk from, and
the generator's reasons at the planning pose it could not pass (`ContactGenerator.stop_reasons`).

    python docs/results/2026-12-07-walkability-root-heights/reasons.py blocks 200 206 50 \
        --model /tmp/walk_nom/walkability.npz
"""

from __future__ import annotations

import argparse
import collections
from pathlib import Path

import numpy as np


def main() -> None:
    from leas_jax.contacts.planner.generator import ContactGenerator, GeneratorConfig
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.feasibility import walkability as wk
    from leas_jax.feasibility.fit import features_of, predict
    from leas_jax.feasibility.walking_truth import WALK_TIMESTEP, walking_guide
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.families import family_terrain

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("family")
    parser.add_argument("first", type=int)
    parser.add_argument("last", type=int)
    parser.add_argument("draws", type=int)
    parser.add_argument("--model", default=wk.WEIGHTS)
    parser.add_argument("--cache", default=".cache")
    args = parser.parse_args()
    config, reach = wk.WalkabilityConfig(), ReachabilityConfig()
    model = wk.load_walkability(args.model, reach)
    top = collections.Counter()
    every = collections.Counter()
    for seed in range(args.first, args.last):
        terrain = loads_terrain(family_terrain(args.family, seed), source=f"<family {args.family} {seed}>")
        field = wk._field(terrain)
        poses, _ = wk.plausible_poses(field, terrain.bounds, args.draws, config.seed + seed, config)
        walkable = wk.walking_labels(terrain, poses, Path(args.cache), 1)
        accepted = predict(model, features_of(model, field, poses, reach))
        generator = ContactGenerator(terrain, GeneratorConfig())
        for pose in poses[accepted & ~walkable][:6]:
            plan, reasons = generator.stop_reasons(walking_guide(pose), WALK_TIMESTEP)
            every.update(reasons)
            if reasons:
                top[reasons.most_common(1)[0][0]] += 1
            print(seed, np.round(pose, 2).tolist(), f"coverage {plan.coverage:.2f}", reasons.most_common(3))
    print(f"{sum(top.values())} poses; the most frequent reason per pose: {top.most_common()}")
    print(f"every rejection: {every.most_common()}")


if __name__ == "__main__":
    main()
