"""Which failures on the HPP rough scenes are the contact generator's own?

Straight guides (`leas_jax.steering.baselines.lift`: a line at constant speed and yaw, the root
`root height` above the terrain under it) across each rough scene's difficult part, from its
scenario's start region's centre (shifted sideways by each lateral offset) to its target, at
several speeds and root heights; the generator plans each (`validate_paths`). A scene where no
straight guide is covered is one the generator cannot walk along a line (a gap wider than its
stride, a drop deeper than its legs reach); where some are, the global layer only has to find
them. Then, on box terrains, straight guides across a gap of each width and a step up and down
of each height: the largest the generator covers. Writes generator_rough_scenes.json and .md
(per scene and setting: coverage, covered, where the generator stops; the limits) into --out
(docs/results/2026-12-06-rough-scenes).

    python studies/generator_rough_scenes.py [--terrains GLOB ...] [--workers 2] [--out DIR]
"""

from __future__ import annotations

import argparse
import glob
import itertools
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))

from common import load_average, provenance  # noqa: E402

SPEEDS = (0.10, 0.18, 0.25)  # m/s; 0.18 is the env's target speed (paper §IV)
ROOT_HEIGHTS = (0.95, 1.0, 1.05)  # m above the terrain under the root (nominal 1.0)
OFFSETS = (-0.3, 0.0, 0.3)  # m, sideways shifts of the line
TIMESTEP = 0.1  # s between guide poses (paper Table I)


def straight_guide(field, start, target, speed: float, root_height: float) -> np.ndarray:
    """[T, 4] (x, y, z, yaw) guide along the segment start -> target (world (x, y)) at `speed`."""
    from leas_jax.steering.baselines import lift

    start, target = np.asarray(start, float), np.asarray(target, float)
    length = float(np.hypot(*(target - start)))
    steps = max(2, int(math.ceil(length / (speed * TIMESTEP))) + 1)
    xy = start + np.linspace(0.0, 1.0, steps)[:, None] * (target - start)
    yaw = math.atan2(*(target - start)[::-1])
    return lift(field, np.column_stack([xy, np.full(steps, yaw)]), root_height)


def scene_lines(terrain) -> list[tuple[np.ndarray, np.ndarray]]:
    """(start, target) pairs: the start region's centre to the target, shifted sideways."""
    scenario = terrain.scenario
    start = np.asarray(scenario.start_region, float).mean(axis=0)
    target = np.asarray(scenario.target, float)
    along = (target - start) / np.hypot(*(target - start))
    side = np.array([-along[1], along[0]])
    return [(start + d * side, target + d * side) for d in OFFSETS]


def run_scene(path: str, workers: int) -> dict:
    """Coverage of every straight guide of a scene."""
    from leas_jax.contacts.validation.pool import validate_paths
    from leas_jax.env import EnvConfig, heightfield_from_terrain
    from leas_jax.terrain import load_terrain

    terrain = load_terrain(path)
    field = heightfield_from_terrain(terrain, EnvConfig(condition="cylinders"))
    settings = list(itertools.product(SPEEDS, ROOT_HEIGHTS, scene_lines(terrain)))
    guides = [straight_guide(field, s, t, v, h) for v, h, (s, t) in settings]
    began = time.perf_counter()
    results = validate_paths(terrain, guides, TIMESTEP, workers=workers, return_plans=False)
    rows = []
    for (speed, height, (start, _)), guide, result in zip(settings, guides, results, strict=True):
        last = int(result.last_valid_index)
        rows.append(
            {
                "speed": speed,
                "root_height": height,
                "start": [round(float(v), 3) for v in start],
                "coverage": float(result.coverage),
                "covered": bool(result.coverage >= 1.0),
                "stops_at": None
                if last >= len(guide) - 1
                else [round(float(v), 2) for v in guide[max(last, 0), :2]],
                "error": None if result.error is None else str(result.error),
            }
        )
    return {
        "terrain": path,
        "name": terrain.name,
        "seconds": round(time.perf_counter() - began, 1),
        "guides": rows,
    }


GAP_WIDTHS = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7)  # m, a gap across the whole width
STEP_HEIGHTS = (0.15, 0.20, 0.25, 0.30, 0.35, 0.40)  # m, one step up (a riser) or down (a drop)


