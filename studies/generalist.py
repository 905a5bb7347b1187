"""Does a policy trained on the curriculum of procedural terrains keep its coverage on arenas it
never saw, and walk round what it sees, better than one trained on the paper's fixed arena?

Each policy is measured
  - on arenas, from the env's own random resets (random start, yaw, target direction; 400
    steps; the policy's own condition ends an episode): its progress along the target
    direction over `--episodes` starts per evaluation seed, and the share of its own guides
    the contact generator covers fully over the first `--guides` of them (Wilson 95 %);
    arenas: the paper's training arena, a freshly seeded one (`leas terrain generate --seed
    7`), hpp-environments' random_scene_10x10_V3 and V5, and the curriculum arena (resets
    over all its rows, not the curriculum's);
  - on scenarios (`leas evaluate --methods leas`, seeded starts): success and coverage on the
    evaluation scenarios, the HPP scenes' scenarios and both pillar checks.

    python studies/generalist.py --policy paper=checkpoints/leas_talos/pretrain \\
        --policy generalist=RUN_DIR --out docs/results/2026-12-06-generalist

writes `generalist.json`, `generalist.md` and `generalist.png` into `--out` (resumable: a
finished (policy, arena, seed) or (policy, scenario) is read back from the JSON);
`--training-curves RUN_DIR` also draws a curriculum run's learning curves (mean row, episodes
ending invalid, episode length and return) into `training_<run name>.png`.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import time
from pathlib import Path

import numpy as np

from leas_jax.stats import wilson

ROOT = Path(__file__).resolve().parents[1]
ARENAS = {
    "paper_arena": "terrains/training_arena.toml",
    "fresh_arena_seed7": None,  # generated into --out
    "random_10x10_V3": "terrains/hpp/random_10x10.toml",
    "random_10x10_V5": "terrains/hpp/random_10x10_v5.toml",
    "curriculum_arena": "terrains/curriculum_arena.toml",
}
SCENARIOS = (
    "terrains/eval_hole.toml",
    "terrains/eval_bridge.toml",
    "terrains/eval_stairs.toml",
    "terrains/eval_stairs_side.toml",
    "terrains/eval_circuit.toml",
    "terrains/hpp/stairs.toml",
    "terrains/hpp/rubble.toml",
    "terrains/hpp/bridge.toml",
    "terrains/checks/pillars.toml",
    "terrains/checks/pillars_in_the_way.toml",
)
FRESH_SEED = 7


def _arena_path(name: str, out: Path) -> Path:
    if ARENAS[name] is not None:
        return ROOT / ARENAS[name]
    from leas_jax.terrain.generate import generate_training_arena

    path = out / f"training_arena_seed{FRESH_SEED}.toml"
    if not path.exists():
        path.write_text(generate_training_arena(FRESH_SEED))
    return path


def arena_row(policy, terrain_path: Path, seed: int, episodes: int, guides: int, workers: int) -> dict:
    """Progress over `episodes` resets and full coverage of the first `guides` guides."""
    from leas_jax.contacts.validation.pool import validate_paths
    from leas_jax.eval.geometric import arena_episodes
    from leas_jax.feasibility.spawns import arena_field
    from leas_jax.terrain import load_terrain

    terrain = load_terrain(terrain_path)
    field = arena_field(terrain, policy.config.env, progress=False)
    field = field.replace(curriculum={})  # resets over the whole arena, every row alike
    result = arena_episodes(policy, field, n=episodes, seed=seed)
    lengths = np.asarray(result.lengths)
    paths = [np.asarray(result.poses[k, : lengths[k]], np.float64) for k in range(guides)]
    began = time.perf_counter()
    checked = validate_paths(terrain, paths, policy.config.env.timestep, workers=workers, return_plans=False)
    coverage = np.array([r.coverage for r in checked])
    full = int((coverage >= 1.0).sum())
    return {
        "episodes": episodes,
        "valid_fraction": result.valid_fraction,
        "mean_progress_m": result.mean_progress,
        "guides": guides,
        "fully_covered": full,
        "mean_coverage": float(coverage.mean()),
        "validation_s": round(time.perf_counter() - began, 1),
    }


def scenario_row(
    checkpoint: str, terrain: str, n_starts: int | None, workers: int, method: str = "leas"
) -> dict:
    """Success and coverage of `leas evaluate --methods METHOD` on a terrain file with a
    [scenario] (relative to the repository or absolute; n_starts None: the table's)."""
    from leas_jax.eval.evaluate import evaluate

    report = evaluate(
        [],
        methods=[method],
        checkpoint=checkpoint,
        out=None,
        n_starts=n_starts,
        workers=workers,
        terrain_file=str(ROOT / terrain),
        progress=False,
        figures=False,
    )
    runs = [t for scenario in report["scenarios"].values() for t in scenario["trajectories"]]
    return {
        "n": len(runs),
        "success": sum(bool(t["success"]) for t in runs),
        "mean_coverage": float(np.mean([t["coverage"] for t in runs])),
    }


def percent_with_interval(k: int, n: int) -> str:
    """'p [lo, hi]': k of n in percent with its Wilson 95 % interval."""
    low, high = wilson(k, n)
    return f"{100 * k / n:.1f} [{100 * low:.1f}, {100 * high:.1f}]"


def markdown(results: dict) -> str:
    policies = list(results["policies"])
    lines = ["## Arenas: own guides fully covered % [95 % CI] (seeds pooled) and progress (m)", ""]
    lines.append("| arena | " + " | ".join(f"{p}: covered | {p}: progress" for p in policies) + " |")
    lines.append("|---" * (1 + 2 * len(policies)) + "|")
    for arena in ARENAS:
        cells = []
        for p in policies:
            rows = list(results["arenas"].get(p, {}).get(arena, {}).values())
            if not rows:
                cells += ["", ""]
                continue
            k, n = sum(r["fully_covered"] for r in rows), sum(r["guides"] for r in rows)
            progress = np.mean([r["mean_progress_m"] for r in rows])
            cells += [f"{percent_with_interval(k, n)} (n {n})", f"{progress:.2f}"]
        lines.append(f"| {arena} | " + " | ".join(cells) + " |")
    lines += ["", "## Scenarios: LeaS success % [95 % CI] (coverage %)", ""]
    lines.append("| scenario | " + " | ".join(policies) + " |")
    lines.append("|---" * (1 + len(policies)) + "|")
    for scenario in SCENARIOS:
        cells = []
        for p in policies:
            r = results["scenarios"].get(p, {}).get(scenario)
            cells.append(
                ""
                if r is None
                else f"{percent_with_interval(r['success'], r['n'])} ({100 * r['mean_coverage']:.0f})"
            )
        lines.append(f"| {Path(scenario).stem} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def plot(results: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    policies = list(results["policies"])
    figure, ax = plt.subplots(figsize=(8, 3.5), layout="constrained")
    width = 0.8 / len(policies)
    for j, p in enumerate(policies):
        values, errors = [], [[], []]
        for arena in ARENAS:
            rows = list(results["arenas"].get(p, {}).get(arena, {}).values())
            k, n = sum(r["fully_covered"] for r in rows), sum(r["guides"] for r in rows)
            value = k / n if n else np.nan
            low, high = wilson(k, n) if n else (np.nan, np.nan)
            values.append(100 * value)
            errors[0].append(100 * (value - low))
            errors[1].append(100 * (high - value))
        ax.bar(np.arange(len(ARENAS)) + j * width, values, width, yerr=errors, label=p, capsize=3)
    ax.axhline(90, color="grey", lw=0.8, ls="--")
    ax.set_xticks(np.arange(len(ARENAS)) + width * (len(policies) - 1) / 2, list(ARENAS), fontsize=8)
    ax.set_ylabel("own guides fully covered (%)")
    ax.legend(fontsize=8)
    figure.savefig(path, dpi=100)
    plt.close(figure)


TRAINING_PANELS = [
    ("curriculum_level", "mean curriculum row"),
    ("invalid_fraction", "episodes ending invalid (fraction)"),
    ("episode_length", "episode length (steps)"),
    ("episode_return", "episode return"),
]


def plot_training(run_dir: Path, path: Path) -> None:
    """Learning curves of a curriculum run (its metrics.jsonl)."""
    from leas_jax.eval.report import plot_curves, read_metrics

    plot_curves(read_metrics(run_dir), TRAINING_PANELS, path)


def machine() -> dict:
    """The machine, its load and the repository's commit, recorded with a study's results."""
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    return {
        "machine": platform.processor() or platform.machine(),
        "cpus": os.cpu_count(),
        "load": os.getloadavg()[0],
        "commit": commit.stdout.strip(),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--policy", action="append", required=True, metavar="LABEL=RUN_DIR")
    parser.add_argument("--out", required=True)
    parser.add_argument("--episodes", type=int, default=256, help="arena episodes per seed (progress)")
    parser.add_argument("--guides", type=int, default=64, help="of them validated per seed (coverage)")
    parser.add_argument("--seeds", default="0,1", help="evaluation seeds of the arena episodes")
    parser.add_argument("--arenas", default=",".join(ARENAS))
    parser.add_argument("--n-starts", type=int, default=20, help="starts per scenario cell")
    parser.add_argument("--no-scenarios", action="store_true")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--training-curves", action="append", default=[], metavar="RUN_DIR")
    args = parser.parse_args()

    from leas_jax.training.policy import load_policy

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    store = out / "generalist.json"
    results = (
        json.loads(store.read_text()) if store.exists() else {"policies": {}, "arenas": {}, "scenarios": {}}
    )

    def save():
        results["machine"] = machine()
        tmp = store.with_suffix(".tmp")
        tmp.write_text(json.dumps(results, indent=1) + "\n")
        tmp.replace(store)
        (out / "generalist.md").write_text(markdown(results))
        plot(results, out / "generalist.png")

    for run_dir in args.training_curves:
        plot_training(Path(run_dir), out / f"training_{Path(run_dir).name}.png")
    seeds = [int(s) for s in args.seeds.split(",")]
    for item in args.policy:
        label, _, run_dir = item.partition("=")
        results["policies"][label] = run_dir
        policy = load_policy(run_dir)
        for arena in args.arenas.split(","):
            for seed in seeds:
                done = results["arenas"].setdefault(label, {}).setdefault(arena, {})
                if str(seed) in done:
                    continue
                began = time.perf_counter()
                row = arena_row(
                    policy, _arena_path(arena, out), seed, args.episodes, args.guides, args.workers
                )
                done[str(seed)] = row
                save()
                print(
                    f"{label} {arena} seed {seed}: {row['fully_covered']}/{row['guides']} covered, "
                    f"progress {row['mean_progress_m']:.2f} m ({time.perf_counter() - began:.0f} s)",
                    flush=True,
                )
        if args.no_scenarios:
            continue
        for scenario in SCENARIOS:
            done = results["scenarios"].setdefault(label, {})
            if scenario in done:
                continue
            done[scenario] = scenario_row(run_dir, scenario, args.n_starts, args.workers)
            save()
            print(f"{label} {scenario}: {done[scenario]['success']}/{done[scenario]['n']}", flush=True)
    save()
    print(markdown(results))


if __name__ == "__main__":
    main()
