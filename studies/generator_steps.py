"""Which steps, drops, tilted tiles, beams and stairs the contact generator walks along a straight guide.

The box terrains of studies/generator_rough_scenes.py's limits (a step up or down at x = 3 on a
6 x 2 m terrain; `_limit_terrain`), swept finely, and the other features the field's scenes
hold: 0.3 m tiles tilted 5-25 degrees (pitch or roll), a beam over the void, stairs up and down.
Each case is one straight guide at 0.18 m/s, the root 1 m above the terrain under it
(`straight_guide`; over a beam or the tiles, 1 m above the ground's level), planned by the
default generator (`ContactGenerator.stop_reasons`); a covered plan is also checked by
`contacts.verify`. Also measured: how high and how low a root can stand over a flat sole at its
half-sitting place (leg IK within the joint limits), the kinematic bound of steps and drops.

    python studies/generator_steps.py --label after [--out DIR]
    python studies/generator_steps.py --compare before after [--out DIR]
    python studies/generator_steps.py --rough BEFORE.json AFTER.json [--out DIR]

The first writes generator_steps_<label>.json (every case: coverage, where and why it
stops, verification, seconds; the provenance of `leas_jax` as imported: run it with another
checkout first on PYTHONPATH to measure that one); the second reads two of them and writes
generator_steps.md (per feature the sizes covered in each, then every case whose coverage
differs or that is not covered after); the third compares two runs of
studies/generator_rough_scenes.py per scene (rough_scenes.json / .md).
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
sys.path.insert(0, str(REPO / "studies"))

from common import load_average, provenance  # noqa: E402
from generator_rough_scenes import TIMESTEP, _limit_terrain, straight_guide  # noqa: E402

OUT = "docs/results/2026-12-06-generator-steps"
SPEED = 0.18  # m/s, the env's target speed
UP = (
    tuple(round(h, 3) for h in np.arange(0.10, 0.5001, 0.025))
    + tuple(round(h, 3) for h in np.arange(0.27, 0.3601, 0.005))
    + (0.336, 0.338, 0.342, 0.344)
)
DOWN = tuple(round(h, 3) for h in np.arange(0.10, 0.3501, 0.025))
TILTS = (5, 10, 15, 20, 25)  # degrees
BEAMS = (0.30, 0.40)  # m wide
RISERS = (0.15, 0.20)  # m
TILE = 0.3  # m, the rubble family's tiles
TREAD = 0.30  # m, stair treads (the family's are 0.25-0.35 m)
STEPS = 4  # risers of a flight


def _head(length: float) -> str:
    return f'name = "case"\nbounds = [[0.0, 0.0], [{length}, 2.0]]\nvoid_height = -2.0\nresolution = 0.02\n'


def _box(center, size, rpy=(0.0, 0.0, 0.0)) -> str:
    def row(values):
        return ", ".join(f"{v:.4f}" for v in values)

    return f"[[box]]\ncenter = [{row(center)}]\nsize = [{row(size)}]\nrpy = [{row(rpy)}]\n"


def _slab(x0: float, x1: float, top: float = 0.0, y0: float = 0.0, y1: float = 2.0) -> str:
    return _box(((x0 + x1) / 2, (y0 + y1) / 2, top - 0.25), (x1 - x0, y1 - y0, 0.5))


def tiles_terrain(degrees: float, axis: str) -> str:
    """Flat ground, then 4 x 6 tiles of 0.3 m (x 2.4-3.6), each tilted `degrees` about y
    ("pitch") or x ("roll"), their centres at the ground's level, then flat ground."""
    angle = math.radians(degrees)
    rpy = (0.0, angle, 0.0) if axis == "pitch" else (angle, 0.0, 0.0)
    boxes = [_slab(0.0, 2.4), _slab(3.6, 6.0)]
    for x in np.arange(2.4 + TILE / 2, 3.6, TILE):
        for y in np.arange(TILE / 2, 2.0, TILE):
            boxes.append(_box((x, y, -0.05), (TILE, TILE, 0.1), rpy))
    return _head(6.0) + "\n".join(boxes)


