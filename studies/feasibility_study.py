"""Ablation study of the learned feasibility condition: does the learned condition, the planner in
the loop, or both, make guides the contact generator can follow?

Four methods, each trained from scratch with every seed of `--seeds`:

* `cylinders`: geometric PPO with the paper's cylinders (the preset's env), `--geometric-steps`;
* `cylinders+planner`: that same geometric run (same seed), then `--planner-steps` kept steps
  of planner-in-the-loop PPO (the preset's planner phase, the paper's pruning);
* `learned`: geometric PPO terminating on the learned condition (`--weights`), `--geometric-steps`;
* `learned+planner`: as `cylinders+planner` from the `learned` run, the condition refreshed on
  the generator's verdicts during the planner phase (DAgger, `--refresh-every`).

A planner phase continues its method's own geometric run, so each seed's pair differs only by
the planner phase (a paired comparison); it adds `--planner-steps` env steps to the geometric
budget (100 k against 30 M for `quick`: 0.3 %), so the methods train at equal env steps to
within that.

Per policy (deterministic): on the training arena, from the env's own random resets
(`--starts` per evaluation seed, `--eval-seeds`), the fraction of its guides the contact
generator covers fully, their mean coverage and the mean progress along the target direction
(400 steps, or `--episode-length`); the mean speed along the target on eval_ground; with
`--scenarios`, LeaS success on those scenarios (`leas evaluate`). Each figure comes with a
95 % interval across seeds and starts (a two-level bootstrap: seeds, then starts within each).

    python studies/feasibility_study.py --out DIR [--seeds 0,1,2] [--geometric-steps N]
        [--planner-steps N] [--starts 256] [--eval-seeds 0,1] [--scenarios eval_stairs ...]
        [--clearance-condition condition|cylinders]

Writes DIR/feasibility_study.json, feasibility_study.md and feasibility_study.png; training
runs go to DIR/runs/<method>/seed<k>: a finished run is reused, and so is its evaluation
(`study_evaluation.npz`, while the policy, the settings and the package's code are unchanged).

Results: docs/results/2026-12-01-feasibility, 2026-12-02-ablation, 2026-12-02-retry-settings,
2026-12-03-ablation, 2026-12-04-ablation-more-seeds, 2026-12-04-learned-clearance.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "benchmarks")]  # the other studies, benchmarks/common.py

PACKAGE = Path(__file__).resolve().parent.parent / "leas_jax"
METHODS = ("cylinders", "cylinders+planner", "learned", "learned+planner")
METRICS = {  # name: (label, unit)
    "full_coverage": ("guides fully covered", "%"),
    "mean_coverage": ("mean coverage", "%"),
    "progress_m": ("arena progress", "m"),
    "ground_speed": ("eval_ground speed", "m/s"),
}


def bootstrap_interval(
    groups: list[np.ndarray], resamples: int = 2000, seed: int = 0
) -> tuple[float, float, float]:
    """(mean, lo, hi): the mean of all values and its 95 % interval by a two-level bootstrap
    (resample the groups, e.g. training seeds, then the values within each, e.g. starts).

    Args:
        groups: one 1-D array of values per group (non-empty).
    """
    groups = [np.asarray(g, float) for g in groups if len(g)]
    if not groups:
        return float("nan"), float("nan"), float("nan")
    rng = np.random.default_rng(seed)
    means = np.empty(resamples)
    for r in range(resamples):
        picked = rng.integers(0, len(groups), len(groups))
        means[r] = np.mean(
            np.concatenate([g[rng.integers(0, len(g), len(g))] for g in (groups[i] for i in picked)])
        )
    lo, hi = np.percentile(means, [2.5, 97.5])
    return float(np.mean(np.concatenate(groups))), float(lo), float(hi)


def method_configs(method: str, seed: int, args):
    """(geometric TrainConfig, planner TrainConfig or None) of one method and seed; the
    geometric config is the same for `X` and `X+planner`."""
    from leas_jax.training.config import PRESETS, TRAINING_ENV, learned_condition_env, preset

    env = PRESETS[args.preset].get("env", TRAINING_ENV)  # the preset's env: `quick` adds the clearance term
    if method.startswith("learned"):
        env = learned_condition_env(env, args.weights)
    env = dataclasses.replace(
        env, episode_length=args.episode_length, clearance_condition=args.clearance_condition
    )
    geo = preset(
        args.preset,
        num_timesteps=args.geometric_steps,
        seed=seed,
        env=env,
        **({"num_envs": args.num_envs, "num_minibatches": 4} if args.num_envs else {}),
    )
    if not method.endswith("+planner"):
        return geo, None
    plan = preset(
        _planner_preset(args.preset),
        mode="planner",
        pretrain="",
        num_timesteps=args.planner_steps,
        num_envs=args.planner_envs,
        num_minibatches=4 if args.planner_envs % 4 == 0 else 1,
        seed=seed,
        env=env,
        condition_refresh_every=args.refresh_every if method == "learned+planner" else 0,
        condition_refresh_min_poses=args.refresh_min_poses,
        condition_refresh_sensitivity=args.refresh_sensitivity,
    )
    return geo, plan


def _planner_preset(geometric: str) -> str:
    """The planner-mode preset that continues geometric preset `geometric` (its namesake, else `smoke`)."""
    from leas_jax.training.config import PLANNER_PRESETS

    return geometric if geometric in PLANNER_PRESETS else "smoke"


def train_method(method: str, seed: int, args, out: Path) -> Path:
    """Train one method and seed (a finished run is resumed to its end, i.e. reused); its run
    directory. `X+planner` continues `X`'s geometric run of the same seed."""
    from leas_jax.training import train

    geo, plan = method_configs(method, seed, args)
    base = method.split("+")[0]
    geometric = out / "runs" / base / f"seed{seed}" / "geometric"
    train(geo, geometric, progress=False)
    if plan is None:
        return geometric
    plan = dataclasses.replace(plan, init_from=str(geometric))
    run = out / "runs" / method.replace("+", "_") / f"seed{seed}" / "planner"
    train(plan, run, progress=False, workers=args.workers)
    return run


