"""Merges the per-policy `studies/generalist.py` outputs of this folder (one sub-folder per
policy) with the paper-arena policy's row of `../2026-12-06-generalist`, renders generalist.md and
generalist.png with the study's own functions, and pools the seeds of each recipe into
recipes.md: own guides fully covered over every seed's guides (Wilson 95 %), progress per seed,
and scenario successes over every seed's starts.

    python docs/results/2026-12-07-curriculum-tiles/merge.py
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "studies"))
import generalist  # noqa: E402

EARLIER = HERE.parent / "2026-12-06-generalist" / "generalist.json"
RECIPES = {
    "paper-arena policy (shipped pretrain)": ["paper_arena"],
    "whole ranges, the paper's reward": ["generalist_t7_s0"],
    "whole ranges, direction weight 4": ["direction_x4_s0"],
    "ceilings (the preset)": ["ceilings_s0", "ceilings_s1", "ceilings_s2"],
    "ceilings, beams column": ["beams_s0"],
}


def pooled(merged: dict, labels: list[str]) -> dict:
    """Per arena: (covered, guides, [progress per seed]); per scenario: (success, n)."""
    arenas, scenarios = {}, {}
    for label in labels:
        for arena, seeds in merged["arenas"].get(label, {}).items():
            covered, guides, progress = arenas.setdefault(arena, [0, 0, []])
            rows = list(seeds.values())
            arenas[arena] = [
                covered + sum(r["fully_covered"] for r in rows),
                guides + sum(r["guides"] for r in rows),
                progress + [sum(r["mean_progress_m"] for r in rows) / len(rows)],
            ]
        for scenario, row in merged["scenarios"].get(label, {}).items():
            success, n = scenarios.setdefault(scenario, [0, 0])
            scenarios[scenario] = [success + row["success"], n + row["n"]]
    return {"arenas": arenas, "scenarios": scenarios}


def recipes_markdown(merged: dict, recipes: dict = RECIPES) -> str:
    """recipes.md: `recipes` ({name: [policy labels]}) with their seeds pooled."""
    present = {
        name: [label for label in labels if label in merged["policies"]] for name, labels in recipes.items()
    }
    present = {name: labels for name, labels in present.items() if labels}
    tables = {name: pooled(merged, labels) for name, labels in present.items()}
    names = list(tables)
    lines = [
        "# Recipes, seeds pooled",
        "",
        "Arenas: own guides fully covered % [95 % CI] over every seed's guides; progress (m) per "
        "400-step episode, one figure per seed.",
        "",
        "| arena | "
        + " | ".join(f"{n} ({len(present[n])} seed{'s' * (len(present[n]) > 1)})" for n in names)
        + " |",
        "|---|" + "---|" * len(names),
    ]
    arenas = list(dict.fromkeys(a for t in tables.values() for a in t["arenas"]))
    for arena in arenas:
        cells = []
        for name in names:
            if arena not in tables[name]["arenas"]:
                cells.append("-")
                continue
            covered, guides, progress = tables[name]["arenas"][arena]
            seeds = " / ".join(f"{p:.2f}" for p in progress)
            cells.append(f"{generalist.percent_with_interval(covered, guides)}, {seeds} m")
        lines.append(f"| {arena} | " + " | ".join(cells) + " |")
    lines += ["", "Scenarios: LeaS success % [95 % CI] over every seed's starts.", ""]
    lines.append("| scenario | " + " | ".join(names) + " |")
    lines.append("|---|" + "---|" * len(names))
    scenarios = list(dict.fromkeys(s for t in tables.values() for s in t["scenarios"]))
    for scenario in scenarios:
        cells = []
        for name in names:
            if scenario not in tables[name]["scenarios"]:
                cells.append("-")
                continue
            success, n = tables[name]["scenarios"][scenario]
            cells.append(f"{success} / {n}, {generalist.percent_with_interval(success, n)}")
        lines.append(f"| {Path(scenario).stem} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def merged_results(folder: Path = HERE) -> dict:
    """The paper-arena policy's row of `../2026-12-06-generalist` and every
    `<folder>/*/generalist.json`, merged into one `studies/generalist.py` results dict."""
    earlier = json.loads(EARLIER.read_text())
    merged = {
        "policies": {},
        "arenas": {},
        "scenarios": {},
        "machine": {"paper_arena": earlier.get("machine")},
    }
    for key in ("policies", "arenas", "scenarios"):
        merged[key]["paper_arena"] = earlier[key]["paper_arena"]
    for path in sorted(folder.glob("*/generalist.json")):
        results = json.loads(path.read_text())
        for key in ("policies", "arenas", "scenarios"):
            merged[key].update(results.get(key, {}))
        merged["machine"][path.parent.name] = results.get("machine")
    return merged


def main() -> None:
    merged = merged_results()
    (HERE / "generalist.json").write_text(json.dumps(merged, indent=1) + "\n")
    (HERE / "generalist.md").write_text(generalist.markdown(merged))
    generalist.plot(merged, HERE / "generalist.png")
    (HERE / "recipes.md").write_text(recipes_markdown(merged))
    print(recipes_markdown(merged))


if __name__ == "__main__":
    main()
