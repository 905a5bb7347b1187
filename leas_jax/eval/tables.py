"""Tables of the evaluation: results.json, table.md, table.csv, guides.npz (host).

Metrics are percentages: `coverage` is the mean arc-length fraction of the
guides covered by the contact plans (the paper's Table II "success rate"),
`success` the fraction of trajectories meeting docs/design.md §8's success test.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np

from leas_jax.eval.scenarios import PAPER_TABLE_II, TABLE_II_SPEEDS, TABLE_II_YAWS

CSV_FIELDS = ("scenario", "cell", "method", "n", "coverage", "success", "errors", "paper_coverage")
METHOD_LABELS = {
    "rblin": "RBLin",
    "rbkino": "RBKino",
    "rbkino_rrt": "RBKino+RRT",
    "leas": "LeaS",
    "leas_rrt": "LeaS+RRT waypoints",
    "navigate": "Navigate (lattice search, LeaS, replans)",
}


def _number(value):
    """JSON-safe float (NaN -> None)."""
    value = float(value)
    return None if math.isnan(value) else round(value, 6)


def rows(results) -> list[dict]:
    """One row per scenario, cell (and 'all') and method, with the paper's Table II value where there is one."""
    out = []
    for result in results:
        summary = result.summary()
        names = [c.name for c in result.cells] + (["all"] if len(result.cells) > 1 else [])
        keys = {c.name: c.table_key for c in result.cells}
        for cell in names:
            for method in result.methods:
                s = summary[method][cell]
                key = keys.get(cell)
                paper = (
                    PAPER_TABLE_II[key].get(method) if key is not None and result.name == "ground" else None
                )
                out.append(
                    {
                        "scenario": result.name,
                        "cell": cell,
                        "method": method,
                        "n": s["n"],
                        "coverage": s["coverage"],
                        "success": s["success"],
                        "errors": s["errors"],
                        "paper_coverage": paper,
                    }
                )
    return out


def results_dict(results, policy=None, seconds: float = 0.0, leas_stop_at_invalid: bool = False) -> dict:
    """Everything results.json holds: config, per-trajectory metrics, summaries, Table II."""
    report = {
        "format": "leas-evaluation-v1",
        "policy": None
        if policy is None
        else {
            "source": policy.source,
            "env_steps": int(policy.env_steps),
            "stop_at_invalid": bool(leas_stop_at_invalid),
        },
        "seconds": round(float(seconds), 3),
        "scenarios": {},
        "rows": [],
        "table_ii": None,
    }
    for result in results:
        scenario = result.terrain.scenario
        trajectories = []
        for t in result.trajectories:
            o = t.outcome
            trajectories.append(
                {
                    "cell": t.cell,
                    "method": t.method,
                    "start": [round(float(v), 6) for v in t.start],
                    "speed": _number(t.speed),
                    "yaw_offset_deg": _number(t.yaw_offset_deg),
                    "guide_length": 0 if t.guide is None else int(len(t.guide)),
                    "coverage": _number(o.coverage),
                    "success": bool(o.success),
                    "last_valid_index": int(o.last_valid_index),
                    "final_distance": _number(o.final_distance),
                    "error": o.error,
                    "waypoints": None if t.waypoints is None else np.round(t.waypoints, 6).tolist(),
                }
            )
            if t.replans is not None:
                trajectories[-1]["replans"] = int(t.replans)
            if t.timestep is not None:  # s between the guide's poses, where not the env's
                trajectories[-1]["timestep"] = float(t.timestep)
        report["scenarios"][result.name] = {
            "terrain": result.terrain.path or result.terrain.name,
            "target": np.asarray(scenario.target).tolist(),
            "waypoints": None if scenario.waypoints is None else np.asarray(scenario.waypoints).tolist(),
            "methods": list(result.methods),
            "cells": [
                {"name": c.name, "yaw_deg": list(c.yaw_deg), "speed": list(c.speed)} for c in result.cells
            ],
            "summary": {
                m: {
                    cell: {k: (_number(v) if isinstance(v, float) else v) for k, v in s.items()}
                    for cell, s in cells.items()
                }
                for m, cells in result.summary().items()
            },
            "seconds": {k: round(v, 3) for k, v in result.seconds.items()},
            "trajectories": trajectories,
        }
        if result.motions is not None:
            from leas_jax.eval.motions import aggregate

            report["scenarios"][result.name]["motion"] = {
                "executions": result.motions,
                "summary": aggregate(result.motions),
            }
    report["rows"] = [
        {k: (_number(v) if isinstance(v, float) else v) for k, v in r.items()} for r in rows(results)
    ]
    ground = [r for r in results if r.name == "ground"]
    if ground:
        report["table_ii"] = table_ii(ground[0])
    return report


