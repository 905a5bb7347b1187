"""Does LeaS alone walk round pillars standing in its way, on fields it never saw?

`terrains/checks/pillars_in_the_way.toml` is one field: four 0.30 m pillars on and beside the
straight line from the start to a target 6.5 m ahead. This study draws a family like it from
seeds: flat 12 x 8 m ground, the same start region and target, 3 to 6 square pillars 0.25-0.40
m wide and 1.5 m high at random turns, between 1 and 5.5 m ahead of the start region, the first
on the start-target line and at least two within 0.25 m of it, every two at least 1.0 m apart
face to face (Talos passes the check's 1.1 m gate; `pillar_boxes`). Each policy runs `leas
evaluate --methods leas` on each field (`--starts` seeded starts, yaw +-30 deg): success is
the contact plan covering the whole guide and ending within 0.30 m of the target.

    python studies/pillar_fields.py --policy shipped=checkpoints/leas_talos \\
        --policy generalist=checkpoints/leas_generalist --fields 20 --starts 10 --out DIR

writes `pillar_fields.json` (resumable: a finished (policy, field) is read back), `.md` and
`pillar_fields.png` (the fields seen from above) into `--out`, and the fields' TOML files into
`<out>/fields/`.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from generalist import machine, percent_with_interval, scenario_row  # noqa: E402 (the curriculum study's)

BOUNDS = ((0.0, 0.0), (12.0, 8.0))
START = (4.0, 4.0)
TARGET = (10.5, 4.0)
PILLAR_COUNT = (3, 6)
PILLAR_SIDE = (0.25, 0.40)  # m
PILLAR_HEIGHT = 1.5  # m
PILLAR_X = (5.0, 9.5)  # m, 1 to 5.5 m ahead of the start region's centre
PILLAR_Y = (2.6, 5.4)  # m, up to 1.4 m beside the line
FIRST_X = (5.0, 6.0)  # m, the pillar on the line
FIRST_Y = 0.1  # m, |y - 4| of the pillar on the line, at most
ON_LINE = 0.25  # m, |y - 4| of a pillar standing in the way
IN_THE_WAY = 2  # pillars within ON_LINE of the line, at least
MIN_GAP = 1.0  # m, between two pillars' circumscribed circles
SQUARE = ((-1, -1), (1, -1), (1, 1), (-1, 1))  # a pillar's corners in half-sides, its own frame


def pillar_boxes(seed: int):
    """The pillars of field `seed`: [(x, y, side, yaw)] (m, rad)."""
    rng = np.random.default_rng(seed)
    while True:
        count = int(rng.integers(PILLAR_COUNT[0], PILLAR_COUNT[1] + 1))
        line = START[1]
        pillars = [(rng.uniform(*FIRST_X), line + rng.uniform(-FIRST_Y, FIRST_Y), rng.uniform(*PILLAR_SIDE))]
        for _ in range(200 * count):
            if len(pillars) == count:
                break
            x, y, side = rng.uniform(*PILLAR_X), rng.uniform(*PILLAR_Y), rng.uniform(*PILLAR_SIDE)
            if all(
                math.hypot(x - px, y - py) - (side + ps) / math.sqrt(2) >= MIN_GAP for px, py, ps in pillars
            ):
                pillars.append((x, y, side))
        if len(pillars) == count and sum(abs(y - line) < ON_LINE for _, y, _ in pillars) >= IN_THE_WAY:
            return [(x, y, side, float(rng.uniform(0.0, math.pi / 2))) for x, y, side in pillars]


def pillar_field(seed: int, starts: int) -> str:
    """TOML text of field `seed` with its [scenario] (`starts` starts drawn from `seed`)."""
    from leas_jax.terrain.generate import BoxSpec, slab, terrain_toml

    pillars = [
        BoxSpec((x, y, PILLAR_HEIGHT / 2), (side, side, PILLAR_HEIGHT), (0.0, 0.0, round(yaw, 4)))
        for x, y, side, yaw in pillar_boxes(seed)
    ]
    scenario = {
        "target": list(TARGET),
        "start_region": [[START[0] - 0.1, START[1] - 0.1], [START[0] + 0.1, START[1] + 0.1]],
        "start_yaw_deg": [-30.0, 30.0],
        "start_speed": [0.01, 0.07],
        "n_starts": starts,
        "seed": seed,
    }
    return terrain_toml(
        f"pillar_field_{seed}",
        BOUNDS,
        [("ground, top at z = 0", [slab((0.0, 0.0, 12.0, 8.0), 0.0)]), ("pillars", pillars)],
        header=(f"Pillars standing in the way, field {seed} of studies/pillar_fields.py.",),
        scenario=scenario,
    )


def field_row(checkpoint: str, terrain: Path, workers: int, method: str = "leas") -> dict:
    """`scenario_row` of one field, with the seconds it took."""
    began = time.perf_counter()
    row = scenario_row(checkpoint, str(terrain.resolve()), None, workers, method)
    return {**row, "seconds": round(time.perf_counter() - began, 1)}


def markdown(results: dict) -> str:
    policies = list(results["policies"])
    lines = ["| policy | starts | success % [95 % CI] | fields with every start reached | mean coverage % |"]
    lines.append("|---|---|---|---|---|")
    for p in policies:
        rows = list(results["results"].get(p, {}).values())
        if not rows:
            continue
        k, n = sum(r["success"] for r in rows), sum(r["n"] for r in rows)
        whole = sum(r["success"] == r["n"] for r in rows)
        coverage = 100 * np.mean([r["mean_coverage"] for r in rows])
        lines.append(
            f"| {p} | {n} | {percent_with_interval(k, n)} | {whole} / {len(rows)} | {coverage:.1f} |"
        )
    lines += ["", "Per field (successes of the starts):", ""]
    seeds = sorted({int(s) for rows in results["results"].values() for s in rows})
    lines.append("| policy | " + " | ".join(str(s) for s in seeds) + " |")
    lines.append("|---" * (1 + len(seeds)) + "|")
    for p in policies:
        rows = results["results"].get(p, {})
        cells = [f"{rows[str(s)]['success']}/{rows[str(s)]['n']}" if str(s) in rows else "" for s in seeds]
        lines.append(f"| {p} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def plot_fields(seeds: list[int], path: Path) -> None:
    """The fields from above: pillars, start region and target."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    columns = 5
    rows = math.ceil(len(seeds) / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(2.6 * columns, 1.9 * rows), layout="constrained")
    for ax, seed in zip(np.atleast_1d(axes).ravel(), seeds, strict=False):
        for x, y, side, yaw in pillar_boxes(seed):
            c, s, h = math.cos(yaw), math.sin(yaw), side / 2
            corners = [(x + h * (c * u - s * v), y + h * (s * u + c * v)) for u, v in SQUARE]
            ax.add_patch(Polygon(corners, color="0.3"))
        ax.plot(*START, "go", ms=4)
        ax.plot(*TARGET, "r*", ms=7)
        ax.plot([START[0], TARGET[0]], [START[1], TARGET[1]], color="0.7", lw=0.6, ls="--")
        ax.set_xlim(3.0, 11.5)
        ax.set_ylim(2.0, 6.0)
        ax.set_aspect("equal")
        ax.set_title(f"field {seed}", fontsize=8)
        ax.tick_params(labelsize=6)
    for ax in np.atleast_1d(axes).ravel()[len(seeds) :]:
        ax.axis("off")
    figure.savefig(path, dpi=90)
    plt.close(figure)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--policy", action="append", required=True, metavar="LABEL=RUN_DIR")
    parser.add_argument("--out", required=True)
    parser.add_argument("--fields", type=int, default=20, help="fields, seeds 0 to N - 1")
    parser.add_argument("--starts", type=int, default=10, help="starts per field")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument(
        "--method", choices=("leas", "navigate"), default="leas", help="what the policies steer"
    )
    args = parser.parse_args()
    out = Path(args.out)
    (out / "fields").mkdir(parents=True, exist_ok=True)
    policies = dict(p.split("=", 1) for p in args.policy)
    path = out / "pillar_fields.json"
    results = json.loads(path.read_text()) if path.exists() else {"policies": {}, "results": {}}
    results["policies"].update(policies)
    seeds = list(range(args.fields))
    files = {}
    for seed in seeds:
        files[seed] = out / "fields" / f"pillar_field_{seed}.toml"
        files[seed].write_text(pillar_field(seed, args.starts))
    plot_fields(seeds, out / "pillar_fields.png")
    for label, checkpoint in policies.items():
        rows = results["results"].setdefault(label, {})
        for seed in seeds:
            if str(seed) in rows:
                continue
            rows[str(seed)] = field_row(checkpoint, files[seed], args.workers, args.method)
            r = rows[str(seed)]
            print(f"{label} field {seed}: {r['success']}/{r['n']} ({r['seconds']} s)", flush=True)
            results["machine"] = machine()
            tmp = path.with_suffix(".tmp")
            tmp.write_text(json.dumps(results, indent=1))
            tmp.replace(path)
    (out / "pillar_fields.md").write_text(markdown(results))
    print(markdown(results))


if __name__ == "__main__":
    main()
