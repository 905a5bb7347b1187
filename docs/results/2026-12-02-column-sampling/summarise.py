"""Tables of run.sh's env and training throughputs: before against after, round by round, and
the learned condition against the cylinders on each side.

    python docs/results/2026-12-02-column-sampling/summarise.py docs/results/2026-12-02-column-sampling

Before and after ran one after the other in each round, so their steps/s are compared round
by round (after / before); the ratio to the bare reference env, timed inside each benchmark,
is shown too. The env benchmark alternates the reference and the env within its repeats, so
its ratio is the steadier figure there; the training benchmark times the reference only
before and after its calls, and there the round-by-round steps/s are.
"""

import json
import statistics
import sys
from pathlib import Path

SIDES = ("before", "after")


def figures(folder: Path) -> dict:
    """{(what, preset, condition): {side: [(steps/s, ratio to the reference) per round]}}."""
    rows = {}
    for side in SIDES:
        for round_dir in sorted((folder / side).glob("round*")):
            for condition in ("cylinders", "learned"):
                env = json.loads((round_dir / f"env_{condition}" / "env_throughput.json").read_text())
                program = env["rows"][0]["programs"]["wrapper"]
                rows.setdefault(("env step", "paper", condition), {}).setdefault(side, []).append(
                    (program["steps_per_s_median"], program["ratio_to_reference"])
                )
            train = json.loads((round_dir / "train_throughput.json").read_text())
            for r in train["rows"]:
                rows.setdefault(("training", r["preset"], r["condition"]), {}).setdefault(side, []).append(
                    (r["env_steps_per_s"], r["ratio_to_reference"])
                )
    return rows


def main(folder: Path) -> None:
    rows = figures(folder)
    print(
        "| what | preset | condition | before: steps/s (/ reference) per round | after: the same "
        "| after / before per round (steps/s) | the same (ratios to the reference) |"
    )
    print("|---|---|---|---|---|---|---|")
    for (what, name, condition), sides in rows.items():
        cells = [", ".join(f"{s:,.0f} ({r:.3f})" for s, r in sides[side]) for side in SIDES]
        pairs = list(zip(sides["after"], sides["before"], strict=True))
        gains = [a / b for (a, _), (b, _) in pairs]
        relative = [a / b for (_, a), (_, b) in pairs]
        print(
            f"| {what} | {name} | {condition} | {cells[0]} | {cells[1]} | "
            f"{', '.join(f'x {g:.2f}' for g in gains)} (mean x {statistics.mean(gains):.2f}) | "
            f"{', '.join(f'x {g:.2f}' for g in relative)} (mean x {statistics.mean(relative):.2f}) |"
        )
    print()
    print("| what | preset | side | learned / cylinders time per env step, per round |")
    print("|---|---|---|---|")
    for what, name in sorted({(w, p) for w, p, _ in rows}):
        for side in SIDES:
            cyl, learned = rows[(what, name, "cylinders")][side], rows[(what, name, "learned")][side]
            costs = [c / n for (c, _), (n, _) in zip(cyl, learned, strict=True)]
            print(f"| {what} | {name} | {side} | {', '.join(f'x {c:.2f}' for c in costs)} |")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
