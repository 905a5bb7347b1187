"""Tables and learning curves of the `quick` budget study: 30 M against 80 M geometric steps.

Reads study30/ and study80/ (feasibility_study.json of `studies/feasibility_study.py`, copied
here from its --out) and, with --runs, the runs' metrics.jsonl (learning curves; the runs
stay outside the repository). Writes summary.md and learning_curves.png beside this file.

    python docs/results/2026-12-06-quick-budget/summarise.py --runs runs/quick-budget
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
BUDGETS = {"30 M": "study30", "80 M": "study80"}
METRICS = [
    ("full_coverage", "own guides fully covered", 100, "%"),
    ("progress_m", "arena progress", 1, "m"),
    ("ground_speed", "eval_ground", 1, "m/s"),
    ("scenario/stairs", "stairs", 100, "%"),
    ("scenario/stairs_side", "stairs_side", 100, "%"),
    ("scenario/circuit", "circuit", 100, "%"),
    ("scenario/bridge", "bridge", 100, "%"),
    ("scenario/hole", "hole", 100, "%"),
]


def table(summaries: dict) -> str:
    """Markdown: a row per training seed and per budget (mean [95 % interval across seeds and starts])."""
    head = "| budget | seed | " + " | ".join(f"{title} ({unit})" for _, title, _, unit in METRICS) + " |"
    lines = [head, "|" + "---|" * (len(METRICS) + 2)]
    for budget, summary in summaries.items():
        seeds = len(summary["full_coverage"]["per_seed"])
        for k in range(seeds):
            cells = [
                f"{scale * summary[key]['per_seed'][k]:.{1 if unit == '%' else 3 if unit == 'm/s' else 2}f}"
                for key, _, scale, unit in METRICS
            ]
            lines.append(f"| {budget} | {k} | " + " | ".join(cells) + " |")
        cells = []
        for key, _, scale, unit in METRICS:
            r = summary[key]
            digits = 1 if unit == "%" else 3 if unit == "m/s" else 2
            cells.append(
                f"{scale * r['mean']:.{digits}f} [{scale * r['lo']:.{digits}f}, {scale * r['hi']:.{digits}f}]"
            )
        lines.append(f"| **{budget}**, {seeds} seeds | | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def curves(runs: Path, path: Path) -> None:
    """learning_curves.png: episode return and invalid-episode fraction against env steps, every run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    colors = {"30 M": "tab:orange", "80 M": "tab:blue"}
    for budget, study in BUDGETS.items():
        for metrics in sorted((runs / study / "runs" / "learned").glob("seed*/geometric/metrics.jsonl")):
            rows = [json.loads(line) for line in metrics.read_text().splitlines() if line.strip()]
            if len(rows) < 100:  # a run stopped early (the study was stopped after its first seed)
                continue
            steps = np.array([r["env_steps"] for r in rows]) / 1e6
            for ax, key in zip(axes, ("episode_return", "invalid_fraction"), strict=True):
                values = np.convolve([r[key] for r in rows], np.ones(15) / 15, mode="same")
                ax.plot(
                    steps[7:-7],
                    values[7:-7],
                    color=colors[budget],
                    lw=1,
                    label=f"{budget}, {metrics.parts[-3]}",
                )
    for ax, title in zip(axes, ("episode return", "episodes ending invalid (fraction)"), strict=True):
        ax.set_xlabel("env steps (M)")
        ax.set_title(title)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path, help="the studies' --out parent (learning curves)")
    args = parser.parse_args()
    summaries = {
        budget: json.loads((HERE / study / "feasibility_study.json").read_text())["summary"]["learned"]
        for budget, study in BUDGETS.items()
        if (HERE / study / "feasibility_study.json").is_file()
    }
    text = table(summaries)
    (HERE / "summary.md").write_text(text)
    print(text)
    if args.runs:
        curves(args.runs, HERE / "learning_curves.png")


if __name__ == "__main__":
    main()