def beam_terrain(width: float) -> str:
    """Ground to x = 2.5, a 2 m beam of `width` centred on y = 1 over the void, ground from x = 4.5."""
    return _head(6.5) + "\n".join(
        [_slab(0.0, 2.5), _slab(2.5, 4.5, 0.0, 1.0 - width / 2, 1.0 + width / 2), _slab(4.5, 6.5)]
    )


def stairs_terrain(riser: float, down: bool) -> str:
    """Ground to x = 2.5, then `STEPS` treads of `TREAD` each `riser` higher (or, down, the
    ground `STEPS` risers up and each tread one lower), then flat ground to x = 6.5."""
    tops = [riser * (k + 1) for k in range(STEPS)]
    if down:
        tops = tops[::-1][1:] + [0.0]
        first = STEPS * riser
    else:
        first = 0.0
    boxes = [_slab(0.0, 2.5, first)]
    x = 2.5
    for top in tops[:-1]:
        boxes.append(_slab(x, x + TREAD, top))
        x += TREAD
    boxes.append(_slab(x, 6.5, tops[-1]))
    return _head(6.5) + "\n".join(boxes)


def cases() -> list[dict]:
    """Every case: kind, size (m or degrees), axis, terrain text, guide end x, flat root."""
    rows = [
        {"kind": "up", "size": h, "text": _limit_terrain("up", h), "end": 4.5 + h} for h in sorted(set(UP))
    ]
    rows += [{"kind": "down", "size": h, "text": _limit_terrain("down", h), "end": 4.5 + h} for h in DOWN]
    for axis in ("pitch", "roll"):
        rows += [
            {"kind": f"tiles {axis}", "size": d, "text": tiles_terrain(d, axis), "end": 4.8, "flat": True}
            for d in TILTS
        ]
    rows += [{"kind": "beam", "size": w, "text": beam_terrain(w), "end": 5.5, "flat": True} for w in BEAMS]
    for down in (False, True):
        rows += [
            {
                "kind": "stairs down" if down else "stairs up",
                "size": r,
                "text": stairs_terrain(r, down),
                "end": 5.5,
            }
            for r in RISERS
        ]
    return rows


def run_case(case: dict) -> dict:
    """Plan the case's straight guide; coverage, where it stops and why, verification."""
    from leas_jax.contacts.planner.generator import ContactGenerator
    from leas_jax.contacts.verify import verify
    from leas_jax.env import EnvConfig, heightfield_from_terrain
    from leas_jax.terrain import loads_terrain

    terrain = loads_terrain(case["text"])
    field = heightfield_from_terrain(terrain, EnvConfig(condition="cylinders"))
    guide = straight_guide(field, (1.5, 1.0), (case["end"], 1.0), SPEED, 1.0)
    if case.get("flat"):  # the root stays 1 m over the ground's level (the void, tilted tiles)
        guide[:, 2] = 1.0
    began = time.perf_counter()
    plan, reasons = ContactGenerator(terrain).stop_reasons(guide, TIMESTEP)
    seconds = time.perf_counter() - began
    covered = bool(plan.coverage >= 1.0)
    return {
        "kind": case["kind"],
        "size": case["size"],
        "coverage": round(float(plan.coverage), 4),
        "covered": covered,
        "verified": bool(verify(plan).ok) if covered else None,
        "stops_at_x": None if covered else round(float(guide[max(plan.last_valid_index, 0), 0]), 3),
        "stop_reasons": dict(reasons.most_common(4)),
        "seconds": round(seconds, 2),
    }


