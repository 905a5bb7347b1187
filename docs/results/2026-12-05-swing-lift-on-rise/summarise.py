"""The shipped policy's own arena guides under three generators, paired by start.

Each evaluation seed's 256 episodes are the same in the three reports (the same weights, starts
and seed); only the generator's retries differ: the 6 retries before (`BEFORE`), those plus a
0.15 m swing lift everywhere and a 1.1 s lookahead (`EVERYWHERE`, not landed), and those with
the 0.15 m lift only over a rise (`swing_lift_on_rise`, this folder; the default). A guide is
fixed when it was not fully covered before and is now, broken the other way; the two-sided sign
test on those counts (`guide_failures.sign_test`). The share fully covered gets a 95 % Wilson
interval. Evaluation seeds 0 and 1 chose the retries (../2026-12-05-higher-swing-retries), 2
and 3 are held out.

    python docs/results/2026-12-05-swing-lift-on-rise/summarise.py > docs/results/2026-12-05-swing-lift-on-rise/summary.md
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
EVERYWHERE = REPO / "docs/results/2026-12-05-higher-swing-retries/guides"
SEEDS = {0: "chose the retries", 1: "chose the retries", 2: "held out", 3: "held out"}


def failed(folder: Path) -> tuple[set, int, dict]:
    """(failed starts, starts, report) of folder/guide_failures.json."""
    report = json.loads((folder / "guide_failures.json").read_text())
    return {f["start"] for f in report["failures"]}, report["starts"], report


def share(failures: set, starts: int) -> str:
    covered = starts - len(failures)
    low, high = wilson(covered, starts)
    return f"{100 * covered / starts:.1f} % [{100 * low:.1f}, {100 * high:.1f}] ({covered} of {starts})"


def row(label: str, before: set, everywhere: set, after: set, starts: int) -> str:
    fixed, broken = len(before - after), len(after - before)
    return (
        f"| {label} | {share(before, starts)} | {share(everywhere, starts)} | {share(after, starts)} "
        f"| {fixed} / {broken} (p = {sign_test(fixed, broken):.1g}) | {len(after ^ everywhere)} |"
    )


def main() -> None:
    print(
        "| evaluation seed | 6 retries before | + lift everywhere | + lift over a rise (default) "
        "| fixed / broken vs before (sign test) | guides judged unlike lift everywhere |"
    )
    print("|---|---|---|---|---|---|")
    groups = {role: [set(), set(), set(), 0] for role in set(SEEDS.values())}
    every = [set(), set(), set(), 0]
    progress = []
    for seed, role in SEEDS.items():
        before, starts, _ = failed(BEFORE / f"seed{seed}")
        everywhere, _, _ = failed(EVERYWHERE / f"seed{seed}")
        after, _, report = failed(HERE / f"guides/seed{seed}")
        progress.append(report["mean_progress_m"])
        print(row(f"{seed} ({role})", before, everywhere, after, starts))
        # Starts are renumbered per seed so the sets of different seeds do not merge.
        for total in (groups[role], every):
            for k, starts_failed in enumerate((before, everywhere, after)):
                total[k] |= {(seed, s) for s in starts_failed}
            total[3] += starts
    for role in ("chose the retries", "held out"):
        print(row(f"seeds {role}", *groups[role]))
    print(row("all four seeds", *every))
    print()
    print(f"Mean progress along the target direction per seed: {', '.join(f'{p:.2f}' for p in progress)} m.")
    make_run = [failed(HERE / f"make_run/guides_seed{seed}") for seed in SEEDS]
    starts = sum(n for _, n, _ in make_run)
    failures = {(seed, s) for seed, (f, _, _) in zip(SEEDS, make_run) for s in f}
    progress = sum(r["mean_progress_m"] * n for _, n, r in make_run) / starts
    print()
    print(
        f"`make run`'s planner-phase policy, its own arena guides over evaluation seeds 0-3: "
        f"{share(failures, starts)} fully covered, mean progress {progress:.2f} m."
    )


if __name__ == "__main__":
    main()
