"""Pools this folder's per-policy `studies/generalist.py` outputs (one sub-folder per policy) with
the paper-arena policy and the committed preset's three seeds (`../2026-12-07-curriculum-tiles`)
into recipes.md (the seeds of each recipe pooled, as that folder's merge does), and the pillar
fields of both folders into pillar_fields.md (the same 20 fields and 200 seeded starts).

    python docs/results/2026-12-08-curriculum-clutter/merge.py
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
EARLIER = HERE.parent / "2026-12-07-curriculum-tiles"
sys.path.insert(0, str(HERE.parents[2] / "studies"))
import generalist  # noqa: E402
import numpy as np  # noqa: E402
import pillar_fields  # noqa: E402

spec = importlib.util.spec_from_file_location("earlier_merge", EARLIER / "merge.py")
earlier_merge = importlib.util.module_from_spec(spec)
spec.loader.exec_module(earlier_merge)

RECIPES = {
    "paper-arena policy (shipped pretrain)": ["paper_arena"],
    "ceilings (the preset)": ["ceilings_s0", "ceilings_s1", "ceilings_s2"],
    "ceilings, beams column (narrow's)": ["beams_s0"],
    "three clutter columns": ["clutter3_s0", "clutter3_s1", "clutter3_s2"],
    "three clutter columns, two beams columns": [
        "clutter3_beams2_s0",
        "clutter3_beams2_s1",
        "clutter3_beams2_s2",
    ],
}


def merged_results() -> dict:
    """The earlier folder's policies (its merge) and this folder's, in one results dict."""
    merged = earlier_merge.merged_results()
    for key, value in earlier_merge.merged_results(HERE).items():
        merged[key].update(value)
    return merged


def merged_pillar_fields() -> dict:
    """Both folders' pillar-field results, the earlier ones first."""
    earlier = json.loads((EARLIER / "pillar_fields" / "pillar_fields.json").read_text())
    ours = json.loads((HERE / "pillar_fields" / "pillar_fields.json").read_text())
    return {
        "policies": {**earlier["policies"], **ours["policies"]},
        "results": {**earlier["results"], **ours["results"]},
    }


def pillar_recipes_markdown(results: dict, reference: str = "ceilings (the preset)") -> str:
    """Pillar fields per recipe: successes pooled over seeds and starts (Wilson 95 %), each seed's
    rate, and Welch's t-test of the seeds' rates against `reference`'s (the seed is the unit a
    recipe is replicated over; pooling the starts ignores how much seeds differ)."""
    from scipy.stats import ttest_ind

    def rates(labels):
        rows = [results["results"][label] for label in labels if label in results["results"]]
        return [
            100 * sum(r["success"] for r in row.values()) / sum(r["n"] for r in row.values()) for row in rows
        ], [(sum(r["success"] for r in row.values()), sum(r["n"] for r in row.values())) for row in rows]

    base, _ = rates(RECIPES[reference])
    lines = [
        "| recipe | seeds | pooled success % [95 % CI] | per seed % | seed mean - reference's (Welch p) |",
        "|---|---|---|---|---|",
    ]
    for name, labels in RECIPES.items():
        seed_rates, counts = rates(labels)
        if not seed_rates:
            continue
        k, n = sum(c[0] for c in counts), sum(c[1] for c in counts)
        test = "-"
        if name != reference and len(seed_rates) > 1:
            p = ttest_ind(seed_rates, base, equal_var=False).pvalue
            test = f"{np.mean(seed_rates) - np.mean(base):+.1f} points (p {p:.2f})"
        per_seed = " / ".join(f"{r:.1f}" for r in seed_rates)
        lines.append(
            f"| {name} | {len(seed_rates)} | {generalist.percent_with_interval(k, n)} | {per_seed} | {test} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    text = earlier_merge.recipes_markdown(merged_results(), RECIPES)
    (HERE / "recipes.md").write_text(text)
    fields = (
        pillar_recipes_markdown(merged_pillar_fields())
        + "\n"
        + pillar_fields.markdown(merged_pillar_fields())
    )
    (HERE / "pillar_fields.md").write_text(fields)
    print(text + "\n" + fields)


if __name__ == "__main__":
    main()
