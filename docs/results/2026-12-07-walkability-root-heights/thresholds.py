"""Sensitivity and specificity of a walkability model at other logit thresholds than its own, on
a build's test terrains of the training families at the nominal and at jittered root heights
(the build's draws and cached labels).

    python docs/results/2026-12-07-walkability-root-heights/thresholds.py \
        > docs/results/2026-12-07-walkability-root-heights/thresholds.md
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np


def main() -> None:
    import jax
    import jax.numpy as jnp

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.feasibility import walkability as wk

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default=wk.WEIGHTS)
    parser.add_argument("--thresholds", default="own,-1,-2,-3,-4,-5,-6")
    parser.add_argument("--cache", default=".cache")
    args = parser.parse_args()
    reach = ReachabilityConfig()
    model = wk.load_walkability(args.model, reach)
    config = wk.WalkabilityConfig()
    seeds = wk.build_seeds(config)
    # the model's own inputs: with its footing places where it has them
    grid = lf.init_params(jax.random.PRNGKey(config.seed), reach=reach, footing=model.get("footing"))
    own = float(model["threshold"])
    thresholds = [own if t == "own" else float(t) for t in args.thresholds.split(",")]
    print(
        "| test poses | threshold | sensitivity % | specificity % [95 % CI] | stairs: sensitivity / specificity % |"
    )
    print("|---|---|---|---|---|")
    for name, terrains, jitter in (
        ("nominal root height", seeds.test, 0.0),
        (f"root height +-{config.root_height_jitter:g} m", seeds.jittered_test, config.root_height_jitter),
    ):
        part = wk.concatenate(
            wk.family_sets(
                config.train_families,
                terrains,
                config,
                Path(args.cache),
                1,
                grid,
                lambda _: None,
                config.test_poses_per_terrain,
                jitter,
            )
        )
        logits = np.asarray(lf.logit_of_features(model, jnp.asarray(part.x)))
        stairs = part.group == "stairs"
        for threshold in thresholds:
            r = wk.rates(logits >= threshold, part.y)
            s = wk.rates(logits[stairs] >= threshold, part.y[stairs])
            low, high = r["specificity_ci"]
            print(
                f"| {name} ({r['walkable']} / {r['not_walkable']}) | {threshold:.2f} | {100 * r['sensitivity']:.1f} | "
                f"{100 * r['specificity']:.1f} [{100 * low:.1f}, {100 * high:.1f}] | "
                f"{100 * s['sensitivity']:.1f} / {100 * s['specificity']:.1f} |"
            )


if __name__ == "__main__":
    main()
