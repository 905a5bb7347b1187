"""The learned condition relabelled on the current generator: its validation against the weights
the shipped policy was trained with, and `make run` trained with it against `make run` before.

Validation (`feasibility/feasibility_condition.json`): sensitivity and specificity with 95 %
Wilson intervals of each condition on the same fresh and policy poses. `make run`'s planner-phase
policy: its own arena guides over evaluation seeds 0-3 (256 starts each) pooled, against `make
run`'s policy trained with the weights before (`../2026-12-05-swing-lift-on-rise/make_run`, the
same generator and commands); the difference's 95 % interval by Newcombe's method. The starts
are not paired: each policy spawns where its own condition holds.

    python docs/results/2026-12-05-relabelled-condition/summarise.py > docs/results/2026-12-05-relabelled-condition/summary.md
"""

import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
sys.path.insert(0, str(REPO / "benchmarks"))
from common import newcombe_difference, wilson  # noqa: E402

BEFORE = REPO / "docs/results/2026-12-05-swing-lift-on-rise/make_run"
MAKE_RUNS = {"relabelled condition": HERE / "make_run", "condition before": BEFORE}
SEEDS = (0, 1, 2, 3)


def interval(successes: int, trials: int) -> str:
    low, high = wilson(successes, trials)
    return f"{100 * successes / trials:.1f} % [{100 * low:.1f}, {100 * high:.1f}]"


def validation_rows(report: dict) -> list[str]:
    rows = []
    for pose_set, conditions in report["validation"].items():
        for name, c in conditions.items():
            feasible, infeasible = c["tp"] + c["fn"], c["tn"] + c["fp"]
            rows.append(
                f"| {pose_set} | {name} | {interval(c['tp'], feasible)} | {interval(c['tn'], infeasible)} "
                f"| {feasible} / {infeasible} |"
            )
    return rows


def pooled_guides(folder: Path) -> dict:
    """Fully covered guides, starts, per-seed shares and mean progress over SEEDS."""
    runs = [json.loads((folder / f"guides_seed{s}/guide_failures.json").read_text()) for s in SEEDS]
    starts = sum(r["starts"] for r in runs)
    return {
        "covered": sum(r["starts"] - len(r["failures"]) for r in runs),
        "starts": starts,
        "per_seed": [1 - len(r["failures"]) / r["starts"] for r in runs],
        "progress_m": sum(r["mean_progress_m"] * r["starts"] for r in runs) / starts,
    }


def main() -> None:
    report = json.loads((HERE / "feasibility/feasibility_condition.json").read_text())
    print("## Validation against the generator's walking truth\n")
    print(f"Training data: {report['data']['train']}.\n")
    print("| pose set | condition | sensitivity [95 % CI] | specificity [95 % CI] | feasible / infeasible |")
    print("|---|---|---|---|---|")
    print("\n".join(validation_rows(report)))
    cost = report.get("env_step_cost")
    if cost:
        print(
            f"\nCost per env step, same run: cylinders {cost['cylinders']['us_per_env_step']} us, "
            f"learned {cost['learned']['us_per_env_step']} us (x {cost['cost_ratio_learned_over_cylinders']})."
        )
    print("\n## `make run`'s planner-phase policy, own arena guides, 4 evaluation seeds x 256 starts\n")
    print("| trained with | fully covered | per evaluation seed | progress per episode | eval_ground speed |")
    print("|---|---|---|---|---|")
    guides = {}
    for name, folder in MAKE_RUNS.items():
        g = guides[name] = pooled_guides(folder)
        speed = json.loads((folder / "eval.json").read_text())["geometric"]["ground_mean_speed"]
        seeds = ", ".join(f"{100 * s:.1f}" for s in g["per_seed"])
        print(
            f"| {name} | {interval(g['covered'], g['starts'])} ({g['covered']} of {g['starts']}) | {seeds} % "
            f"| {g['progress_m']:.2f} m | {speed:.3f} m/s |"
        )
    new, old = (guides[name] for name in MAKE_RUNS)
    diff, low, high = newcombe_difference((new["covered"], new["starts"]), (old["covered"], old["starts"]))
    print(
        f"\nFully covered, relabelled - before: {100 * diff:+.1f} points [{100 * low:+.1f}, {100 * high:+.1f}]"
        " (95 %, Newcombe)."
    )


if __name__ == "__main__":
    main()
