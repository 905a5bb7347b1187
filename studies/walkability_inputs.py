"""Do other inputs or a shift-invariance prior let the walkability model tell unwalkable poses apart?

The walkability model (`leas feasibility walkability`) reads a root-frame height patch (0.08 m
grid), the height above the local ground and the calibrated cylinders' margins. On terrains it
did not fit it keeps 95 % of the walkable poses but rejects only 50-70 % of the unwalkable ones,
and its fit settings do not change that (`walkability_fit_settings.py`). This study refits it on
the same poses and labels with other inputs:

  - `shipped`: the shipped inputs and fit (`FitConfig()`);
  - `shifted`: each fitting pose also at `--shifted` copies moved by up to 2 cm and 0.03 rad,
    with its label (the generator's label survives such a move for 89 % of unwalkable poses
    and 97 % of walkable ones: `walkability_label_noise.py`);
  - `fine` / `coarse`: the patch on a 0.04 m / 0.16 m grid;
  - `margins`: no patch, only the height above the ground and the cylinders' margins.

For each, on the unseen terrains of the training families and on the held-out families:
sensitivity and specificity at the fitted threshold, and the specificity at the threshold
that keeps 95 % of that set's walkable poses (what the inputs allow with a perfectly placed
threshold), with 95 % Wilson intervals.

Labels: an earlier build's cache (`--cache`, files whose poses equal the drawn ones, from
whatever generator made them); a terrain without them is labelled with the current generator
and cached there.

    python studies/walkability_inputs.py [--out DIR] [--workers 2]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
sys.path.insert(0, str(REPO / "studies"))

from common import load_average, provenance  # noqa: E402
from walkability_label_noise import earlier_labels  # noqa: E402

FIT_SEEDS = (0, 1, 2, 3)  # the shipped build's fitting terrains (--terrains-per-family 4)
TEST_SEEDS = (100, 101)
SHIFT, TURN = 0.02, 0.03  # m, rad: the `shifted` copies' largest move
VARIANTS = ("shipped", "shifted", "fine", "coarse", "margins")


def specificity_at(logits: np.ndarray, y: np.ndarray, sensitivity: float) -> tuple[int, int]:
    """(unwalkable poses rejected, unwalkable poses) at the threshold keeping `sensitivity` of
    the walkable ones (logits [N], labels y [N] bool)."""
    walkable = np.sort(logits[y])
    threshold = walkable[int(np.floor((1.0 - sensitivity) * len(walkable)))]
    return int((logits[~y] < threshold).sum()), int((~y).sum())


def main() -> None:
    import jax
    import jax.numpy as jnp

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.feasibility import walkability as wk
    from leas_jax.feasibility.fit import FitConfig, features_of, fit
    from leas_jax.files import atomic_write_text
    from leas_jax.stats import wilson
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.families import FAMILIES, family_terrain

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cache", type=Path, default=Path(".cache"))
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--shifted", type=int, default=4, help="moved copies of each fitting pose")
    parser.add_argument("--out", type=Path, default=Path("docs/results/2026-12-06-walkability-label-noise"))
    args = parser.parse_args()
    load_before = load_average()
    config = wk.WalkabilityConfig(terrains_per_family=4, test_terrains_per_family=2, poses_per_terrain=250)
    reach = ReachabilityConfig()
    grids = {"fine": lf.patch_grid(step=0.04), "coarse": lf.patch_grid(step=0.16)}
    rng = np.random.default_rng(0)
    terrains = []  # (family, seed, field, poses, labels)
    for family in FAMILIES:
        seeds = FIT_SEEDS + TEST_SEEDS if family in config.train_families else TEST_SEEDS
        for seed in seeds:
            terrain = loads_terrain(family_terrain(family, seed), source=f"<family {family} {seed}>")
            field = wk._field(terrain)
            poses, _ = wk.plausible_poses(
                field, terrain.bounds, config.poses_per_terrain, config.seed + seed, config
            )
            labels = earlier_labels(poses, args.cache)
            if labels is None:
                labels = wk.walking_labels(terrain, poses, args.cache, args.workers)
            terrains.append((family, seed, field, poses, labels))
    print(f"{len(terrains)} terrains, {sum(len(t[4]) for t in terrains)} poses", flush=True)

    def features(variant, field, poses):
        grid = grids.get(variant, lf.patch_grid())
        x = features_of(
            lf.init_params(jax.random.PRNGKey(0), (64, 32), grid, reach=reach), field, poses, reach
        )
        if variant == "margins":
            x = x.copy()
            x[:, : len(grid)] = 0.0  # constant columns: standardised to 0, the patch says nothing
        return x

    def moved(poses):
        out = poses.copy()
        out[:, :2] += rng.uniform(-SHIFT, SHIFT, (len(poses), 2))
        out[:, 3] += rng.uniform(-TURN, TURN, len(poses))
        return out

    def rate(k, n):
        low, high = wilson(k, n)
        return {"rate": k / n if n else float("nan"), "k": k, "n": n, "ci": [low, high]}

    rows = {}
    for variant in VARIANTS:
        fit_x, fit_y, tests = [], [], {"unseen terrains": ([], []), "held-out families": ([], [])}
        for family, seed, field, poses, labels in terrains:
            if seed in FIT_SEEDS:
                copies = [poses] + (
                    [moved(poses) for _ in range(args.shifted)] if variant == "shifted" else []
                )
                fit_x += [features(variant, field, p) for p in copies]
                fit_y += [labels] * len(copies)
            else:
                split = "held-out families" if family in config.held_out_families else "unseen terrains"
                tests[split][0].append(features(variant, field, poses))
                tests[split][1].append(labels)
        grid = grids.get(variant, lf.patch_grid())
        params, _ = fit(np.concatenate(fit_x), np.concatenate(fit_y), FitConfig(), grid=grid, reach=reach)
        rows[variant] = {}
        for split, (xs, ys) in tests.items():
            x, y = np.concatenate(xs), np.concatenate(ys)
            logits = np.asarray(lf.logit_of_features(params, jnp.asarray(x, jnp.float32)))
            accepted = logits >= float(params["threshold"])
            rows[variant][split] = {
                "sensitivity": rate(int((accepted & y).sum()), int(y.sum())),
                "specificity": rate(int((~accepted & ~y).sum()), int((~y).sum())),
                "specificity_at_95": rate(*specificity_at(logits, y, 0.95)),
            }
        print(
            variant,
            json.dumps({s: {k: round(v["rate"], 3) for k, v in r.items()} for s, r in rows[variant].items()}),
            flush=True,
        )

    def cell(r):
        return f"{100 * r['rate']:.1f} [{100 * r['ci'][0]:.1f}, {100 * r['ci'][1]:.1f}]"

    lines = [
        "| inputs | poses | sensitivity % | specificity % | specificity at 95 % sensitivity % |",
        "|---|---|---|---|---|",
    ]
    for variant, splits in rows.items():
        for split, r in splits.items():
            lines.append(
                f"| {variant} | {split}: {r['sensitivity']['n']} / {r['specificity']['n']} | "
                f"{cell(r['sensitivity'])} | {cell(r['specificity'])} | {cell(r['specificity_at_95'])} |"
            )
    args.out.mkdir(parents=True, exist_ok=True)
    settings = {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()}
    atomic_write_text(
        args.out / "inputs.json",
        json.dumps({**provenance(load_before), "settings": settings, "rows": rows}, indent=1) + "\n",
    )
    atomic_write_text(args.out / "inputs.md", "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
