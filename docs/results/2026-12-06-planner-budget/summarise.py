"""Table of the planner-budget study: each `quick` geometric policy, and its planner phase of
100 k and of 150 k kept steps, on its own arena guides and on eval_bridge / eval_stairs.

Reads <variant>/seed<S>/guide_failures.json (`studies/guide_failures.py`), <variant>/seed<S>/
scenarios/results.json (`leas evaluate`) and, for the planner variants, <variant>/seed<S>/
metrics.jsonl (the phase's wall time and kept steps). Prints the markdown table.

    python docs/results/2026-12-06-planner-budget/summarise.py > docs/results/2026-12-06-planner-budget/summary.md
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2]))

from leas_jax.stats import newcombe_difference, wilson  # noqa: E402

VARIANTS = {
    "geometric": "geometric (30 M)",
    "planner100000": "+ 100 k kept steps",
    "planner150000": "+ 150 k kept steps",
}
SEEDS = (0, 1, 2)


def seed_record(folder: Path) -> dict:
    """The figures of one policy: own guides, scenarios and (planner runs) the phase's cost."""
    guides = json.loads((folder / "guide_failures.json").read_text())
    scenarios = json.loads((folder / "scenarios" / "results.json").read_text())["scenarios"]
    record = {
        "starts": guides["starts"],
        "full": round(guides["full_coverage"] * guides["starts"]),
        "progress": guides["mean_progress_m"],
        "valid": guides["valid_fraction"],
    }
    for name, scenario in scenarios.items():
        runs = [t for t in scenario["trajectories"] if t["method"] == "leas"]
        record[name] = (sum(bool(t["success"]) for t in runs), len(runs))
        record[f"{name}_full"] = sum(t["coverage"] >= 1.0 for t in runs)
    metrics = folder / "metrics.jsonl"
    if metrics.is_file():
        last = json.loads(metrics.read_text().splitlines()[-1])
        record["wall_s"], record["kept"] = last["wall_s"], last["env_steps"]
    return record


def percent(k: int, n: int) -> str:
    low, high = wilson(k, n)
    return f"{100 * k / n:.1f} % [{100 * low:.1f}, {100 * high:.1f}]"


def main() -> None:
    records = {
        v: [
            seed_record(HERE / v / f"seed{s}")
            for s in SEEDS
            if (HERE / v / f"seed{s}" / "scenarios" / "results.json").is_file()
        ]
        for v in VARIANTS
    }
    print(
        "| policy | seeds | own guides fully covered (pooled) | per seed | progress per episode | bridge crossed (pooled) | bridge guides fully covered | stairs crossed | phase wall time, kept steps |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    pooled = {}
    for variant, label in VARIANTS.items():
        rows = [r for r in records[variant] if "bridge" in r and "stairs" in r]
        if not rows:
            continue
        full, starts = sum(r["full"] for r in rows), sum(r["starts"] for r in rows)
        bridge = (sum(r["bridge"][0] for r in rows), sum(r["bridge"][1] for r in rows))
        stairs = (sum(r["stairs"][0] for r in rows), sum(r["stairs"][1] for r in rows))
        bridge_full = sum(r["bridge_full"] for r in rows)
        pooled[variant] = {"full": (full, starts), "bridge": bridge, "stairs": stairs}
        per_seed = ", ".join(f"{100 * r['full'] / r['starts']:.1f}" for r in rows)
        progress = ", ".join(f"{r['progress']:.2f}" for r in rows)
        cost = (
            ", ".join(f"{r['wall_s']:.0f} s / {r['kept'] / 1e3:.0f} k" for r in rows if "wall_s" in r) or "-"
        )
        print(
            f"| {label} | {len(rows)} | {percent(full, starts)} | "
            f"{per_seed} % | {progress} m | {percent(*bridge)} | "
            f"{percent(bridge_full, bridge[1])} | {percent(*stairs)} | {cost} |"
        )
    if {"planner100000", "planner150000"} <= pooled.keys():
        print()
        print(
            "Differences, 100 k minus 150 k (Newcombe's 95 % interval of a difference of proportions, pooled):"
        )
        print()
        for key, name in (
            ("full", "own guides fully covered"),
            ("bridge", "bridge crossed"),
            ("stairs", "stairs crossed"),
        ):
            d, low, high = newcombe_difference(pooled["planner100000"][key], pooled["planner150000"][key])
            print(f"- {name}: {100 * d:+.1f} points [{100 * low:+.1f}, {100 * high:+.1f}]")


if __name__ == "__main__":
    main()
