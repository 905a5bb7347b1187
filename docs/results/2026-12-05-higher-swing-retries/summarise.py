"""The shipped policy's own arena guides before and after the two retries, paired by start.

Each evaluation seed's 256 episodes are the same before and after (the same weights, starts and
seed): a guide is fixed when it was not fully covered before and is now, broken the other way;
the two-sided sign test on those counts (`guide_failures.sign_test`). The share fully covered
gets a 95 % Wilson interval; seeds 0 and 1 chose the retries, 2 and 3 are held out.

    python docs/results/2026-12-05-higher-swing-retries/summarise.py > docs/results/2026-12-05-higher-swing-retries/summary.md
"""

import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
sys.path[:0] = [str(REPO / "studies"), str(REPO / "benchmarks")]
from common import wilson  # noqa: E402
from guide_failures import sign_test  # noqa: E402

BEFORE = REPO / "docs/results/2026-12-04-ship-learned/guides/planner"
SEEDS = {0: "chose the retries", 1: "chose the retries", 2: "held out", 3: "held out"}


def report(path: Path) -> dict:
    return json.loads((path / "guide_failures.json").read_text())


def covered(run: dict) -> int:
    return run["starts"] - len(run["failures"])


def row(label: str, before: int, after: int, starts: int, fixed: int, broken: int) -> str:
    low, high = wilson(after, starts)
    return (
        f"| {label} | {100 * before / starts:.1f} % | {100 * after / starts:.1f} % [{100 * low:.1f}, "
        f"{100 * high:.1f}] ({after} of {starts}) | {fixed} / {broken} (p = {sign_test(fixed, broken):.1g}) |"
    )


def main() -> None:
    print("| evaluation seed | before | after | fixed / broken (sign test) |")
    print("|---|---|---|---|")
    totals = {"chose the retries": [0, 0, 0, 0, 0], "held out": [0, 0, 0, 0, 0]}
    for seed, role in SEEDS.items():
        before, after = report(BEFORE / f"seed{seed}"), report(HERE / f"guides/seed{seed}")
        failed_before = {f["start"] for f in before["failures"]}
        failed_after = {f["start"] for f in after["failures"]}
        fixed, broken = len(failed_before - failed_after), len(failed_after - failed_before)
        counts = (covered(before), covered(after), after["starts"], fixed, broken)
        print(row(f"{seed} ({role})", *counts))
        totals[role] = [t + c for t, c in zip(totals[role], counts)]
    for role, counts in totals.items():
        print(row(f"seeds {role}", *counts))
    every = [sum(c) for c in zip(*totals.values())]
    print(row("all four seeds", *every))


if __name__ == "__main__":
    main()
