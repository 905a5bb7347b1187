"""Table of run.sh: each planner-phase seed's own arena guides against its pretrain's and the
shipped policy's (same starts: evaluation seed 0, 256 starts), with the seeds pooled by a
two-level bootstrap (seeds, then starts) as studies/feasibility_study.py does.

    python docs/results/2026-12-02-planner-phase/summarise.py docs/results/2026-12-02-planner-phase
"""

import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[3]
sys.path[:0] = [str(REPO / "studies"), str(REPO / "benchmarks")]
from feasibility_study import bootstrap_interval  # noqa: E402

REFERENCES = {
    "pretrain (geometric only)": "docs/results/2026-12-02-retry-settings/guides/pretrain/seed0",
    "shipped (planner phase on an earlier generator)": "docs/results/2026-12-02-column-sampling/guides_shipped_seed0",
}


def covered(report: dict) -> np.ndarray:
    """[starts] 1.0 where the guide was fully covered (every start not listed as a failure)."""
    full = np.ones(report["starts"])
    full[[f["start"] for f in report["failures"]]] = 0.0
    return full


def row(label: str, reports: list[dict]) -> str:
    groups = [covered(r) for r in reports]
    mean, lo, hi = bootstrap_interval(groups)
    per_seed = ", ".join(f"{100 * g.mean():.1f}" for g in groups)
    progress = np.mean([r["mean_progress_m"] for r in reports])
    coverage = np.mean([r["mean_coverage"] for r in reports])
    valid = np.mean([r["valid_fraction"] for r in reports])
    return (
        f"| {label} | {len(reports)} | {100 * mean:.1f} % [{100 * lo:.1f}, {100 * hi:.1f}] | {per_seed} "
        f"| {100 * coverage:.1f} % | {progress:.2f} | {100 * valid:.1f} % |"
    )


def main(folder: Path) -> None:
    print(
        "| policy | seeds | fully covered (95 % interval) | per seed (%) | mean coverage | progress (m) "
        "| episodes without an invalid pose |"
    )
    print("|---|---|---|---|---|---|---|")
    for label, path in REFERENCES.items():
        print(row(label, [json.loads((REPO / path / "guide_failures.json").read_text())]))
    seeds = sorted(folder.glob("seed*/guides/guide_failures.json"))
    print(row("pretrain + planner phase (150 k kept steps)", [json.loads(p.read_text()) for p in seeds]))
    print()
    print(
        "| seed | training: kept steps, s, kept steps/s, learner waiting | full coverage during training, "
        "first -> last iteration |"
    )
    print("|---|---|---|")
    for path in sorted(folder.glob("seed*/metrics.jsonl")):
        rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
        rows = [r for r in rows if "full_coverage_fraction" in r]
        last = rows[-1]
        wall = last["wall_s"]  # cumulative
        print(
            f"| {path.parent.name} | {last['env_steps']:,}, {wall:.0f} s, {last['env_steps'] / wall:,.0f}, "
            f"{100 * np.mean([r['wait_fraction'] for r in rows]):.0f} % | "
            f"{100 * rows[0]['full_coverage_fraction']:.1f} -> {100 * last['full_coverage_fraction']:.1f} % |"
        )


if __name__ == "__main__":
    main(Path(sys.argv[1]))
