"""Training throughput before and after, two alternated rounds: minutes per 80 M env steps, the
learned condition's cost against the cylinders' in the same run, and after over before.

    python docs/results/2026-12-05-condition-ground-gather/summarise.py > docs/results/2026-12-05-condition-ground-gather/summary.md
"""

import json
from pathlib import Path

HERE = Path(__file__).resolve().parent
RUNS = ("before1", "after1", "before2", "after2")


def minutes(run: str) -> dict:
    """(preset, condition) -> minutes per 80 M env steps of one run."""
    rows = json.loads((HERE / run / "train_throughput.json").read_text())["rows"]
    return {(r["preset"], r["condition"]): r["minutes_for_80M_steps"] for r in rows}


def main() -> None:
    table = {run: minutes(run) for run in RUNS}
    machine = json.loads((HERE / "before1" / "train_throughput.json").read_text())["machine"]
    print(
        f"Machine: {machine['cpu']}, family {machine['cpu_family']} model {machine['cpu_model']}, {machine['vector_isa']}, {machine['cores']} cores\n"
    )
    print("| preset | condition | " + " | ".join(RUNS) + " | after / before |")
    print("|---|---|" + "---|" * (len(RUNS) + 1))
    for key in table["before1"]:
        before = sum(table[r][key] for r in RUNS if r.startswith("before")) / 2
        after = sum(table[r][key] for r in RUNS if r.startswith("after")) / 2
        cells = " | ".join(f"{table[r][key]:.1f} min" for r in RUNS)
        print(f"| {key[0]} | {key[1]} | {cells} | {after / before:.2f} |")
    print("\nThe learned condition's cost over the cylinders' (same run, same preset):\n")
    print("| preset | " + " | ".join(RUNS) + " |")
    print("|---|" + "---|" * len(RUNS))
    for preset in sorted({p for p, _ in table["before1"]}):
        cells = " | ".join(
            f"x {table[r][(preset, 'learned')] / table[r][(preset, 'cylinders')]:.2f}" for r in RUNS
        )
        print(f"| {preset} | {cells} |")


if __name__ == "__main__":
    main()
