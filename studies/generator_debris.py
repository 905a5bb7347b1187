"""Does the contact generator cross a field of small tilted debris tiles at an angle to their axes?

hpp-environments' slalom_debris holds 0.30 x 0.20 m tiles tilted 15 degrees: the 0.20 x 0.13 m
sole fits one only within about 0.3 rad of one of its axes. A guide crossing them at 25-40
degrees found no foothold at its own yaw and stopped before them. `GeneratorConfig.sole_turns`
lets a sole turn (up to `max_foot_yaw`) where a face holds none at the step's yaw.

The terrain (`debris_terrain`): flat ground, 5 columns of 0.29 x 0.19 m tiles (x 1.5-3.0 m) each
tilted about x or y in turn, flat ground again (5 x 4 m). Each case is one straight guide at
0.18 m/s from (0.8, 1.2) at a heading to the tiles' axes (`diagonal_guide`), the root 1 m up,
planned with and without sole turns (`ContactGenerator.stop_reasons`); a covered plan is also
checked by `contacts.verify`. Writes generator_debris.json and generator_debris.md into --out.

    python studies/generator_debris.py --out docs/results/2026-12-06-sole-turns
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))

from common import load_average, provenance  # noqa: E402

DT = 0.1  # s between guide poses
SPEED = 0.18  # m/s, the env's target speed
ROOT = 1.0  # m, the root above the ground
TILES_X = (1.5, 3.0)  # m, the tiles' extent along x
HEADINGS = (0.0, 0.2, 0.4, 0.55, 0.7)  # rad, the guide's heading to the tiles' x axis
TILTS = (10.0, 15.0)  # deg


def debris_terrain(tilt_deg: float = 15.0):
    """Flat ground, then 5 columns of 0.29 x 0.19 m debris tiles (x in TILES_X, their tops about
    z = 0), each tilted by `tilt_deg` about x or y in turn, then flat ground (5 x 4 m)."""
    from leas_jax.terrain import loads_terrain

    tilt = math.radians(tilt_deg)
    text = 'name = "debris"\nbounds = [[0.0, 0.0], [5.0, 4.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
    text += "[[box]]\ncenter = [0.75, 2.0, -0.25]\nsize = [1.5, 4.0, 0.5]\n"
    text += "[[box]]\ncenter = [4.0, 2.0, -0.25]\nsize = [2.0, 4.0, 0.5]\n"
    for i, x in enumerate(np.arange(TILES_X[0] + 0.15, TILES_X[1], 0.3)):
        for j, y in enumerate(np.arange(0.1, 4.0, 0.2)):
            roll, pitch = [(tilt, 0.0), (-tilt, 0.0), (0.0, tilt), (0.0, -tilt)][(i + 2 * j) % 4]
            text += (
                f"[[box]]\ncenter = [{x:.3f}, {y:.3f}, -0.05]\nsize = [0.29, 0.19, 0.1]\n"
                f"rpy = [{roll}, {pitch}, 0.0]\n"
            )
    return loads_terrain(text, source=f"<debris {tilt_deg:g} deg>")


def diagonal_guide(yaw: float, length: float = 3.0) -> np.ndarray:
    """[T, 4] straight guide (x, y, z, yaw), world, from (0.8, 1.2) at heading `yaw` (rad) over the
    debris at SPEED, the root ROOT above the ground."""
    count = int(length / (SPEED * DT)) + 1
    along = np.linspace(0.0, length, count)
    x, y = 0.8 + along * math.cos(yaw), 1.2 + along * math.sin(yaw)
    return np.stack([x, y, np.full(count, ROOT), np.full(count, yaw)], axis=1)


def run_case(terrain, yaw: float, turns: bool) -> dict:
    """One guide planned with (or without) sole turns: coverage, verification, where and why it stops."""
    from leas_jax.contacts import GeneratorConfig, verify
    from leas_jax.contacts.planner.generator import ContactGenerator

    config = GeneratorConfig() if turns else GeneratorConfig(sole_turns=())
    guide = diagonal_guide(yaw)
    began = time.perf_counter()
    plan, reasons = ContactGenerator(terrain, config).stop_reasons(guide, DT)
    stop = guide[plan.last_valid_index]
    return {
        "heading": yaw,
        "sole_turns": turns,
        "coverage": round(float(plan.coverage), 4),
        "verified": bool(verify(plan).ok) if plan.coverage == 1.0 else None,
        "stops_at_x": None if plan.coverage == 1.0 else round(float(stop[0]), 3),
        "reasons": dict(reasons.most_common(3)),
        "seconds": round(time.perf_counter() - began, 2),
    }


def table(cases: list[dict]) -> str:
    lines = [
        "| tilt (deg) | heading (rad) | coverage with turns | without | stops at x (m) without / with | why, without |",
        "|---|---|---|---|---|---|",
    ]
    for tilt in TILTS:
        for yaw in HEADINGS:
            on, off = (
                next(c for c in cases if c["tilt"] == tilt and c["heading"] == yaw and c["sole_turns"] == t)
                for t in (True, False)
            )
            stops = f"{off['stops_at_x'] or '-'} / {on['stops_at_x'] or '-'}"
            why = ", ".join(f"{k} {v}" for k, v in off["reasons"].items()) or "-"
            lines.append(
                f"| {tilt:g} | {yaw:g} | {100 * on['coverage']:.0f} % | {100 * off['coverage']:.0f} % | {stops} | {why} |"
            )
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="docs/results/2026-12-06-sole-turns")
    args = parser.parse_args()
    load_before = load_average()
    cases = []
    for tilt in TILTS:
        terrain = debris_terrain(tilt)
        for yaw in HEADINGS:
            for turns in (True, False):
                cases.append({"tilt": tilt, **run_case(terrain, yaw, turns)})
                print(cases[-1], flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report = {**provenance(load_before), "cases": cases}
    (out / "generator_debris.json").write_text(json.dumps(report, indent=1) + "\n")
    (out / "generator_debris.md").write_text(table(cases))
    print(table(cases), end="")


if __name__ == "__main__":
    main()
