"""Table of the env and training throughputs of run.sh, before and after, per round.

    python docs/results/2026-12-02-column-sampling/summarise.py docs/results/2026-12-02-column-sampling
"""

import json
import statistics
import sys
from pathlib import Path


def main(folder: Path) -> None:
    rows = {}
    for side in ("before", "after"):
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
    print("| what | preset | condition | before: steps/s (/ reference) | after: steps/s (/ reference) "
          "| after / before (mean of the rounds' ratios to the reference) |")
    print("|---|---|---|---|---|---|")
    for (what, name, condition), sides in rows.items():
        cells = [", ".join(f"{s:,.0f} ({r:.3f})" for s, r in sides[side]) for side in ("before", "after")]
        gain = statistics.mean(r for _, r in sides["after"]) / statistics.mean(r for _, r in sides["before"])
        print(f"| {what} | {name} | {condition} | {cells[0]} | {cells[1]} | x {gain:.2f} |")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