EVALUATION_FILE = "study_evaluation.npz"  # in a run's directory: its evaluation, reused by a resumed study
# the arguments an evaluation depends on (with the policy file and the package's code)
EVALUATION_SETTINGS = (
    "starts",
    "eval_seeds",
    "ground_starts",
    "episode_length",
    "scenarios",
    "scenario_starts",
)


def evaluation_key(run_dir: Path, args) -> str:
    """sha256 (hex) of what `evaluate_policy(run_dir, args)` depends on: the run's policy file
    (bytes), the evaluation settings (`EVALUATION_SETTINGS`) and every .py file of the package
    (the generator, the env and the evaluation alike; any change re-evaluates)."""
    import hashlib

    from leas_jax.feasibility.spawns import generator_code_digest
    from leas_jax.training.checkpoint import policy_file

    digest = hashlib.sha256(b"leas-study-evaluation-v1")
    digest.update(policy_file(run_dir).read_bytes())
    settings = {name: getattr(args, name) for name in EVALUATION_SETTINGS}
    digest.update(json.dumps(settings, sort_keys=True, default=list).encode())
    digest.update(generator_code_digest(roots=(PACKAGE,)).encode())
    return digest.hexdigest()


def cached_evaluation(run_dir: Path, args, evaluate=None) -> dict:
    """`evaluate(run_dir, args)` (default `evaluate_policy`), read from the run's
    `EVALUATION_FILE` where it holds this `evaluation_key`, else computed and written there
    (atomically): a study stopped during a long evaluation campaign resumes without
    evaluating its finished policies again. A damaged or stale file is recomputed."""
    import io

    from leas_jax.files import atomic_write_bytes

    evaluate = evaluate or evaluate_policy
    path = Path(run_dir) / EVALUATION_FILE
    key = evaluation_key(run_dir, args)
    try:
        with np.load(path) as data:
            if str(data["key"]) == key:
                return _unflatten({name: data[name] for name in data.files if name != "key"})
    except (OSError, ValueError, KeyError):  # missing or damaged: evaluate again
        pass
    result = evaluate(run_dir, args)
    buffer = io.BytesIO()
    np.savez(buffer, key=np.array(key), **_flatten(result))
    atomic_write_bytes(path, buffer.getvalue())
    return result


def _flatten(result: dict) -> dict:
    """An evaluation's arrays under flat names (`scenarios/<name>` for its scenarios)."""
    flat = {name: values for name, values in result.items() if name != "scenarios"}
    flat.update({f"scenarios/{name}": values for name, values in result.get("scenarios", {}).items()})
    return flat


