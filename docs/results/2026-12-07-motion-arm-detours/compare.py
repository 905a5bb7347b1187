"""Executions of the same plans before and after this folder's changes, by group and by plan.

    python docs/results/2026-12-07-motion-arm-detours/compare.py \\
        docs/results/2026-12-07-motion-transitions/motion_execution_checked.json \\
        docs/results/2026-12-07-motion-arm-detours/motion_execution_checked.json

Prints a markdown table of executed / verified plans per group (95 % Wilson intervals), the
plans whose verdict changed, each failure now with its cause and message, and the starts
that changed with a two-sided sign test over them.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))

from leas_jax.stats import wilson  # noqa: E402

GROUPS = {
    "target group (Table II ground, eval_stairs, eval_bridge, talos_stairs10, talos_navBauzil)": lambda n: (
        n in ("ground", "stairs", "bridge", "hpp_talos_stairs10", "hpp_talos_navBauzil")
    ),
    "evaluation scenarios": lambda n: not n.startswith("hpp_"),
    "HPP Talos demo queries": lambda n: n.startswith("hpp_talos_"),
    "HPP stairs, bridges, rough scenes and rubble": lambda n: (
        n.startswith("hpp_") and not n.startswith("hpp_talos_")
    ),
    "every scene": lambda n: True,
}


def verdicts(path: str) -> dict:
    """{(scenario, plan file): (success, cause, message)} of a motion_execution JSON."""
    report = json.loads(Path(path).read_text())
    out = {}
    for name, scenario in report["scenarios"].items():
        for e in scenario["executions"]:
            out[(name, e["plan"])] = (
                bool(e["success"]),
                e.get("cause"),
                e.get("error") or e.get("message") or "",
            )
    return out


def rate(ok: int, n: int) -> str:
    if not n:
        return "-"
    low, high = wilson(ok, n)
    return f"{ok} / {n} ({100 * ok / n:.0f} % [{100 * low:.0f}, {100 * high:.0f}])"


def main(before_path: str, after_path: str) -> None:
    before, after = verdicts(before_path), verdicts(after_path)
    print("| | before | after |\n|---|---|---|")
    for label, member in GROUPS.items():
        cells = []
        for runs in (before, after):
            keys = [k for k in runs if member(k[0])]
            cells.append(rate(sum(runs[k][0] for k in keys), len(keys)))
        print(f"| {label} | {cells[0]} | {cells[1]} |")
    both = sorted(set(before) & set(after))
    gained = [k for k in both if after[k][0] and not before[k][0]]
    lost = [k for k in both if before[k][0] and not after[k][0]]
    only = sorted(set(before) ^ set(after))
    print(f"\nplans in both: {len(both)}; gained {len(gained)}: {[k[1] for k in gained]}")
    print(f"lost {len(lost)}: {[k[1] for k in lost]}")
    if only:
        print(f"plans in one run only: {[k[1] for k in only]}")
    changed = len(gained) + len(lost)
    if changed:
        tail = sum(math.comb(changed, i) for i in range(min(len(gained), len(lost)) + 1)) / 2**changed
        print(f"sign test over the {changed} changed plans: p = {min(1.0, 2 * tail):.3g} (two-sided)")
    print("\nfailures after:")
    for key in sorted(k for k in after if not after[k][0]):
        _, cause, message = after[key]
        print(f"- {key[1]}: {cause}: {message[:300]}")


if __name__ == "__main__":
    main(*sys.argv[1:3])
