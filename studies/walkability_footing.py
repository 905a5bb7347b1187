"""Does the share of ground a sole stands on in static equilibrium tell the walkability model
which unseen rough ground it walks?

The walkability model (`leas feasibility walkability`) reads a root-frame height patch, the
height above the local ground and the calibrated cylinders' margins; on the held-out families
(DARPA-style blocks, stepping stones) it refuses about a third of the unwalkable poses. On the
blocks, whether a terrain is walkable follows the tilt: the contact generator's friction pyramid
holds a sole up to 19.5 deg along x or y. This study fits the network with and without the
footing shares (`field.footing_rasters`: ground within that limit, even and solid, and solid
ground, within 0.10 m of each footstep place of the walking guide, `learned_feasibility.footing_points`)
on the same poses and labels, `--fit-seeds` network seeds each, and reports sensitivity and
specificity (95 % Wilson intervals) at the fitted threshold on unseen terrains of the training
families, on the held-out families and on `--scenes`.

The data are a build's (`walkability.family_sets`, its label cache and seeds): the training
families' nominal terrains 0..--terrains-per-family-1, their test terrains, the held-out terrains.
A missing label is computed (`--workers` processes).

    python studies/walkability_footing.py --out DIR [--terrains-per-family 40] [--fit-seeds 3] [--scenes GLOB ...]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))

from common import load_average, provenance  # noqa: E402

VARIANTS = ("without footing", "with footing")


def _cell(r: dict) -> str:
    (sl, sh), (pl, ph) = r["sensitivity_ci"], r["specificity_ci"]
    return (
        f"{100 * r['sensitivity']:.1f} [{100 * sl:.1f}, {100 * sh:.1f}] / "
        f"{100 * r['specificity']:.1f} [{100 * pl:.1f}, {100 * ph:.1f}]"
    )


def main() -> None:
    import jax
    import numpy as np

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.feasibility import walkability as wk
    from leas_jax.feasibility.commands import scene_terrains
    from leas_jax.feasibility.fit import FitConfig, fit, predict

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--terrains-per-family", type=int, default=40)
    parser.add_argument("--fit-seeds", type=int, default=3)
    parser.add_argument("--scenes", nargs="*", default=())
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cache", default=".cache")
    args = parser.parse_args()
    load_before = load_average()
    began = time.perf_counter()
    config = wk.WalkabilityConfig(
        terrains_per_family=args.terrains_per_family, jittered_terrains_per_family=0
    )
    reach = ReachabilityConfig()
    places = lf.footing_points(reach)
    template = lf.init_params(jax.random.PRNGKey(config.seed), reach=reach, footing=places)
    seeds = wk.build_seeds(config)
    cache = Path(args.cache)

    def families(names, terrains, count=None):
        parts = wk.family_sets(names, terrains, config, cache, args.workers, template, print, count)
        return wk.concatenate(parts)

    train = families(config.train_families, seeds.fit)
    splits = {
        "unseen terrains of the training families": families(
            config.train_families, seeds.test, config.test_poses_per_terrain
        ),
        "held-out families": families(
            config.held_out_families, seeds.held_out, config.held_out_poses_per_terrain
        ),
    }
    scenes = [
        wk.labelled_scene(scene, k, config, cache, args.workers, template)
        for k, scene in enumerate(scene_terrains(args.scenes))
    ]
    if scenes:
        splits["hpp-environments scenes"] = wk.concatenate(scenes)
    footing_columns = 2 * len(places)
    rows = []
    for variant in VARIANTS:
        with_footing = variant == "with footing"
        columns = slice(None) if with_footing else slice(0, train.x.shape[1] - footing_columns)
        for seed in range(args.fit_seeds):
            settings = FitConfig(target_sensitivity=config.target_sensitivity, seed=seed)
            params, _ = fit(
                train.x[:, columns], train.y, settings, reach=reach, footing=places if with_footing else None
            )
            row = {"variant": variant, "seed": seed}
            for name, part in splits.items():
                verdicts = predict(params, part.x[:, columns])
                row[name] = wk.rates(verdicts, part.y)
                for group in dict.fromkeys(part.group.tolist()) if name == "held-out families" else ():
                    mask = part.group == group
                    row[f"{name}: {group}"] = wk.rates(verdicts[mask], part.y[mask])
            rows.append(row)
            print(
                variant, seed, {k: round(v["specificity"], 3) for k, v in row.items() if isinstance(v, dict)}
            )
    names = [k for k in rows[0] if isinstance(rows[0][k], dict)]
    counts = {name: f"{rows[0][name]['walkable']} / {rows[0][name]['not_walkable']}" for name in names}
    lines = [
        f"Fit: {len(train.y)} poses of {len(seeds.fit)} terrains per training family "
        f"({int((~train.y).sum())} not walkable). Cells: sensitivity / specificity % [95 % Wilson interval].\n",
        "| poses (walkable / not) | "
        + " | ".join(f"{v}, seed {s}" for v in VARIANTS for s in range(args.fit_seeds))
        + " |",
        "|---|" + "---|" * (len(VARIANTS) * args.fit_seeds),
    ]
    for name in names:
        lines.append(f"| {name} ({counts[name]}) | " + " | ".join(_cell(r[name]) for r in rows) + " |")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    summary = {
        **provenance(load_before),
        "seconds": round(time.perf_counter() - began, 1),
        "config": {
            "terrains_per_family": args.terrains_per_family,
            "fit_seeds": args.fit_seeds,
            "scenes": list(args.scenes),
        },
        "footing_points": np.asarray(places).tolist(),
        "rows": rows,
    }
    (out / "footing.json").write_text(json.dumps(summary, default=float) + "\n")
    (out / "footing.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