def _unflatten(flat: dict) -> dict:
    """The inverse of `_flatten`: an evaluation's dict from its flat arrays."""
    result = {name: np.asarray(values) for name, values in flat.items() if "/" not in name}
    scenarios = {
        name.split("/", 1)[1]: np.asarray(v) for name, v in flat.items() if name.startswith("scenarios/")
    }
    if scenarios:
        result["scenarios"] = scenarios
    return result


def evaluate_policy(run_dir: Path, args) -> dict:
    """Per-start arrays of one policy: full coverage and coverage of its arena guides, progress
    (per evaluation seed, concatenated), speed on eval_ground."""
    from leas_jax.contacts.validation.pool import validate_paths
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.eval.geometric import arena_episodes, ground_speed
    from leas_jax.files import resolve_data_path
    from leas_jax.terrain import load_terrain
    from leas_jax.training.policy import load_policy

    policy = load_policy(run_dir)  # with a DAgger run's own refreshed condition
    env = policy.config.env
    arena = load_terrain(policy.config.terrain_path())
    field = heightfield_from_terrain(arena, env)
    full, coverage, progress = [], [], []
    for eval_seed in args.eval_seeds:
        episodes = arena_episodes(policy, field, n=args.starts, seed=eval_seed, steps=args.episode_length)
        guides = [episodes.poses[k, : episodes.lengths[k]].astype(np.float64) for k in range(args.starts)]
        results = validate_paths(arena, guides, env.timestep, workers=args.workers, return_plans=False)
        cov = np.array([r.coverage for r in results])
        full.append(cov >= 1.0)
        coverage.append(cov)
        start = episodes.poses[:, 0, :2]
        final = episodes.poses[np.arange(args.starts), episodes.lengths - 1, :2]
        progress.append(_progress(policy, field, eval_seed, args.starts, start, final))
    ground = load_terrain(resolve_data_path("terrains/eval_ground.toml"))
    speed = ground_speed(
        policy,
        ground,
        heightfield_from_terrain(ground, env),
        n=args.ground_starts,
        seed=2,
        steps=args.episode_length,
    )
    out = {
        "full_coverage": np.concatenate(full).astype(float),
        "mean_coverage": np.concatenate(coverage),
        "progress_m": np.concatenate(progress),
        "ground_speed": np.asarray(speed.per_episode),
    }
    if args.scenarios:
        out["scenarios"] = _scenario_success(run_dir, args)
    return out


def _progress(policy, field, seed, n, start, final) -> np.ndarray:
    """[n] displacement along each episode's target direction (m): the env's resets of `arena_episodes`."""
    import jax

    from leas_jax.env import LeasEnv

    env = LeasEnv(field, policy.config.env)
    dirs = jax.vmap(lambda k: env.reset(k).pipeline_state.target_dir)(
        jax.random.split(jax.random.PRNGKey(seed), n)
    )
    return np.sum((final - start) * np.asarray(dirs), axis=1)


def _scenario_success(run_dir: Path, args) -> dict:
    """{scenario: [starts] 1.0 where LeaS succeeded} (`leas evaluate`'s seeded starts)."""
    from leas_jax.eval.evaluate import evaluate

    report = evaluate(
        list(args.scenarios),
        methods=["leas"],
        checkpoint=run_dir,
        out=None,
        n_starts=args.scenario_starts,
        workers=args.workers,
        progress=False,
        figures=False,
    )
    return {
        name: np.array([float(t["success"]) for t in scenario["trajectories"] if t["method"] == "leas"])
        for name, scenario in report["scenarios"].items()
    }


def summarise(per_seed: dict) -> dict:
    """{method: {metric: {mean, lo, hi, seeds}}} from {method: [per-seed dict of arrays]}."""
    table = {}
    for method, runs in per_seed.items():
        row = {}
        for metric in METRICS:
            mean, lo, hi = bootstrap_interval([r[metric] for r in runs])
            row[metric] = {
                "mean": mean,
                "lo": lo,
                "hi": hi,
                "per_seed": [float(np.mean(r[metric])) for r in runs],
            }
        scenarios = {}
        for run in runs:
            for name, values in run.get("scenarios", {}).items():
                scenarios.setdefault(name, []).append(values)
        for name, groups in scenarios.items():
            mean, lo, hi = bootstrap_interval(groups)
            row[f"scenario/{name}"] = {
                "mean": mean,
                "lo": lo,
                "hi": hi,
                "per_seed": [float(np.mean(g)) for g in groups],
            }
        table[method] = row
    return table


