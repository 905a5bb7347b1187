"""Is the walkability model's specificity limited by its fit settings?

Fits the network on the training families' terrains of seeds 0-2 and measures sensitivity and
specificity on seed 3 (a terrain of the same families it did not fit), over weight decay, network
width and Adam steps, the threshold set for 95 % sensitivity on the fitting poses kept aside.
Labels come from the cache of `leas feasibility walkability` (the same poses; a missing label is
computed). Writes fit_settings.json and fit_settings.md into --out
(docs/results/2026-12-06-walkability).

    python studies/walkability_fit_settings.py [--workers 2] [--out DIR]
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))

from common import load_average, provenance  # noqa: E402

WEIGHT_DECAYS = (1e-2, 1e-1, 1.0)
HIDDEN = ((64, 32), (16, 8))
STEPS = (600, 200)


def main() -> None:
    import jax

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.feasibility import walkability as wk
    from leas_jax.feasibility.fit import FitConfig, fit, predict

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cache", default=".cache")
    parser.add_argument("--out", default="docs/results/2026-12-06-walkability")
    args = parser.parse_args()
    load_before = load_average()
    config = wk.WalkabilityConfig(terrains_per_family=4, test_terrains_per_family=2, poses_per_terrain=250)
    reach = ReachabilityConfig()
    grid = lf.init_params(jax.random.PRNGKey(config.seed), reach=reach)

    def sets(seeds):
        parts = wk.family_sets(
            config.train_families, seeds, config, Path(args.cache), args.workers, grid, print
        )
        return wk.concatenate(parts)

    train, held = sets(range(3)), sets(range(3, 4))
    rows = []
    for decay, hidden, steps in itertools.product(WEIGHT_DECAYS, HIDDEN, STEPS):
        settings = FitConfig(hidden=hidden, weight_decay=decay, steps=steps, target_sensitivity=0.95)
        params, info = fit(train.x, train.y, settings, reach=reach)
        rows.append(
            {"weight_decay": decay, "hidden": list(hidden), "steps": steps, "final_loss": info["final_loss"]}
            | wk.rates(predict(params, held.x), held.y)
        )
    lines = [
        f"Fit: {len(train.y)} poses (seeds 0-2); test: {len(held.y)} poses of seed 3, "
        f"{int((~held.y).sum())} not walkable.\n",
        "| weight decay | hidden | steps | final loss | sensitivity % | specificity % |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        (sl, sh), (pl, ph) = r["sensitivity_ci"], r["specificity_ci"]
        lines.append(
            f"| {r['weight_decay']:g} | {r['hidden']} | {r['steps']} | {r['final_loss']:.4f} | "
            f"{100 * r['sensitivity']:.1f} [{100 * sl:.1f}, {100 * sh:.1f}] | "
            f"{100 * r['specificity']:.1f} [{100 * pl:.1f}, {100 * ph:.1f}] |"
        )
    out = Path(args.out)
    (out / "fit_settings.json").write_text(
        json.dumps({**provenance(load_before), "rows": rows}, indent=1) + "\n"
    )
    (out / "fit_settings.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
