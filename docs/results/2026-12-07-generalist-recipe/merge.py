"""Merges the per-policy `studies/generalist.py` outputs (one --out folder per policy, run side
by side) and the earlier study's two policies into this folder's generalist.json, and renders
generalist.md and generalist.png with the study's own functions.

    python docs/results/2026-12-07-generalist-recipe/merge.py FOLDER [FOLDER ...]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "studies"))
import generalist  # noqa: E402

EARLIER = HERE.parent / "2026-12-06-generalist" / "generalist.json"


def main() -> None:
    merged = {"policies": {}, "arenas": {}, "scenarios": {}, "machine": {}}
    for path in [EARLIER] + [Path(f) / "generalist.json" for f in sys.argv[1:]]:
        results = json.loads(path.read_text())
        for key in ("policies", "arenas", "scenarios"):
            merged[key].update(results.get(key, {}))
        merged["machine"][str(path.parent.name)] = results.get("machine")
    (HERE / "generalist.json").write_text(json.dumps(merged, indent=1))
    (HERE / "generalist.md").write_text(generalist.markdown(merged))
    generalist.plot(merged, HERE / "generalist.png")
    print(generalist.markdown(merged))


if __name__ == "__main__":
    main()
