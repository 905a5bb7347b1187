"""Plans of every scene with and without the generator's transition checks: how many starts
give a verified plan, how long planning takes, and which plans the checks change.

Plans as `studies/motion_execution.py` makes them (its `make_plans`, the same starts and
caches): the target group with 4 starts (ground: 1 per cell), the other scenes with 2.

    python docs/results/2026-12-07-motion-transitions/plans.py OUT.json

Writes OUT.json: per scenario, per setting ("unchecked": `GeneratorConfig()`, "checked":
`motion_generator_config()`), the starts, the verified plans, their postures and the planning
seconds (wall, one process); and whether each checked plan equals the unchecked one of its start.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "studies"))

import motion_execution as study  # noqa: E402

from leas_jax.contacts.plan import ContactPlan  # noqa: E402
from leas_jax.contacts.planner.config import motion_generator_config  # noqa: E402

CACHES = {"unchecked": ROOT / "runs/motion_plans", "checked": ROOT / "runs/motion_plans_checked"}


def main(out: str) -> None:
    rows = {}
    for name in study.TARGET + study.OTHERS:
        starts = 4 if name in study.TARGET else 2
        row = {}
        for setting, cache in CACHES.items():
            cache.mkdir(parents=True, exist_ok=True)
            generator = motion_generator_config() if setting == "checked" else None
            paths = study.make_plans(name, starts, 1, cache, str(ROOT / "checkpoints/leas_talos"), generator)
            marker = json.loads((cache / f"{name}.json").read_text())
            row[setting] = {
                "starts": marker["starts"],
                "plans": [p.name for p in paths],
                "postures": [len(ContactPlan.load(p).q) for p in paths],
                "planning_seconds": marker["planning_seconds"],
            }
        same = []
        for plan in row["checked"]["plans"]:
            other = CACHES["unchecked"] / plan
            if not other.is_file():
                same.append(False)
                continue
            a, b = ContactPlan.load(CACHES["checked"] / plan), ContactPlan.load(other)
            same.append(a.q.shape == b.q.shape and bool(np.array_equal(a.q, b.q)))
        row["checked"]["same_as_unchecked"] = same
        rows[name] = row
        print(
            f"{name:30s} starts {row['checked']['starts']:2d}  verified {len(row['unchecked']['plans'])} -> "
            f"{len(row['checked']['plans'])}  planning {row['unchecked']['planning_seconds']:7.1f} -> "
            f"{row['checked']['planning_seconds']:7.1f} s  unchanged {sum(same)}/{len(same)}",
            flush=True,
        )
    Path(out).write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main(sys.argv[1])
