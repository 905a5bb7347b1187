"""The shipped policy retrained with the learned condition against the cylinders' policy it replaces.

Own arena guides: the four evaluation seeds of each policy pooled (256 starts each), the share fully
covered with a 95 % Wilson interval and the difference's 95 % interval by Newcombe's method (its
score intervals combined, method 10 of Newcombe 1998). The starts are not paired: spawns near grid
points where each policy's own condition holds. Scenarios and the pillar check: LeaS success with
Wilson intervals from each policy's `leas evaluate` run. `make run`'s planner policy, trained from a
fresh clone with either condition, compared the same way over its evaluation seeds 0 and 1.

    python docs/results/2026-12-04-ship-learned/summarise.py > docs/results/2026-12-04-ship-learned/summary.md
"""

import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
sys.path.insert(0, str(REPO / "benchmarks"))
from common import newcombe_difference, wilson  # noqa: E402

EARLIER = REPO / "docs/results/2026-12-02-retry-settings"
GUIDES = {  # policy: its guide_failures.json per evaluation seed
    "learned (new)": [HERE / f"guides/planner/seed{s}/guide_failures.json" for s in range(4)],
    "cylinders (replaced)": [EARLIER / f"guides/shipped/seed{s}/guide_failures.json" for s in (0, 1)]
    + [HERE / f"guides/cylinders_shipped/seed{s}/guide_failures.json" for s in (2, 3)],
}
MAKE_RUN_GUIDES = {  # `make run`'s planner policy: its guide_failures.json per evaluation seed
    "learned (now)": [HERE / f"make_run/guides_seed{s}/guide_failures.json" for s in (0, 1)],
    "cylinders (until now)": [EARLIER / f"make_run/guides_seed{s}/guide_failures.json" for s in (0, 1)],
}
EVALUATIONS = {  # policy: (scenarios' results.json, pillar check's results.json, arena_check.json)
    "learned (new)": (HERE / "evaluate", HERE / "pillars", HERE / "arena_check"),
    "cylinders (replaced)": (
        REPO / "docs/results/2026-12-03-rbkino-hpp-sampling/evaluate_shipped",
        EARLIER / "pillars",
        EARLIER / "arena_check_shipped",
    ),
}


def pooled_guides(paths: list[Path]) -> dict:
    """Fully covered guides, starts, mean progress and episodes without an invalid pose, pooled."""
    runs = [json.loads(p.read_text()) for p in paths]
    starts = sum(r["starts"] for r in runs)
    covered = sum(round(r["full_coverage"] * r["starts"]) for r in runs)
    weighted = lambda key: sum(r[key] * r["starts"] for r in runs) / starts  # noqa: E731
    return {
        "covered": covered,
        "starts": starts,
        "per_seed": [r["full_coverage"] for r in runs],
        "progress_m": weighted("mean_progress_m"),
        "per_seed_progress_m": [r["mean_progress_m"] for r in runs],
        "valid_fraction": weighted("valid_fraction"),
    }


def leas_success(results: Path) -> dict:
    """{scenario: (successes, starts)} of the LeaS rows (all cells of eval_ground together)."""
    rows = json.loads((results / "results.json").read_text())["rows"]
    out = {}
    for row in rows:
        if row["method"] == "leas" and (row["scenario"] != "ground" or row["cell"] == "all"):
            out[row["scenario"]] = (round(row["success"] * row["n"] / 100), row["n"])
    return out


def percent(fraction: float) -> str:
    return f"{100 * fraction:.1f}"


def print_guides(groups: dict[str, list[Path]]) -> None:
    """One row per policy of its pooled own guides, then the first minus the second policy."""
    guides = {policy: pooled_guides(paths) for policy, paths in groups.items()}
    print(
        "| policy | fully covered | per evaluation seed | progress per episode | per seed | "
        "episodes without an invalid pose |"
    )
    print("|---|---|---|---|---|---|")
    for policy, g in guides.items():
        low, high = wilson(g["covered"], g["starts"])
        seeds = ", ".join(percent(f) for f in g["per_seed"])
        progress = ", ".join(f"{m:.2f}" for m in g["per_seed_progress_m"])
        print(
            f"| {policy} | {percent(g['covered'] / g['starts'])} % [{percent(low)}, {percent(high)}] "
            f"({g['covered']} of {g['starts']}) | {seeds} % | {g['progress_m']:.2f} m | {progress} m | "
            f"{percent(g['valid_fraction'])} % |"
        )
    new, old = guides.values()
    diff, low, high = newcombe_difference((new["covered"], new["starts"]), (old["covered"], old["starts"]))
    print(
        f"\nFully covered, learned - cylinders: {100 * diff:+.1f} points [{100 * low:+.1f}, {100 * high:+.1f}]"
        " (95 %, Newcombe).\n"
    )


def main() -> None:
    print("## Own arena guides of the shipped policy, 4 evaluation seeds x 256 starts\n")
    print_guides(GUIDES)
    print("## Own arena guides of `make run`'s planner policy, 2 evaluation seeds x 256 starts\n")
    print_guides(MAKE_RUN_GUIDES)

    print("## Scenarios (LeaS success), pillar check, eval_ground\n")
    table = {policy: leas_success(paths[0]) | leas_success(paths[1]) for policy, paths in EVALUATIONS.items()}
    scenarios = list(table[next(iter(table))])
    print("| scenario | " + " | ".join(EVALUATIONS) + " |")
    print("|---|" + "---|" * len(EVALUATIONS))
    for scenario in scenarios:
        cells = []
        for policy in EVALUATIONS:
            wins, n = table[policy][scenario]
            low, high = wilson(wins, n)
            cells.append(f"{percent(wins / n)} % [{percent(low)}, {percent(high)}] of {n}")
        print(f"| {scenario} | " + " | ".join(cells) + " |")
    speeds = [
        json.loads((paths[2] / "arena_check.json").read_text())["ground"]["mean_speed"]
        for paths in EVALUATIONS.values()
    ]
    print("| eval_ground speed (256 episodes) | " + " | ".join(f"{v:.3f} m/s" for v in speeds) + " |")


if __name__ == "__main__":
    main()