def _cell(entry: dict, unit: str) -> str:
    scale = 100.0 if unit == "%" else 1.0
    digits = 1 if unit == "%" else 3
    return f"{scale * entry['mean']:.{digits}f} [{scale * entry['lo']:.{digits}f}, {scale * entry['hi']:.{digits}f}]"


def markdown(report: dict) -> str:
    """The study's table: every metric of every method with its 95 % interval."""
    table = report["summary"]
    metrics = list(METRICS) + sorted({k for row in table.values() for k in row if k.startswith("scenario/")})

    def label(m: str) -> str:
        return f"{METRICS[m][0]} ({METRICS[m][1]})" if m in METRICS else m.split("/", 1)[1] + " success (%)"

    def unit(m: str) -> str:
        return METRICS[m][1] if m in METRICS else "%"

    s = report["settings"]
    lines = [
        "# Feasibility ablation",
        "",
        f"{len(s.get('seeds_done', s['seeds']))} training seeds ({', '.join(map(str, s.get('seeds_done', s['seeds'])))}; `seeds`: those each method finished), {s['geometric_steps']} geometric + {s['planner_steps']} planner env steps "
        f"(a planner phase continues its method's geometric run of the same seed); {s['starts']} arena starts x "
        f"{len(s['eval_seeds'])} evaluation seeds, {s['episode_length']}-step episodes. Mean [95 % interval "
        "across seeds and starts].",
        "",
        "| method | seeds | " + " | ".join(label(m) for m in metrics) + " |",
        "|---|---|" + "---|" * len(metrics),
    ]
    for method, row in table.items():
        seeds = len(row[next(iter(METRICS))]["per_seed"])  # a study stopped early: fewer for some methods
        lines.append(
            f"| {method} | {seeds} | "
            + " | ".join(_cell(row[m], unit(m)) if m in row else "-" for m in metrics)
            + " |"
        )
    return "\n".join(lines) + "\n"