def table_ii(result) -> list[dict]:
    """Table II rows: yaw range, speed, then per method our mean coverage (%) and the paper's."""
    summary = result.summary()
    out = []
    for cell in result.cells:
        if cell.table_key is None:
            continue
        row = {"yaw_deg": list(cell.yaw_deg), "speed": cell.speed[0]}
        for method in ("rblin", "rbkino", "leas"):
            ours = summary[method][cell.name]["coverage"] if method in summary else float("nan")
            row[method] = _number(ours)
            row[f"paper_{method}"] = PAPER_TABLE_II[cell.table_key][method]
        out.append(row)
    return out


def _pct(value) -> str:
    return "-" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value:.1f}%"


def table_ii_markdown(rows_ii: list[dict]) -> str:
    """Table II beside the paper's values (ours / paper)."""
    lines = [
        "## Table II: flat ground, mean coverage of the contact plan (ours / paper)",
        "",
        'Paper values: Chemin et al., "Learning to steer a locomotion contact planner", Table II '
        "(60 trajectories per cell).",
        "",
        "| initial yaw | speed (m/s) | RBLin | RBKino | LeaS |",
        "|---|---|---|---|---|",
    ]
    for yaw in TABLE_II_YAWS:
        for speed in TABLE_II_SPEEDS:
            match = [r for r in rows_ii if tuple(r["yaw_deg"]) == yaw and r["speed"] == speed]
            if not match:
                continue
            r = match[0]
            cells = [f"{_pct(r[m])} / {_pct(r['paper_' + m])}" for m in ("rblin", "rbkino", "leas")]
            lines.append(f"| {yaw[0]:g} to {yaw[1]:g} deg | {speed:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def markdown(report: dict) -> str:
    """table.md: Table II (when ground ran), then every scenario's coverage and success per cell and method."""
    parts = ["# LeaS evaluation", ""]
    if report.get("policy"):
        policy = report["policy"]
        ends = (
            "its paths end before the first pose the reachability condition rejects"
            if policy.get("stop_at_invalid", False)
            else "its paths roll on through poses the reachability condition rejects (the contact generator alone "
            "judges them, as it judges the baselines' paths)"
        )
        parts += [f"Policy: `{policy['source']}` ({policy['env_steps']:,} training steps); {ends}.", ""]
    parts += [
        "coverage: mean arc-length fraction of the guide covered by the contact plan; success: the plan covers "
        "the whole guide and a posture's root is within 0.30 m of the target (docs/design.md §8).",
        "",
    ]
    if report.get("table_ii"):
        parts.append(table_ii_markdown(report["table_ii"]))
    parts += [
        "## All scenarios",
        "",
        "| scenario | cell | method | n | coverage | success | no guide / errors |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in report["rows"]:
        parts.append(
            f"| {r['scenario']} | {r['cell']} | {METHOD_LABELS.get(r['method'], r['method'])} | {r['n']} "
            f"| {_pct(r['coverage'])} | {_pct(r['success'])} | {r['errors']} |"
        )
    parts.append("")
    from leas_jax.eval.motions import markdown as motion_markdown

    parts += motion_markdown(report, METHOD_LABELS)
    seconds = {name: s["seconds"] for name, s in report["scenarios"].items()}
    parts += [
        "Wall time (s): "
        + "; ".join(
            f"{name}: " + ", ".join(f"{k} {v:.1f}" for k, v in s.items()) for name, s in seconds.items()
        )
        + f"; total {report['seconds']:.1f}",
        "",
    ]
    return "\n".join(parts)


def csv_text(report: dict) -> str:
    """table.csv: the rows of `markdown`'s scenario table (percentages, empty for missing)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=CSV_FIELDS, lineterminator="\n")
    writer.writeheader()
    for r in report["rows"]:
        writer.writerow({k: ("" if r[k] is None else r[k]) for k in CSV_FIELDS})
    return buffer.getvalue()


def write_json(path: Path, report: dict) -> None:
    from leas_jax.training.checkpoint import atomic_write_text

    atomic_write_text(path, json.dumps(report, indent=1, allow_nan=False) + "\n")


def write_guides(path: Path, results) -> None:
    """guides.npz: `<scenario>/<index>` -> [T, 4] guide, index into results.json's trajectories."""
    from leas_jax.training.checkpoint import atomic_write_bytes

    arrays = {
        f"{r.name}/{k}": t.guide for r in results for k, t in enumerate(r.trajectories) if t.guide is not None
    }
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    atomic_write_bytes(path, buffer.getvalue())


def write_outputs(out: Path, results, report: dict) -> None:
    """results.json, table.md, table.csv and guides.npz into `out`."""
    from leas_jax.training.checkpoint import atomic_write_text

    write_json(out / "results.json", report)
    atomic_write_text(out / "table.md", markdown(report))
    atomic_write_text(out / "table.csv", csv_text(report))
    write_guides(out / "guides.npz", results)
