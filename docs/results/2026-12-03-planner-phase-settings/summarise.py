"""Tables and figure of run.sh: the planner phase's settings against its own arena guides.

First table: the pretrain (judged again here), the 150 k-step phase of
../2026-12-02-planner-phase and each variant of this folder (length/, minibatches/), each
policy on the same 256 starts (evaluation seed 0), seeds pooled by a two-level bootstrap
(seeds, then starts). Second table, from each run's metrics.jsonl: the share of the
stochastic training guides the generator covered fully in the first and last `WINDOW`
iterations, pooled over seeds the same way. Figure: training_coverage.png.

    python docs/results/2026-12-03-planner-phase-settings/summarise.py docs/results/2026-12-03-planner-phase-settings
"""

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[3]
sys.path[:0] = [str(REPO / "studies"), str(REPO / "benchmarks")]
from feasibility_study import bootstrap_interval  # noqa: E402

SHORT_PHASE = REPO / "docs/results/2026-12-02-planner-phase"
_spec = importlib.util.spec_from_file_location("short_phase_summary", SHORT_PHASE / "summarise.py")
short_phase_summary = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(short_phase_summary)

VARIANTS = ("length", "minibatches")
WINDOW = 4  # iterations (256 training guides per seed) at each end of a run
GUIDES_PER_ITERATION = 64  # the `paper` planner preset's num_envs


def reports(folder: Path, pattern: str) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted(folder.glob(pattern))]


def label(run: Path) -> str:
    """'150 k kept steps, 4 mini-batches' from a run's config.json."""
    config = json.loads((run / "config.json").read_text())
    return f"{config['num_timesteps'] / 1e3:,.0f} k kept steps, {config['num_minibatches']} mini-batches"


def training_rows(variant: Path) -> dict[str, list[dict]]:
    """{seed folder name: [metrics row of each iteration]}."""
    runs = {}
    for path in sorted(variant.glob("seed*/metrics.jsonl")):
        rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
        runs[path.parent.name] = [r for r in rows if "full_coverage_fraction" in r]
    return runs


def covered_guides(rows: list[dict]) -> np.ndarray:
    """[64 x len(rows)] 1.0 per training guide the generator covered fully."""
    counts = [round(r["full_coverage_fraction"] * GUIDES_PER_ITERATION) for r in rows]
    return np.concatenate([np.r_[np.ones(c), np.zeros(GUIDES_PER_ITERATION - c)] for c in counts])


def interval(groups: list[np.ndarray]) -> str:
    mean, lo, hi = bootstrap_interval(groups)
    return f"{100 * mean:.1f} % [{100 * lo:.1f}, {100 * hi:.1f}]"


def figure(variants: dict[str, dict[str, list[dict]]], path: Path) -> None:
    from leas_jax.plotting import agg_figure

    fig = agg_figure(9, 3.4)
    left, right = fig.subplots(1, 2)
    for (name, runs), color in zip(variants.items(), ("tab:blue", "tab:orange"), strict=False):
        for i, rows in enumerate(runs.values()):
            steps = np.array([r["env_steps"] for r in rows]) / 1e6
            full = np.array([r["full_coverage_fraction"] for r in rows])
            smooth = np.convolve(full, np.ones(WINDOW) / WINDOW, mode="valid")
            tag = dict(label=name) if i == 0 else {}
            left.plot(steps[WINDOW - 1 :], 100 * smooth, color=color, **tag)
            right.plot(steps, [r["episode_length"] for r in rows], color=color, **tag)
    left.set(
        xlabel="kept steps (M)", ylabel="training guides fully covered (%)", title=f"{WINDOW}-iteration mean"
    )
    right.set(xlabel="kept steps (M)", ylabel="steps per episode", title="episode length, one line per seed")
    left.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(folder: Path) -> None:
    row = short_phase_summary.row
    print(
        "| policy | seeds | fully covered (95 % interval) | per seed (%) | mean coverage | progress (m) "
        "| episodes without an invalid pose |"
    )
    print("|---|---|---|---|---|---|---|")
    pretrain = reports(folder, "pretrain/guide_failures.json")
    if pretrain:
        print(row("pretrain (geometric only), judged again", pretrain))
    short = reports(SHORT_PHASE, "seed*/guides/guide_failures.json")
    print(row(f"+ planner phase, {label(SHORT_PHASE / 'seed0')} (../2026-12-02-planner-phase)", short))
    variants = {}
    for name in VARIANTS:
        judged = reports(folder / name, "seed*/guides/guide_failures.json")
        if judged:
            print(row(f"+ planner phase, {label(folder / name / 'seed0')} ({name}/)", judged))
            variants[name] = training_rows(folder / name)
    print()
    print(
        f"| run | iterations | kept steps, s, kept steps/s, learner waiting | training guides fully covered, "
        f"first {WINDOW} iterations | last {WINDOW} | steps per episode, first -> last {WINDOW} |"
    )
    print("|---|---|---|---|---|---|")
    for name, runs in variants.items():
        for seed, rows in runs.items():
            last = rows[-1]
            wall = last["wall_s"]  # cumulative
            first_len = np.mean([r["episode_length"] for r in rows[:WINDOW]])
            last_len = np.mean([r["episode_length"] for r in rows[-WINDOW:]])
            print(
                f"| {name}/{seed} | {len(rows)} | {last['env_steps']:,}, {wall:.0f} s, "
                f"{last['env_steps'] / wall:,.0f}, {100 * np.mean([r['wait_fraction'] for r in rows]):.0f} % "
                f"| {100 * covered_guides(rows[:WINDOW]).mean():.1f} % "
                f"| {100 * covered_guides(rows[-WINDOW:]).mean():.1f} % | {first_len:.0f} -> {last_len:.0f} |"
            )
        first = [covered_guides(rows[:WINDOW]) for rows in runs.values()]
        last = [covered_guides(rows[-WINDOW:]) for rows in runs.values()]
        print(f"| {name}, seeds pooled | | | {interval(first)} | {interval(last)} | |")
    figure(variants, folder / "training_coverage.png")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
