"""Two walkability models on the same poses: the test terrains and scenes of a build, and the
successful guides of `leas evaluate` folders.

Labels come from the label cache of `leas feasibility walkability` (the same poses: family seeds
100.. and each scene's draws; a missing label is computed with the current generator). For the
guides, a model "ends" a guide where it rejects one of its poses at the guide's own root height,
as the env's condition judges a policy's poses (the plausible cylinders and the network). A model
given as WEIGHTS|WEIGHTS accepts a pose that any of its networks accepts.

    python docs/results/2026-12-07-walkability-many-terrains/compare.py \
        --models shipped=checkpoints/walkability/walkability.npz many=/tmp/walk40/walkability.npz \
        --scenes 'terrains/hpp/rough/*.toml' terrains/hpp/rubble.toml \
        --guides /tmp/cg_eval /tmp/cg_eval_hpp --out docs/results/2026-12-07-walkability-many-terrains
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(REPO / "benchmarks"))

from common import load_average, provenance  # noqa: E402


def verdicts(params_list, x, predict):
    """bool [N]: accepted by any of the networks (a model given as WEIGHTS|WEIGHTS is their union)."""
    return np.logical_or.reduce([predict(params, x) for params in params_list])


def split_rates(models, part, wk, predict):
    """{group: {model: rates}} over 'all' and each group of a LabelledSet, and the calibrated
    cylinders' (the lattice's confident verdict without a model) as the last column."""
    groups = {"all": np.ones(len(part.y), bool)} | {
        g: part.group == g for g in dict.fromkeys(part.group.tolist())
    }
    return {
        g: {
            name: wk.rates(verdicts(params, part.x, predict)[m], part.y[m]) for name, params in models.items()
        }
        | {"cylinders": wk.rates(part.cylinders[m], part.y[m])}
        for g, m in groups.items()
    }


def guide_rows(models, folders, env):
    """{scenario: {model: (guides ended, guides, share of poses rejected)}} on successful guides."""
    import jax
    import jax.numpy as jnp

    from leas_jax.env import heightfield_from_terrain, reachability
    from leas_jax.env import learned_feasibility as lf
    from leas_jax.files import resolve_data_path
    from leas_jax.terrain import load_terrain

    relaxed = reachability.relaxed_reachability(env.reachability)
    rows = {}
    for folder in map(Path, folders):
        results = json.loads((folder / "results.json").read_text())
        with np.load(folder / "guides.npz") as stored:
            for name, scenario in results["scenarios"].items():
                guides = [
                    stored[f"{name}/{k}"] for k, t in enumerate(scenario["trajectories"]) if t["success"]
                ]
                field = heightfield_from_terrain(load_terrain(resolve_data_path(scenario["terrain"])), env)
                plausible = jax.jit(jax.vmap(lambda q, f=field: reachability.valid(f, q, relaxed)))
                rows[name] = {}
                for model, params_list in models.items():
                    networks = [
                        (jax.jit(jax.vmap(lambda q, f=field, p=p: lf.logit(p, f, q, env.reachability))), p)
                        for p in params_list
                    ]

                    def accepted_by(guide, networks=networks, plausible=plausible):
                        poses = jnp.asarray(guide, jnp.float32)
                        verdict = [np.asarray(logit(poses)) >= float(p["threshold"]) for logit, p in networks]
                        return np.asarray(plausible(poses)) & np.logical_or.reduce(verdict)

                    accepted = [accepted_by(g) for g in guides]
                    rows[name][model] = {
                        "guides": len(guides),
                        "ended": int(sum((~a).any() for a in accepted)),
                        "poses_rejected": float(np.mean(np.concatenate([~a for a in accepted])))
                        if guides
                        else 0.0,
                    }
    return rows


def cell(r):
    if not r["walkable"] or not r["not_walkable"]:
        fmt = lambda v, ci: "n/a" if v != v else f"{100 * v:.1f} [{100 * ci[0]:.1f}, {100 * ci[1]:.1f}]"  # noqa: E731
    else:
        fmt = lambda v, ci: f"{100 * v:.1f} [{100 * ci[0]:.1f}, {100 * ci[1]:.1f}]"  # noqa: E731
    return f"{fmt(r['sensitivity'], r['sensitivity_ci'])} / {fmt(r['specificity'], r['specificity_ci'])}"


def main() -> None:
    import dataclasses

    import jax

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.feasibility import walkability as wk
    from leas_jax.feasibility.commands import _scenes
    from leas_jax.feasibility.fit import predict
    from leas_jax.training.config import preset

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--models", nargs="+", required=True, metavar="NAME=WEIGHTS.npz[|WEIGHTS.npz]", help="| : their union"
    )
    parser.add_argument("--scenes", nargs="*", default=[])
    parser.add_argument("--guides", nargs="*", default=[], metavar="EVALUATION_DIR")
    parser.add_argument("--test-terrains-per-family", type=int, default=2)
    parser.add_argument("--test-poses-per-terrain", type=int, default=250)
    parser.add_argument(
        "--wide-held-out",
        type=int,
        nargs=2,
        default=None,
        metavar=("TERRAINS", "DRAWS"),
        help="also TERRAINS more terrains (seeds 200..) of each held-out family, DRAWS poses each",
    )
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cache", default=".cache")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    load_before = load_average()
    reach = ReachabilityConfig()
    models = {}
    for spec in args.models:
        name, paths = spec.split("=", 1)
        models[name] = [wk.load_walkability(path, reach) for path in paths.split("|")]
    config = dataclasses.replace(wk.WalkabilityConfig(), poses_per_terrain=args.test_poses_per_terrain)
    grid = lf.init_params(jax.random.PRNGKey(config.seed), reach=reach)
    seeds = range(100, 100 + args.test_terrains_per_family)
    cache = Path(args.cache)
    seen = wk.concatenate(
        wk.family_sets(config.train_families, seeds, config, cache, args.workers, grid, print)
    )
    held = wk.concatenate(
        wk.family_sets(config.held_out_families, seeds, config, cache, args.workers, grid, print)
    )
    splits = {"unseen terrains of the training families": seen, "held-out families": held}
    if args.wide_held_out:
        terrains, draws = args.wide_held_out
        wide = dataclasses.replace(config, poses_per_terrain=draws)
        splits["held-out families, wide"] = wk.concatenate(
            wk.family_sets(
                config.held_out_families, range(200, 200 + terrains), wide, cache, args.workers, grid, print
            )
        )
    scene_sets = [
        wk.labelled_terrain(
            scene,
            scene.name,
            config.poses_per_terrain,
            wk.scene_seed(config, k),
            config,
            cache,
            args.workers,
            grid,
            band=None,
        )
        for k, scene in enumerate(_scenes(args.scenes))
    ]
    if scene_sets:
        splits["hpp-environments scenes"] = wk.concatenate(scene_sets)
    report = {name: split_rates(models, part, wk, predict) for name, part in splits.items()}
    guides = guide_rows(models, args.guides, preset("generalist").env) if args.guides else {}
    names = [*models, "cylinders"]
    lines = [
        "Sensitivity / specificity % [95 % Wilson intervals] on the same labelled poses.\n",
        "| poses | walkable / not | " + " | ".join(names) + " |",
        "|---|---|" + "---|" * len(names),
    ]
    for split, groups in report.items():
        for group, by_model in groups.items():
            first = by_model[names[0]]
            lines.append(
                f"| {split}: {group} | {first['walkable']} / {first['not_walkable']} | "
                + " | ".join(cell(by_model[n]) for n in names)
                + " |"
            )
    if guides:
        lines += [
            "",
            "Successful guides each model would end (a pose rejected at the guide's own root height), "
            "and the share of poses it rejects.\n",
            "| scenario | guides | " + " | ".join(models) + " |",
            "|---|---|" + "---|" * len(models),
        ]
        for scenario, by_model in guides.items():
            first = by_model[names[0]]
            lines.append(
                f"| {scenario} | {first['guides']} | "
                + " | ".join(
                    f"{by_model[n]['ended']} ({100 * by_model[n]['poses_rejected']:.1f} %)" for n in models
                )
                + " |"
            )
    table = "\n".join(lines) + "\n"
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    record = {
        **provenance(load_before),
        "models": dict(a.split("=", 1) for a in args.models),
        "splits": report,
        "guides": guides,
    }
    (out / "compare.json").write_text(json.dumps(record, indent=1, default=float) + "\n")
    (out / "compare.md").write_text(table)
    print(table, end="")


if __name__ == "__main__":
    main()