def root_heights_over_a_sole() -> dict:
    """m, the highest and lowest root heights above a flat sole at its half-sitting place under
    the root (1 mm steps) with the leg's IK within its joint limits, and the joints at the lowest."""
    from leas_jax.contacts.robot.ik import leg_ik_single
    from leas_jax.contacts.robot.model import load_talos

    talos = load_talos()
    leg, nominal = talos.legs[0], talos.nominal_sole_in_root[0]
    within = []
    for z in np.arange(1.20, 0.40, -0.001):
        q = leg_ik_single(leg, np.eye(3), np.array([nominal[0], nominal[1], -z]))
        if q is not None:
            within.append((round(float(z), 3), q))
    return {
        "highest": within[0][0],
        "lowest": within[-1][0],
        "joints_at_lowest": [round(float(v), 3) for v in within[-1][1]],
        "joint_lower": [round(float(v), 3) for v in leg.lower],
        "joint_upper": [round(float(v), 3) for v in leg.upper],
    }


def single_sole_tilt_limit() -> dict:
    """degrees, the largest tilt (0.5 degree steps, about the sole's y axis; its x axis gives
    the same) at which Talos stands on one sole, CoM 0.9 m above its centre, with the
    generator's equilibrium LP at `min_robustness` or more (hpp-centroidal-dynamics, friction
    mu, 4 generators per corner: an inscribed pyramid of the cone)."""
    from leas_jax.contacts.planner.config import GeneratorConfig
    from leas_jax.contacts.planner.surfaces import SOLE_CORNERS
    from leas_jax.contacts.robot.equilibrium import HppEquilibrium
    from leas_jax.contacts.robot.model import load_talos

    config = GeneratorConfig()
    equilibrium = HppEquilibrium(load_talos().mass, config.mu)
    largest = None
    for degrees in np.arange(0.0, 30.01, 0.5):
        a = math.radians(float(degrees))
        rot = np.array([[math.cos(a), 0.0, math.sin(a)], [0.0, 1.0, 0.0], [-math.sin(a), 0.0, math.cos(a)]])
        equilibrium.set_contacts(SOLE_CORNERS @ rot.T, np.repeat(rot[:, 2][None], 4, axis=0))
        if equilibrium.robustness(np.array([0.0, 0.0, 0.9])) >= config.min_robustness:
            largest = float(degrees)
    return {
        "largest_tilt_deg": largest,
        "mu": config.mu,
        "atan_mu_deg": round(math.degrees(math.atan(config.mu)), 2),
        "atan_mu_over_sqrt2_deg": round(math.degrees(math.atan(config.mu / math.sqrt(2.0))), 2),
    }


def _limits(rows: list[dict], kind: str) -> tuple[str, str]:
    part = sorted((r for r in rows if r["kind"] == kind), key=lambda r: r["size"])
    yes = ", ".join(f"{r['size']:g}" for r in part if r["covered"])
    no = ", ".join(f"{r['size']:g}" for r in part if not r["covered"])
    return yes or "-", no or "-"


def compare(before: dict, after: dict) -> str:
    """Markdown: per feature, the sizes covered before and after; then every case that differs."""
    lines = [
        "| feature | covered before | not covered before | covered after | not covered after |",
        "|---|---|---|---|---|",
    ]
    kinds = list(dict.fromkeys(r["kind"] for r in after["rows"]))
    for kind in kinds:
        b, a = _limits(before["rows"], kind), _limits(after["rows"], kind)
        lines.append(f"| {kind} | {b[0]} | {b[1]} | {a[0]} | {a[1]} |")
    lines += ["", "| case | coverage before | coverage after | after: stops at x, why |", "|---|---|---|---|"]
    old = {(r["kind"], r["size"]): r for r in before["rows"]}
    for row in after["rows"]:
        prev = old.get((row["kind"], row["size"]))
        if prev is None or prev["coverage"] != row["coverage"] or not row["covered"]:
            why = "" if row["covered"] else f"{row['stops_at_x']}: {row['stop_reasons']}"
            was = "-" if prev is None else f"{prev['coverage']:.3f}"
            lines.append(f"| {row['kind']} {row['size']:g} | {was} | {row['coverage']:.3f} | {why} |")
    unverified = [f"{r['kind']} {r['size']:g}" for r in after["rows"] if r["covered"] and not r["verified"]]
    lines += ["", f"Covered plans that fail `contacts.verify` after: {', '.join(unverified) or 'none'}."]
    heights = after["root_heights_over_a_sole"]
    lines.append(
        f"Root height above a flat sole under it with the leg's IK within its limits: "
        f"{heights['lowest']:.3f}-{heights['highest']:.3f} m (joints at the lowest: {heights['joints_at_lowest']})."
    )
    tilt = after["single_sole_tilt_limit"]
    lines.append(
        f"Largest tilt of one sole Talos stands on (equilibrium LP, mu {tilt['mu']}): {tilt['largest_tilt_deg']:g} deg "
        f"(atan(mu) = {tilt['atan_mu_deg']} deg, atan(mu / sqrt 2) = {tilt['atan_mu_over_sqrt2_deg']} deg)."
    )
    return "\n".join(lines) + "\n"


