"""Minutes per 80 M env steps of `paper` geometric training against PPO epochs, per condition,
and a least-squares line through them: the intercept is what 80 M steps cost without any PPO
epoch (env steps, rollout, advantages), the slope what each epoch over the batch adds.

    python docs/results/2026-12-05-paper-training-cost/summarise.py > docs/results/2026-12-05-paper-training-cost/summary.md
"""

import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def main() -> None:
    rows = json.loads((HERE / "train_throughput.json").read_text())["rows"]
    print(
        "| condition | epochs: minutes per 80 M steps | without epochs (intercept) | per epoch (slope) | share of the 10-epoch run in epochs |"
    )
    print("|---|---|---|---|---|")
    for condition in sorted({r["condition"] for r in rows}):
        mine = sorted((r for r in rows if r["condition"] == condition), key=lambda r: r["num_epochs"])
        epochs = np.array([r["num_epochs"] for r in mine], float)
        minutes = np.array([r["minutes_for_80M_steps"] for r in mine], float)
        slope, intercept = np.polyfit(epochs, minutes, 1)
        at = ", ".join(f"{int(e)}: {m:.1f}" for e, m in zip(epochs, minutes))
        ten = intercept + 10 * slope
        print(
            f"| {condition} | {at} | {intercept:.1f} min | {slope:.2f} min | {100 * 10 * slope / ten:.0f} % |"
        )


if __name__ == "__main__":
    main()
