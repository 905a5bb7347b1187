"""Does the learned feasibility condition, refitted on the contact generator's whole-path verdicts,
stop ending the guides the generator covers (beams, stairs)?

The shipped weights (`checkpoints/feasibility/walking.npz`, `leas feasibility condition`)
learned the *walking truth*: a 0.36 m straight guide at the pose's height and yaw. On a
beam or up a flight of stairs that short level guide often fails where the walk that
follows the terrain does not, so the condition rejects poses of guides the generator
covers end to end, and a policy trained with it stops before beams and stairs
(docs/results/2026-12-01-learned-paper, "Why").

This script labels poses with what the generator does on whole paths instead. A teacher
policy that crosses beams and climbs stairs (default: the geometric pretrain with the
paper's cylinders) draws `--episodes` guides on its training arena from the env's random
resets; the generator plans each (kept in --out/teacher_guides_<k>.npz and read back by a
rerun with the same settings), and `leas_jax.training.planner.verdict_samples` turns
the verdicts into labelled poses (covered poses the generator followed for 20 more
poses: feasible; the first pose it could not pass: infeasible). The condition is refitted
from the shipped weights on those poses together with `--anchors` poses drawn as resets
are and labelled by the shipped condition (`anchor_samples`), so that it keeps its
verdicts where the teacher's guides do not go (the labelled path poses are also written to
--out/path_verdicts.npz, for `leas train --condition-seed-data`). Its threshold is set for
`FitConfig.target_sensitivity` on the poses kept aside, or (`--path-sensitivity`) so that
a share of the fitted guides' surely feasible prefixes pass whole: per-pose errors
compound along a 400-pose guide. Several teachers aggregate their verdicts: a DAgger round
refits on the guides of the policy trained with the last refit together with the earlier
teachers'.

Both conditions (before and after the refit) are then checked on `--holdout` other guides
of each teacher (another reset seed), per path (does the condition end a guide the generator covers? does it stop
a guide at or before the pose the generator could not pass?) and per pose, with 95 %
Wilson intervals; covered guides' false ends are broken down by arena cell. Writes the
weights to --weights-out and condition_from_paths.json / .md into --out.

    python studies/condition_from_paths.py --episodes 1024 --holdout 256 --workers 2 \
        --weights-out DIR/condition.npz --out DIR

Results: docs/results/2026-12-01-path-condition.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "benchmarks")]  # the other studies, benchmarks/common.py

PATH_FIT_STEPS = (
    400  # AdamW steps of the refit from the shipped weights (FitConfig.refresh_steps is a DAgger step's 200)
)


def sure_end(last_valid_index: int, length: int, horizon: int) -> int:
    """Last guide index the generator surely walks from: the whole guide when it is covered,
    else `horizon` poses before its last valid one (-1: none); the rule of `verdict_samples`."""
    return length - 1 if last_valid_index >= length - 1 else last_valid_index - horizon


def path_outcomes(rejected, last_valid, horizon: int) -> dict:
    """Per-path agreement of a condition with the generator.

    Args:
        rejected: list of bool [L_n] arrays, the condition rejects each guide pose.
        last_valid: [N] the generator's last valid index on each guide.
        horizon: poses a covered pose must be followed by to count as surely feasible.

    Returns:
        {"covered": guides the generator covers fully, "covered_ended": of them, those the
        condition ends somewhere; "failed": the others, "failed_stopped": of them, those the
        condition rejects at or before the first pose the generator could not pass;
        "sure_prefix_ended": guides whose surely-feasible prefix the condition ends}.
    """
    covered = covered_ended = failed = failed_stopped = prefix_ended = 0
    for r, lvi in zip(rejected, np.asarray(last_valid), strict=True):
        end = sure_end(int(lvi), len(r), horizon)
        if end >= 0 and r[: end + 1].any():
            prefix_ended += 1
        if lvi >= len(r) - 1:
            covered += 1
            covered_ended += int(r.any())
        else:
            failed += 1
            failed_stopped += int(r[: max(int(lvi), -1) + 2].any())
    return {
        "covered": covered,
        "covered_ended": covered_ended,
        "failed": failed,
        "failed_stopped": failed_stopped,
        "sure_prefix_ended": prefix_ended,
    }


def path_threshold(minima: np.ndarray, target: float) -> float:
    """The largest threshold that lets at least `target` of the prefixes whose lowest logits
    are `minima` [K] (`prefix_minima`) pass whole."""
    from leas_jax.feasibility.fit import threshold_for

    return threshold_for(minima, np.ones(len(minima), bool), target)


def guide_logits(params, field, reach, guides) -> list[np.ndarray]:
    """The learned condition's logit at every pose of each guide: list of [L_n] float arrays.

    One jitted call over every guide padded to the longest (their last pose repeated): one
    compilation, whatever the lengths."""
    import jax

    from leas_jax.env import learned_feasibility as lf

    longest = max(len(g) for g in guides)
    padded = np.stack([np.concatenate([g, np.repeat(g[-1:], longest - len(g), axis=0)]) for g in guides])
    logits = jax.jit(jax.vmap(jax.vmap(lambda pose: lf.logit(params, field, pose, reach))))
    flat = np.asarray(logits(padded.astype(np.float32)))
    return [flat[k, : len(g)] for k, g in enumerate(guides)]


def prefix_minima(logits, last_valid, horizon: int) -> np.ndarray:
    """[K] the lowest logit on each guide's surely feasible prefix (`sure_end`), for the guides
    that have one: the condition lets the prefix through when the threshold is at most this."""
    return np.array(
        [
            lg[: sure_end(int(lvi), len(lg), horizon) + 1].min()
            for lg, lvi in zip(logits, np.asarray(last_valid), strict=True)
            if sure_end(int(lvi), len(lg), horizon) >= 0
        ]
    )


def plan_teacher_guides(
    teacher_path: str,
    teacher,
    arena,
    field,
    episodes: int,
    holdout: int,
    seed: int,
    workers: int,
    cache: Path,
):
    """(fitted guides, their last valid indices, holdout guides, theirs): `episodes` guides of the
    policy `teacher` (loaded from `teacher_path`)
    guides from reset seed `seed` and `holdout` from `seed + 1`, planned by the generator;
    kept in `cache` (.npz) and read back from it when it matches these settings."""
    from leas_jax.contacts.validation.pool import validate_paths
    from leas_jax.eval.geometric import arena_episodes

    settings = np.asarray(f"{teacher_path} {teacher.config.terrain} {episodes} {holdout} {seed}")
    if cache.is_file():
        with np.load(cache) as data:
            if str(data["settings"]) == str(settings):
                guides = np.split(data["poses"], np.cumsum(data["lengths"])[:-1])
                return (
                    guides[:episodes],
                    data["last_valid"][:episodes],
                    guides[episodes:],
                    data["last_valid"][episodes:],
                )

    def guides_of(n, s):
        run = arena_episodes(teacher, field, n=n, seed=s)
        return [run.poses[k, : run.lengths[k]].astype(np.float64) for k in range(n)]

    guides = guides_of(episodes, seed) + guides_of(holdout, seed + 1)
    print(f"planning {len(guides)} teacher guides", flush=True)
    results = validate_paths(arena, guides, teacher.config.env.timestep, workers=workers, return_plans=False)
    last_valid = np.array([r.last_valid_index for r in results])
    cache.parent.mkdir(parents=True, exist_ok=True)
    tmp = cache.with_name(cache.name + ".tmp.npz")
    np.savez(
        tmp,
        settings=settings,
        poses=np.concatenate(guides),
        lengths=np.array([len(g) for g in guides]),
        last_valid=last_valid,
    )
    tmp.replace(cache)
    return guides[:episodes], last_valid[:episodes], guides[episodes:], last_valid[episodes:]


def main(argv=None) -> dict:
    from common import add_out_argument, load_average, save, wilson

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--teacher",
        nargs="+",
        default=["checkpoints/leas_talos/pretrain"],
        help="run directories or policy.ckpt files whose guides' verdicts are fitted (aggregated: a "
        "DAgger round adds the policy trained with the last refit)",
    )
    parser.add_argument(
        "--weights", default="checkpoints/feasibility/walking.npz", help="weights refitted from"
    )
    parser.add_argument("--weights-out", required=True, help="where the refitted weights are written")
    parser.add_argument("--episodes", type=int, default=1024, help="teacher guides whose verdicts are fitted")
    parser.add_argument(
        "--holdout", type=int, default=256, help="other teacher guides the conditions are checked on"
    )
    parser.add_argument("--covered-per-guide", type=int, default=16, help="feasible poses drawn per guide")
    parser.add_argument("--anchors", type=int, default=8000, help="reset-like poses labelled by --weights")
    parser.add_argument("--steps", type=int, default=PATH_FIT_STEPS, help="AdamW steps of the refit")
    parser.add_argument(
        "--path-sensitivity",
        type=float,
        default=None,
        help="set the threshold so that this fraction of the fitted guides' surely feasible prefixes "
        "pass whole (default: the fit's per-pose rule, FitConfig.target_sensitivity)",
    )
    parser.add_argument(
        "--seed", type=int, default=0, help="reset seed of the fitted guides (holdout: seed + 1)"
    )
    parser.add_argument("--workers", type=int, default=2)
    add_out_argument(parser)
    args = parser.parse_args(argv)
    if args.path_sensitivity is not None and not 0.0 < args.path_sensitivity <= 1.0:
        parser.error(f"--path-sensitivity must be in (0, 1], got {args.path_sensitivity}")
    load_before = load_average()

    import jax.numpy as jnp
    from guide_failures import cell_kinds, kind_at

    from leas_jax.env import heightfield_from_terrain
    from leas_jax.env.learned_weights import load_params, save_params
    from leas_jax.feasibility.fit import FitConfig, features_of, fit, predict
    from leas_jax.feasibility.spawns import arena_field
    from leas_jax.files import resolve_data_path
    from leas_jax.stats import rates
    from leas_jax.terrain import load_terrain
    from leas_jax.training.config import learned_condition_env
    from leas_jax.training.planner import VERDICT_HORIZON, anchor_samples, verdict_samples
    from leas_jax.training.policy import load_policy

    teachers = [load_policy(path) for path in args.teacher]
    arena = load_terrain(teachers[0].config.terrain_path())
    if any(t.config.terrain_path() != teachers[0].config.terrain_path() for t in teachers):
        parser.error("--teacher: the policies were trained on different terrains")
    learned_env = learned_condition_env(teachers[0].config.env, args.weights)
    field = heightfield_from_terrain(arena, learned_env)
    reach = learned_env.reachability
    base, base_meta = load_params(resolve_data_path(args.weights))
    out = Path(args.out)
    planned = {
        path: plan_teacher_guides(
            path,
            teacher,
            arena,
            arena_field(arena, teacher.config.env, workers=args.workers),
            args.episodes,
            args.holdout,
            args.seed,
            args.workers,
            out / f"teacher_guides_{k}.npz",
        )
        for k, (path, teacher) in enumerate(zip(args.teacher, teachers, strict=True))
    }
    fitted_guides = [g for p in planned.values() for g in p[0]]
    fitted_lvi = np.concatenate([p[1] for p in planned.values()])

    rng = np.random.default_rng(args.seed)
    path_poses, path_labels = verdict_samples(fitted_guides, fitted_lvi, rng, args.covered_per_guide)
    out.mkdir(parents=True, exist_ok=True)
    tmp = out / "path_verdicts.tmp.npz"
    np.savez(tmp, poses=path_poses, labels=path_labels)  # TrainConfig.condition_seed_data's format
    tmp.replace(out / "path_verdicts.npz")
    anchor_poses, anchor_labels = anchor_samples(field, learned_env, args.anchors, rng)
    poses = np.concatenate([path_poses, anchor_poses])
    labels = np.concatenate([path_labels, anchor_labels])
    config = FitConfig(refresh_steps=args.steps)
    params, info = fit(features_of(base, field, poses, reach), labels, config, init=base, reach=reach)
    fitted_minima = {  # the logits do not depend on the threshold
        name: prefix_minima(guide_logits(weights, field, reach, fitted_guides), fitted_lvi, VERDICT_HORIZON)
        for name, weights in (("before", base), ("after", params))
    }
    if args.path_sensitivity is not None:
        info["per_pose_threshold"] = info["threshold"]
        info["threshold"] = path_threshold(fitted_minima["after"], args.path_sensitivity)
        params["threshold"] = jnp.asarray(info["threshold"], jnp.float32)
    save_params(
        Path(args.weights_out),
        params,
        refitted_from=args.weights,
        teacher=" ".join(args.teacher),
        train=f"{len(path_poses)} path-verdict poses of {args.episodes} guides (seed {args.seed}) of each teacher "
        f"+ {args.anchors} anchors labelled by {args.weights}",
        fit=json.dumps(
            {
                **dataclasses.asdict(config),
                "steps_from_init": args.steps,
                "path_sensitivity": args.path_sensitivity,
            }
        ),
        reachability=base_meta.get("reachability", json.dumps(dataclasses.asdict(reach))),
    )

    cells = cell_kinds(arena.text)
    holdout_samples = {
        path: verdict_samples(guides, lvi, np.random.default_rng(args.seed + 1), args.covered_per_guide)
        for path, (_, _, guides, lvi) in planned.items()
    }
    conditions = {}
    for name, weights in (("before", base), ("after", params)):
        conditions[name] = {}
        for path, (_, _, holdout_guides, holdout_lvi) in planned.items():
            logits = guide_logits(weights, field, reach, holdout_guides)
            rejected = [lg < float(weights["threshold"]) for lg in logits]
            outcome = path_outcomes(rejected, holdout_lvi, VERDICT_HORIZON)
            ended_cells = Counter(
                kind_at(cells, g[np.argmax(r), :2])
                for g, r, lvi in zip(holdout_guides, rejected, holdout_lvi, strict=True)
                if lvi >= len(g) - 1 and r.any()
            )
            trade = []
            for target in (0.5, 0.7, 0.8, 0.9, 0.95):
                threshold = path_threshold(fitted_minima[name], target)
                at = path_outcomes([lg < threshold for lg in logits], holdout_lvi, VERDICT_HORIZON)
                trade.append({"path_sensitivity": target, "threshold": threshold, **at})
            holdout_poses, holdout_labels = holdout_samples[path]
            conditions[name][path] = {
                **outcome,
                "threshold": float(weights["threshold"]),
                "covered_ended_95ci": list(wilson(outcome["covered_ended"], outcome["covered"])),
                "failed_stopped_95ci": list(wilson(outcome["failed_stopped"], outcome["failed"])),
                "covered_ended_by_cell": dict(ended_cells.most_common()),
                "holdout_poses": rates(
                    predict(weights, features_of(weights, field, holdout_poses, reach)), holdout_labels
                ),
                "path_thresholds": trade,
            }
    report = {
        "teachers": args.teacher,
        "weights": args.weights,
        "weights_out": args.weights_out,
        "terrain": arena.name,
        "episodes": args.episodes,
        "holdout": args.holdout,
        "seed": args.seed,
        "path_poses": int(len(path_poses)),
        "path_feasible": int(path_labels.sum()),
        "anchors": int(len(anchor_poses)),
        "anchors_feasible": int(anchor_labels.sum()),
        "fitted_guides": len(fitted_guides),
        "fitted_guides_covered": int(np.sum(fitted_lvi >= np.array([len(g) - 1 for g in fitted_guides]))),
        "fit": info,
        "conditions": conditions,
    }
    (out / "condition_from_paths.md").write_text(markdown(report))
    save("condition_from_paths", report, load_before, out)
    print(markdown(report))
    return report


def markdown(report: dict) -> str:
    """The report's tables."""
    lines = [
        f"Condition refitted from {report['weights']} on the generator's verdicts on "
        f"{report['fitted_guides']} guides of {', '.join(report['teachers'])} "
        f"({report['fitted_guides_covered']} fully covered; {report['path_poses']} poses, "
        f"{report['path_feasible']} feasible) + {report['anchors']} anchors "
        f"({report['anchors_feasible']} feasible); threshold {report['fit']['threshold']:.3f}.",
        "",
        f"Checked on {report['holdout']} other guides of each teacher (before: {report['weights']}, "
        f"after: {report['weights_out']}):",
        "",
        "| condition | teacher | covered guides it ends [95 % CI] | failed guides it stops [95 % CI] | "
        "sensitivity (poses) | specificity (poses) | covered guides ended, by cell |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, by_teacher in report["conditions"].items():
        for teacher, c in by_teacher.items():
            e, s, p = c["covered_ended_95ci"], c["failed_stopped_95ci"], c["holdout_poses"]
            by_cell = ", ".join(f"{k} {v}" for k, v in c["covered_ended_by_cell"].items()) or "none"
            lines.append(
                f"| {name} | {teacher} | {c['covered_ended']} / {c['covered']} "
                f"[{100 * e[0]:.1f}, {100 * e[1]:.1f} %] | {c['failed_stopped']} / {c['failed']} "
                f"[{100 * s[0]:.1f}, {100 * s[1]:.1f} %] | {100 * p['sensitivity']:.1f} % | "
                f"{100 * p['specificity']:.1f} % | {by_cell} |"
            )
    lines += [
        "",
        "Thresholds set for a share of the fitted guides' surely feasible prefixes passing whole, "
        "checked on the held-out guides:",
        "",
        "| condition | teacher | prefixes passing (fitted) | threshold | covered guides it ends | "
        "failed guides it stops |",
        "|---|---|---|---|---|---|",
    ]
    for name, by_teacher in report["conditions"].items():
        for teacher, c in by_teacher.items():
            for t in c["path_thresholds"]:
                lines.append(
                    f"| {name} | {teacher} | {100 * t['path_sensitivity']:.0f} % | {t['threshold']:.3f} | "
                    f"{t['covered_ended']} / {t['covered']} | {t['failed_stopped']} / {t['failed']} |"
                )
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
