"""Summary of this folder's evaluations: success with 95 % Wilson intervals, replans, time.

python docs/results/2026-12-01-navigate/summarize.py > docs/results/2026-12-01-navigate/summary.md
"""

import json
import math
from pathlib import Path

HERE = Path(__file__).resolve().parent


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return 100 * (centre - half), 100 * (centre + half)


def rows():
    for folder in sorted(HERE.glob("*/results.json")):
        report = json.loads(folder.read_text())
        for name, scenario in report["scenarios"].items():
            for method in scenario["methods"]:
                ts = [t for t in scenario["trajectories"] if t["method"] == method]
                k, n = sum(t["success"] for t in ts), len(ts)
                lo, hi = (max(0.0, v) for v in wilson(k, n))
                replans = [t["replans"] for t in ts if "replans" in t]
                seconds = scenario["seconds"]
                # the RRT's search time is its own entry, shared by rbkino_rrt and leas_rrt
                per = (
                    seconds.get("rrt_search", 0.0) if method == "rbkino_rrt" else seconds.get(method, 0.0)
                ) / n
                yield (
                    f"| {folder.parent.name} | {name} | {method} | {k} / {n} | {100 * k / n:.1f} % "
                    f"[{lo:.1f}, {hi:.1f}] | "
                    + (f"{sum(r > 0 for r in replans)} / {sum(replans)} / {max(replans)}" if replans else "")
                    + f" | {per:.1f} |"
                )


print(
    "| folder | scenario | method | success | % [Wilson 95 %] | starts replanned / replans / max | s per start |"
)
print("|---|---|---|---|---|---|---|")
for line in rows():
    print(line)
