"""Summary of run.sh: success with 95 % Wilson intervals, coverage, replans and wall time of
every `leas evaluate` run under RUNS (its results.json files), one row per run and scene.

    python docs/results/2026-12-06-navigate-path-fallback/summarise.py [RUNS]   # default /tmp/path_fallback
writes summary.md beside this script.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "2026-12-06-rough-scenes"))
from summarise import scene_rows  # noqa: E402

from leas_jax.stats import wilson  # noqa: E402


def main(runs: Path) -> str:
    lines = [
        "| run | scene | n | success % [95 % CI] | coverage % | replans (mean) | navigate s |",
        "|---|---|---|---|---|---|---|",
    ]
    pooled = {}
    for path in sorted(runs.rglob("results.json")):
        run = str(path.parent.relative_to(runs))
        for r in scene_rows(json.loads(path.read_text())):
            low, high = r["success_ci"]
            seconds = "" if r["seconds"] is None else f"{r['seconds']:.0f}"
            lines.append(
                f"| {run} | {r['scene']} | {r['n']} | {100 * r['success']:.0f} [{100 * low:.0f}, {100 * high:.0f}] "
                f"| {100 * r['coverage']:.1f} | {r['replans']:.2f} | {seconds} |"
            )
            if run.startswith("bridge/"):
                wins, n = pooled.get(path.parent.name, (0, 0))
                pooled[path.parent.name] = (wins + round(r["success"] * r["n"]), n + r["n"])
    for mode, (wins, n) in sorted(pooled.items()):
        low, high = wilson(wins, n)
        lines.append(
            f"| bridge, 3 seeds pooled, {mode} | eval_bridge | {n} | {100 * wins / n:.0f} "
            f"[{100 * low:.0f}, {100 * high:.0f}] | | | |"
        )
    text = "\n".join(lines) + "\n"
    (HERE / "summary.md").write_text(text)
    return text


if __name__ == "__main__":
    print(main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("/tmp/path_fallback")))