def figure(report: dict, path: Path) -> None:
    """One panel per metric: each method's mean and 95 % interval."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    table = report["summary"]
    fig, axes = plt.subplots(1, len(METRICS), figsize=(4 * len(METRICS), 3.5))
    methods = list(table)
    for ax, (metric, (name, unit)) in zip(axes, METRICS.items(), strict=True):
        scale = 100.0 if unit == "%" else 1.0
        means = np.array([table[m][metric]["mean"] for m in methods]) * scale
        lo = np.array([table[m][metric]["lo"] for m in methods]) * scale
        hi = np.array([table[m][metric]["hi"] for m in methods]) * scale
        ax.bar(
            range(len(methods)), means, yerr=[means - lo, hi - means], capsize=4, color="tab:blue", alpha=0.7
        )
        ax.set_xticks(range(len(methods)), methods, rotation=30, ha="right", fontsize=8)
        ax.set_title(f"{name} ({unit})", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _parse_ints(name: str, text: str) -> tuple[int, ...]:
    from leas_jax.errors import UsageError

    try:
        values = tuple(int(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise UsageError(f"--{name}: expected comma-separated integers, got {text!r}") from None
    if not values:
        raise UsageError(f"--{name}: expected at least one integer")
    return values


def main(argv=None) -> dict:
    from common import machine

    from leas_jax.env.config import CLEARANCE_CONDITIONS
    from leas_jax.errors import UsageError
    from leas_jax.training.config import PLANNER_PRESETS, PRESETS

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--methods", default=",".join(METHODS))
    parser.add_argument("--seeds", default="0,1,2")
    parser.add_argument(
        "--preset", default="quick", help="geometric preset (its PPO settings; steps and env are set here)"
    )
    parser.add_argument("--num-envs", type=int, default=0, help="geometric envs (0: the preset's)")
    parser.add_argument(
        "--geometric-steps", type=int, default=0, help="geometric env steps (0: the preset's)"
    )
    parser.add_argument(
        "--planner-steps",
        type=int,
        default=0,
        help="kept planner-in-the-loop steps (0: the planner preset's)",
    )
    parser.add_argument("--planner-envs", type=int, default=64, help="guides validated per planner iteration")
    parser.add_argument(
        "--refresh-every", type=int, default=4, help="learned+planner: DAgger refresh period (iterations)"
    )
    parser.add_argument("--refresh-min-poses", type=int, default=400)
    parser.add_argument(
        "--refresh-sensitivity",
        type=float,
        default=None,
        help="learned+planner: the share of held-aside feasible poses a refit keeps feasible "
        "(TrainConfig.condition_refresh_sensitivity; default FitConfig's 0.95)",
    )
    parser.add_argument("--weights", default="checkpoints/feasibility/walking.npz")
    parser.add_argument(
        "--clearance-condition",
        choices=CLEARANCE_CONDITIONS,
        default="condition",
        help="what judges the clearance term's probe poses (EnvConfig.clearance_condition)",
    )
    parser.add_argument("--starts", type=int, default=256, help="arena starts per evaluation seed")
    parser.add_argument("--eval-seeds", default="0,1")
    parser.add_argument("--ground-starts", type=int, default=256)
    parser.add_argument("--episode-length", type=int, default=400)
    parser.add_argument("--scenarios", nargs="*", default=[])
    parser.add_argument("--scenario-starts", type=int, default=30)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument(
        "--tables-only",
        action="store_true",
        help="rewrite the table and plot from --out's feasibility_study.json (e.g. of a study stopped early)",
    )
    args = parser.parse_args(argv)
    if args.tables_only:
        path = Path(args.out) / "feasibility_study.json"
        try:
            report = json.loads(path.read_text())
        except (OSError, ValueError) as error:
            raise UsageError(f"--tables-only: cannot read {path} ({error})") from None
        (path.parent / "feasibility_study.md").write_text(markdown(report))
        figure(report, path.parent / "feasibility_study.png")
        return report
    methods = tuple(m for m in args.methods.split(",") if m)
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise UsageError(f"--methods: unknown {', '.join(unknown)}; choose among {', '.join(METHODS)}")
    args.seeds = _parse_ints("seeds", args.seeds)
    args.eval_seeds = _parse_ints("eval-seeds", args.eval_seeds)
    if args.preset not in PRESETS:
        raise UsageError(f"--preset: unknown {args.preset!r}; choose among {', '.join(PRESETS)}")
    for name in ("geometric_steps", "planner_steps"):
        if getattr(args, name) < 0:
            raise UsageError(f"--{name.replace('_', '-')} must be >= 0 (0: the preset's)")
    args.geometric_steps = args.geometric_steps or PRESETS[args.preset]["num_timesteps"]
    args.planner_steps = args.planner_steps or PLANNER_PRESETS[_planner_preset(args.preset)]["num_timesteps"]
    for name in (
        "planner_envs",
        "starts",
        "ground_starts",
        "episode_length",
    ):
        if getattr(args, name) < 1:
            raise UsageError(f"--{name.replace('_', '-')} must be >= 1")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    began = time.perf_counter()
    per_seed, timings = {m: [] for m in methods}, {}
    settings = {k: (list(v) if isinstance(v, tuple) else v) for k, v in vars(args).items() if k != "out"}
    report = {}
    # seeds outer, methods inner: the report is rewritten after every run, so a study stopped
    # early holds every method for the seeds it finished
    for seed in args.seeds:
        for method in methods:
            t0 = time.perf_counter()
            run = train_method(method, seed, args, out)
            t1 = time.perf_counter()
            per_seed[method].append(cached_evaluation(run, args))
            timings[f"{method}/seed{seed}"] = {
                "train_s": round(t1 - t0, 1),
                "eval_s": round(time.perf_counter() - t1, 1),
            }
            print(
                f"{method} seed {seed}: trained {t1 - t0:.0f} s, evaluated {time.perf_counter() - t1:.0f} s",
                flush=True,
            )
            report = {
                "format": "leas-feasibility-study-v1",
                "settings": {**settings, "seeds_done": sorted({int(k.split("seed")[-1]) for k in timings})},
                "summary": summarise({m: runs for m, runs in per_seed.items() if runs}),
                "timings": timings,
                "seconds": round(time.perf_counter() - began, 1),
                "machine": machine(),
            }
            (out / "feasibility_study.json").write_text(json.dumps(report, indent=2))
            (out / "feasibility_study.md").write_text(markdown(report))
    figure(report, out / "feasibility_study.png")
    print(markdown(report))
    return report


if __name__ == "__main__":
    main()
