"""Summary of the rough-scene evaluations: success per scene and method with 95 % Wilson
intervals, coverage, navigate's replans and the reasons it stops.

    python docs/results/2026-12-06-rough-scenes/summarise.py FOLDER
reads FOLDER/eval/*/results.json and FOLDER/baselines/*/results.json, writes FOLDER/summary.json and
FOLDER/summary.md, rows sorted by scene then method.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from leas_jax.stats import wilson

ORDER = ("rblin", "rbkino_rrt", "leas", "navigate")


def scene_rows(results: dict) -> list[dict]:
    """One row per (scene, method) of a `leas evaluate` results.json."""
    rows = []
    for scene, data in results["scenarios"].items():
        by_method = {}
        for t in data["trajectories"]:
            by_method.setdefault(t["method"], []).append(t)
        for method in sorted(by_method, key=lambda m: ORDER.index(m) if m in ORDER else len(ORDER)):
            runs = by_method[method]
            wins = sum(bool(t["success"]) for t in runs)
            low, high = wilson(wins, len(runs))
            rows.append(
                {
                    "scene": scene,
                    "method": method,
                    "n": len(runs),
                    "success": wins / len(runs),
                    "success_ci": [low, high],
                    "coverage": sum(t["coverage"] for t in runs) / len(runs),
                    "replans": sum(t.get("replans") or 0 for t in runs) / len(runs),
                    "seconds": data["seconds"].get(method),
                }
            )
    return rows


def table(rows: list[dict]) -> str:
    lines = [
        "| scene | method | n | success % [95 % CI] | coverage % | replans (mean) | guide s |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        low, high = r["success_ci"]
        seconds = "" if r["seconds"] is None else f"{r['seconds']:.0f}"
        lines.append(
            f"| {r['scene']} | {r['method']} | {r['n']} | {100 * r['success']:.0f} "
            f"[{100 * low:.0f}, {100 * high:.0f}] | {100 * r['coverage']:.1f} | {r['replans']:.2f} | {seconds} |"
        )
    return "\n".join(lines) + "\n"


def main(folder: Path) -> None:
    rows = []
    for path in sorted([*folder.glob("eval/*/results.json"), *folder.glob("baselines/*/results.json")]):
        rows += scene_rows(json.loads(path.read_text()))
    rank = {m: k for k, m in enumerate(ORDER)}
    rows.sort(key=lambda r: (r["scene"], rank.get(r["method"], len(ORDER))))
    (folder / "summary.json").write_text(json.dumps(rows, indent=1) + "\n")
    (folder / "summary.md").write_text(table(rows))
    print(table(rows), end="")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