def _limit_terrain(kind: str, size: float) -> str:
    """A 6 x 2 m box terrain: flat ground with, at x = 3, a gap of `size` m ("gap"), or a step up
    ("up") or down ("down") of `size` m."""
    head = 'name = "limit"\nbounds = [[0.0, 0.0], [6.0, 2.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
    if kind == "gap":
        left, right, top = (0.0, 3.0), (3.0 + size, 6.0), (0.0, 0.0)
    else:
        left, right = (0.0, 3.0), (3.0, 6.0)
        top = (0.0, size) if kind == "up" else (size, 0.0)
    boxes = [
        f"[[box]]\ncenter = [{(a + b) / 2}, 1.0, {t - 0.25}]\nsize = [{b - a}, 2.0, 0.5]\n"
        for (a, b), t in zip((left, right), top, strict=True)
    ]
    return head + "\n".join(boxes)


def kinematic_limits(workers: int) -> list[dict]:
    """Straight guides at the target speed across a gap of each width and a step up and down of
    each height (x 1.5 -> 4.5 + size): which the generator covers."""
    from leas_jax.contacts.validation.pool import validate_paths
    from leas_jax.env import EnvConfig, heightfield_from_terrain
    from leas_jax.terrain import loads_terrain

    cases = [("gap", w) for w in GAP_WIDTHS] + [(k, h) for k in ("up", "down") for h in STEP_HEIGHTS]
    rows = []
    for kind, size in cases:
        terrain = loads_terrain(_limit_terrain(kind, size))
        field = heightfield_from_terrain(terrain, EnvConfig(condition="cylinders"))
        guide = straight_guide(field, (1.5, 1.0), (4.5 + size, 1.0), 0.18, 1.0)
        if kind == "gap":  # the root stays at the ground's height over the gap, not the void's
            guide[:, 2] = 1.0
        (result,) = validate_paths(terrain, [guide], TIMESTEP, workers=min(workers, 1), return_plans=False)
        rows.append(
            {
                "kind": kind,
                "size": size,
                "coverage": float(result.coverage),
                "covered": bool(result.coverage >= 1.0),
            }
        )
        print(f"{kind} {size:.2f} m: coverage {result.coverage:.3f}", flush=True)
    return rows


def limits_table(rows: list[dict]) -> str:
    """Markdown: the largest gap, riser and drop a straight guide is covered across."""
    lines = ["| feature | sizes covered (m) | sizes not covered (m) |", "|---|---|---|"]
    for kind, label in (("gap", "gap across"), ("up", "step up"), ("down", "step down")):
        part = [r for r in rows if r["kind"] == kind]
        yes = ", ".join(f"{r['size']:.2f}" for r in part if r["covered"])
        no = ", ".join(f"{r['size']:.2f}" for r in part if not r["covered"])
        lines.append(f"| {label} | {yes or '-'} | {no or '-'} |")
    return "\n".join(lines) + "\n"


def table(scenes: list[dict]) -> str:
    """Markdown: per scene and (speed, root height), guides covered of 3 and mean coverage."""
    lines = [
        "| scene | speed m/s | root height m | covered | mean coverage % | stops at (x, y) |",
        "|---|---|---|---|---|---|",
    ]
    for scene in scenes:
        for speed, height in itertools.product(SPEEDS, ROOT_HEIGHTS):
            rows = [r for r in scene["guides"] if r["speed"] == speed and r["root_height"] == height]
            stops = "; ".join(f"({s[0]:.2f}, {s[1]:.2f})" for s in (r["stops_at"] for r in rows) if s)
            lines.append(
                f"| {scene['name']} | {speed:.2f} | {height:.2f} | {sum(r['covered'] for r in rows)} / {len(rows)} | "
                f"{100 * np.mean([r['coverage'] for r in rows]):.1f} | {stops} |"
            )
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--terrains", nargs="*", default=["terrains/hpp/rough/*.toml", "terrains/hpp/rubble.toml"]
    )
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", default="docs/results/2026-12-06-rough-scenes")
    args = parser.parse_args()
    load_before = load_average()
    files = sorted({f for pattern in args.terrains for f in glob.glob(pattern)})
    scenes = []
    for path in files:
        scenes.append(run_scene(path, args.workers))
        covered = sum(r["covered"] for r in scenes[-1]["guides"])
        print(
            f"{scenes[-1]['name']}: {covered} / {len(scenes[-1]['guides'])} straight guides covered",
            flush=True,
        )
    limits = kinematic_limits(args.workers)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "generator_rough_scenes.json").write_text(
        json.dumps({**provenance(load_before), "scenes": scenes, "limits": limits}, indent=1) + "\n"
    )
    text = table(scenes) + "\n" + limits_table(limits)
    (out / "generator_rough_scenes.md").write_text(text)
    print(text, end="")


if __name__ == "__main__":
    main()
