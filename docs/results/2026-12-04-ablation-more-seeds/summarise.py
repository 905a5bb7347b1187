"""The geometric methods over every training seed: ../2026-12-03-ablation's seeds 0-2 and this
folder's study (seeds 3-5, or those it finished), same preset and evaluation.

Per method: each seed's figures, the mean over seeds with a 95 % interval from resampling the
seeds (each seed's own mean; the starts within a seed are not resampled, so the interval is the
spread between training seeds), and the seeds whose policy climbs both stairs and finishes the
circuit (success >= 50 % on each), compared between the methods by Fisher's exact test.

    python docs/results/2026-12-04-ablation-more-seeds/summarise.py > docs/results/2026-12-04-ablation-more-seeds/summary.md
"""

import json
import sys
from pathlib import Path

from scipy.stats import fisher_exact

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
sys.path[:0] = [str(REPO / "studies"), str(REPO / "benchmarks")]
from feasibility_study import bootstrap_interval  # noqa: E402

STUDIES = (REPO / "docs/results/2026-12-03-ablation/study", HERE / "study")
METHODS = ("cylinders", "learned")
COLUMNS = {  # summary key: (label, scale, format)
    "full_coverage": ("fully covered", 100, "{:.1f} %"),
    "progress_m": ("progress", 1, "{:.2f} m"),
    "ground_speed": ("eval_ground", 1, "{:.3f} m/s"),
    "scenario/stairs": ("stairs", 100, "{:.0f} %"),
    "scenario/stairs_side": ("stairs_side", 100, "{:.0f} %"),
    "scenario/circuit": ("circuit", 100, "{:.0f} %"),
    "scenario/bridge": ("bridge", 100, "{:.0f} %"),
    "scenario/hole": ("hole", 100, "{:.0f} %"),
}
CLIMBS = ("scenario/stairs", "scenario/stairs_side", "scenario/circuit")


def per_seed(method: str) -> list[dict]:
    """[{summary key: that seed's mean, "seed": k}] over both studies, in seed order."""
    rows = []
    for study in STUDIES:
        path = study / "feasibility_study.json"
        if not path.is_file():
            continue
        report = json.loads(path.read_text())
        summary = report["summary"].get(method)
        if summary is None:
            continue
        seeds = [s for s in report["settings"]["seeds"] if s in report["settings"]["seeds_done"]]
        for i, seed in enumerate(seeds[: len(summary["full_coverage"]["per_seed"])]):
            rows.append({"seed": seed, **{k: summary[k]["per_seed"][i] for k in COLUMNS}})
    return rows


def climbs(row: dict) -> bool:
    return all(row[k] >= 0.5 for k in CLIMBS)


def main() -> None:
    seeds = {m: per_seed(m) for m in METHODS}
    print("| method | seed | " + " | ".join(label for label, _, _ in COLUMNS.values()) + " |")
    print("|---|---|" + "---|" * len(COLUMNS))
    for method, rows in seeds.items():
        for row in rows:
            cells = [fmt.format(row[k] * scale) for k, (_, scale, fmt) in COLUMNS.items()]
            print(f"| {method} | {row['seed']} | " + " | ".join(cells) + " |")
        means = []
        for k, (_, scale, fmt) in COLUMNS.items():
            mean, lo, hi = bootstrap_interval([[row[k]] for row in rows])
            number = fmt.split("}")[0] + "}"  # the interval's bounds without the unit
            means.append(
                f"{fmt.format(mean * scale)} [{number.format(lo * scale)}, {number.format(hi * scale)}]"
            )
        print(f"| **{method}**, {len(rows)} seeds | | " + " | ".join(means) + " |")
    print()
    counts = {m: sum(climbs(r) for r in rows) for m, rows in seeds.items()}
    table = [[counts[m], len(seeds[m]) - counts[m]] for m in METHODS]
    _, p = fisher_exact(table)
    print(
        "Seeds whose policy climbs both stairs and finishes the circuit (>= 50 % success on each): "
        + ", ".join(f"{m} {counts[m]} of {len(seeds[m])}" for m in METHODS)
        + f"; Fisher's exact test, two-sided: p = {p:.3f}."
    )


if __name__ == "__main__":
    main()