def rough_compare(before_path: Path, after_path: Path) -> tuple[dict, str]:
    """Per HPP rough scene, the straight guides of studies/generator_rough_scenes.py covered
    and their mean coverage in two of its JSON outputs, and the guides whose coverage fell or
    rose: (summary, markdown)."""
    before, after = (json.loads(Path(path).read_text()) for path in (before_path, after_path))
    old = {scene["name"]: scene["guides"] for scene in before["scenes"]}
    summary = []
    for scene in after["scenes"]:
        was, now = old[scene["name"]], scene["guides"]
        pairs = list(zip(was, now, strict=True))
        summary.append(
            {
                "scene": scene["name"],
                "guides": len(now),
                "covered_before": sum(g["covered"] for g in was),
                "covered_after": sum(g["covered"] for g in now),
                "mean_coverage_before": round(float(np.mean([g["coverage"] for g in was])), 4),
                "mean_coverage_after": round(float(np.mean([g["coverage"] for g in now])), 4),
                "fell": sum(b["coverage"] > a["coverage"] + 1e-9 for b, a in pairs),
                "rose": sum(a["coverage"] > b["coverage"] + 1e-9 for b, a in pairs),
            }
        )
    lines = [
        "| scene | guides | covered before | covered after | mean coverage before % | after % | guides lower / higher after |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in summary:
        lines.append(
            f"| {row['scene']} | {row['guides']} | {row['covered_before']} | {row['covered_after']} | "
            f"{100 * row['mean_coverage_before']:.1f} | {100 * row['mean_coverage_after']:.1f} | {row['fell']} / {row['rose']} |"
        )
    return {"scenes": summary}, "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--label", help="run every case; write generator_steps_<label>.json")
    parser.add_argument(
        "--compare", nargs=2, metavar=("BEFORE", "AFTER"), help="labels of two runs to compare"
    )
    parser.add_argument(
        "--rough",
        nargs=2,
        metavar=("BEFORE_JSON", "AFTER_JSON"),
        help="two generator_rough_scenes.json: write rough_scenes.json / .md (per scene, before and after)",
    )
    parser.add_argument("--out", default=OUT)
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.label:
        load_before = load_average()
        rows = []
        for case in cases():
            rows.append(run_case(case))
            r = rows[-1]
            print(
                f"{r['kind']} {r['size']:g}: coverage {r['coverage']:.3f} verified {r['verified']} {r['seconds']} s",
                flush=True,
            )
        payload = {
            **provenance(load_before),
            "rows": rows,
            "root_heights_over_a_sole": root_heights_over_a_sole(),
            "single_sole_tilt_limit": single_sole_tilt_limit(),
        }
        (out / f"generator_steps_{args.label}.json").write_text(json.dumps(payload, indent=1) + "\n")
    if args.compare:
        before, after = (
            json.loads((out / f"generator_steps_{label}.json").read_text()) for label in args.compare
        )
        text = compare(before, after)
        (out / "generator_steps.md").write_text(text)
        print(text, end="")
    if args.rough:
        summary, text = rough_compare(*args.rough)
        (out / "rough_scenes.json").write_text(json.dumps(summary, indent=1) + "\n")
        (out / "rough_scenes.md").write_text(text)
        print(text, end="")


if __name__ == "__main__":
    main()
