"""Do Table II's baselines (RBLin, RBKino) on eval_ground, run as the paper ran them, reach its
figures?

Paper §IV-B.1 / Table II: flat ground, a target 4 m away, the start yaw turned
-30..30, 60..120 or 150..210 degrees from the target direction, an initial speed
of 0.01, 0.04 or 0.07 m/s along the heading, 60 starts per cell; the figure is the
mean fraction of the guide covered by the contact plan. Starts are those of
`leas evaluate --scenario ground` (same seeds: the scenario's seed plus the cell's
index in Table II's order), the guides those of `leas_jax.steering`, the judge the
contact generator (`leas_jax.eval.evaluate.validate`, one pool of `--workers`).

Variants (`--variants`):

  rblin            RBLin as shipped (100 rotation steps, paper §IV-B.1);
  rbkino           RBKino with HPP's fixed-time synchronisation (the default);
  rbkino_cruise    RBKino with the former synchronisation (+-a_max, lower cruise
                   velocity: a start velocity across the goal dies within 0.1 s);
  rbkino_vmax030   RBKino with hpp-rbprm-corba's Talos vMax = 0.30 m/s;
  rbkino_dt001     RBKino's continuous path sampled every 0.01 s, as HPP's contact
                   generator samples it (hpp-rbprm-corba scenarios/
                   abstract_contact_generator.py, `interpolate(0.01, ...)`), judged by a
                   generator planning at the same 0.5 s as the others (its refinement,
                   `GeneratorConfig.refine_stride`, then steps through the 0.01 s poses).

and two diagnostics of the generator's turning:

  --sweep-steps    RBLin's in-place rotation over fewer steps (a faster turn in
                   place) on the 150..210 degree cells of `--sweep-speeds`;
  --generator-strides  RBKino's guides judged again by generators that plan every
                   k-th guide pose (`GeneratorConfig.planning_interval` k x timestep,
                   default 0.5 s; HPP's contact generator samples the guide every
                   0.01 s, hpp-rbprm-corba scenarios/abstract_contact_generator.py `dt`);
  per guide        the root's yaw change over the first 0.5 s (the generator's first
                   planning pose, `GeneratorConfig.planning_interval`) and the largest
                   one within any 0.5 s, next to its coverage.

    nice -n 10 python studies/table2_baselines.py --out docs/results/2026-12-01-table2-baselines \\
        [--n-starts 60] [--workers 2] [--variants rblin,rbkino,rbkino_cruise] \\
        [--sweep-steps 5,10,20,50] [--sweep-speeds 0.04] [--generator-strides 1] [--set NAME=VALUE ...]

`--set NAME=VALUE` (repeatable) changes one GeneratorConfig field of the judging generator,
e.g. `--set refine_stride=10` to refine a 0.01 s guide every 0.1 s only.

Writes <out>/table2_baselines.json (per cell and variant: n, mean coverage with a 95 %
bootstrap interval, fully covered and success fractions with 95 % Wilson intervals, the
paper's figure; every trajectory) and <out>/table2_baselines.png.

Results: docs/results/2026-12-01-table2-baselines, 2026-12-03-table2-hpp-sampling,
2026-12-03-rbkino-hpp-sampling, and the table2 folders of 2026-12-02-refined-planning-poses,
2026-12-02-retry-settings, 2026-12-02-stance-arm-shifts, 2026-12-02-step-fallback.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "benchmarks")]  # the other studies, benchmarks/common.py

from common import (  # noqa: E402
    add_generator_settings_argument,
    generator_settings,
    load_average,
    provenance,
    wilson,
)

from leas_jax.errors import UsageError  # noqa: E402

VARIANTS = {
    "rblin": ("rblin", {}),
    "rbkino": ("rbkino", {}),
    "rbkino_cruise": ("rbkino", {"rbkino_sync": "cruise"}),
    "rbkino_vmax030": ("rbkino", {"v_max": 0.30}),
    "rbkino_dt001": ("rbkino", {"timestep": 0.01}),
}
BOOTSTRAP = 2000  # resamples of the mean-coverage interval


def parse_list(text: str, kind, name: str) -> list:
    """'a,b' -> [kind(a), kind(b)]; UsageError naming the option on a bad item."""
    try:
        return [kind(x) for x in text.split(",") if x.strip()]
    except ValueError as error:
        raise UsageError(f"{name}: {error}") from None


def bootstrap_mean(values: np.ndarray, seed: int = 0) -> tuple[float, float]:
    """95 % percentile-bootstrap interval of the mean of `values` [N >= 1]."""
    rng = np.random.default_rng(seed)
    means = rng.choice(values, (BOOTSTRAP, len(values))).mean(axis=1)
    return float(np.percentile(means, 2.5)), float(np.percentile(means, 97.5))


def first_turn_deg(guide: np.ndarray, poses: int) -> float:
    """|yaw change| (deg) from the first guide pose to the generator's first planning pose (`poses` on)."""
    k = min(poses, len(guide) - 1)
    return float(abs(math.degrees(guide[k, 3] - guide[0, 3])))


def max_turn_deg(guide: np.ndarray, poses: int) -> float:
    """Largest |yaw change| (deg) over any `poses` consecutive steps (0.5 s at 0.1 s) of the guide."""
    k = min(poses, len(guide) - 1)
    return float(np.degrees(np.abs(guide[k:, 3] - guide[: len(guide) - k, 3])).max()) if k else 0.0


def percent_interval(successes: int, trials: int) -> list[float]:
    """Wilson 95 % interval in %, clipped to [0, 100] (the bounds of 0 or n successes round past them)."""
    return [min(100.0, max(0.0, 100.0 * x)) for x in wilson(successes, trials)]


def summarize(trajectories) -> dict:
    """n >= 1 trajectories -> n, mean coverage (%) and its interval, fully covered and success
    rates (%) with Wilson intervals."""
    cover = np.array([t.outcome.coverage for t in trajectories], np.float64)
    full = int(sum(t.outcome.last_valid_index >= len(t.guide) - 1 for t in trajectories))
    success = int(sum(t.outcome.success for t in trajectories))
    n = len(trajectories)
    lo, hi = bootstrap_mean(cover)
    return {
        "n": n,
        "coverage": 100.0 * float(cover.mean()),
        "coverage_95ci": [100.0 * lo, 100.0 * hi],
        "fully_covered": 100.0 * full / n,
        "fully_covered_95ci": percent_interval(full, n),
        "success": 100.0 * success / n,
        "success_95ci": percent_interval(success, n),
        "errors": int(sum(t.outcome.error is not None for t in trajectories)),
    }


def turn_separation(records: list[dict], variant: str) -> dict:
    """Largest 0.5 s yaw change (deg) of the fully covered guides against the smallest of the
    guides covered under half: `separated` when every covered one turns less than every failed one."""
    full = [t["max_turn_deg"] for t in records if t["variant"] == variant and t["coverage"] >= 1.0]
    failed = [t["max_turn_deg"] for t in records if t["variant"] == variant and t["coverage"] < 0.5]
    covered_max = max(full) if full else None
    failed_min = min(failed) if failed else None
    return {
        "covered_max": covered_max,
        "failed_min": failed_min,
        "n_covered": len(full),
        "n_failed": len(failed),
        "separated": bool(full and failed and covered_max < failed_min),  # None above: no such guide
    }


def build(jobs, terrain, field, cells, n_starts: int, base, env):
    """Trajectories of every job (label, method, config overrides, cell indices), unvalidated."""
    from leas_jax.eval.evaluate import Trajectory
    from leas_jax.eval.scenarios import draw_starts
    from leas_jax.steering.rbkino import rbkino
    from leas_jax.steering.rblin import rblin

    scenario = terrain.scenario
    target = np.asarray(scenario.target, np.float64)
    starts = {}
    out = []
    for label, method, overrides, cell_ids in jobs:
        config = dataclasses.replace(base, **overrides)
        steer = rblin if method == "rblin" else rbkino
        for k in cell_ids:
            if k not in starts:
                starts[k] = draw_starts(
                    scenario,
                    cells[k],
                    n_starts,
                    scenario.seed + k,
                    field,
                    base.nominal_root_height,
                    env.reachability,
                )
            s = starts[k]
            for n in range(len(s.poses)):
                guide = steer(field, s.poses[n], target, float(s.speeds[n]), config)
                out.append(
                    Trajectory(
                        k,
                        label,
                        s.poses[n],
                        float(s.speeds[n]),
                        float(s.yaw_offsets_deg[n]),
                        guide,
                        timestep=config.timestep,
                    )
                )
    return out


def judge(
    terrain, trajectories, timestep: float, workers: int, stride: int | None, settings: dict | None = None
) -> None:
    """Fill every trajectory's outcome with `evaluate.validate`, each guide at its own
    timestep: a generator with `settings` (GeneratorConfig fields; None: its defaults),
    planning every `stride` x `timestep` s where `stride` is given."""
    from leas_jax.contacts import GeneratorConfig
    from leas_jax.eval.evaluate import validate

    config = GeneratorConfig(**(settings or {}))
    if stride is not None:
        config = dataclasses.replace(config, planning_interval=stride * timestep)
    validate(
        terrain, trajectories, timestep, workers, progress=True, desc="table II baselines", config=config
    )


def figure(report: dict, path: Path) -> None:
    """Coverage vs start yaw offset (ours vs paper), coverage vs first-0.5 s turn, RBLin turn-rate sweep."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from leas_jax.training.checkpoint import atomic_write_bytes

    cells = report["cells"]
    speeds = sorted({c["speed"] for c in cells})
    colours = dict(zip(speeds, ("tab:blue", "tab:orange", "tab:green")))
    table = list(report["table"])
    ncols = 4
    nrows = -(-(len(table) + 2) // ncols)
    fig, grid = plt.subplots(nrows, ncols, figsize=(4.3 * ncols, 3.9 * nrows), squeeze=False)
    axes = list(grid.ravel())
    for ax in axes[len(table) + 2 :]:
        ax.axis("off")
    for ax, variant in zip(axes, table):
        method = report["variants"][variant]["method"]
        for v in speeds:
            rows = [(c, report["table"][variant][c["name"]]) for c in cells if c["speed"] == v]
            x = np.array([0.5 * sum(c["yaw_deg"]) for c, _ in rows]) + 4 * (speeds.index(v) - 1)
            y = np.array([r["coverage"] for _, r in rows])
            err = np.abs(np.array([r["coverage_95ci"] for _, r in rows]).T - y)
            ax.errorbar(x, y, yerr=err, fmt="o-", color=colours[v], label=f"ours {v:g} m/s", capsize=3)
            paper = [c["paper"].get(method) for c, _ in rows]
            ax.plot(x, paper, "x--", color=colours[v], alpha=0.7, label=f"paper {v:g} m/s")
        ax.set_title(report["variants"][variant]["title"], fontsize=9)
        ax.set_xlabel("start yaw offset from the target direction (deg)")
        ax.set_xticks([0, 90, 180])
        ax.set_ylim(-5, 105)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("mean coverage of the contact plan (%)")
    axes[0].legend(fontsize=7)
    ax = axes[len(table)]
    for variant, marker in zip(table, "o^sDv.*"):
        points = [t for t in report["trajectories"] if t["variant"] == variant]
        if points:
            ax.scatter(
                [t["max_turn_deg"] for t in points],
                [100 * t["coverage"] for t in points],
                s=10,
                marker=marker,
                alpha=0.5,
                label=variant,
            )
    ax.set_xlabel("largest root yaw change within 0.5 s (deg)")
    ax.set_ylabel("coverage (%)")
    ax.set_title("fast turns: the generator's limit")
    for variant, gap in report["turn_separation"].items():
        if variant == "rbkino" and gap["separated"]:
            ax.axvline(gap["failed_min"], color="k", lw=0.8, ls=":")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    sweep_panel(axes[len(table) + 1], report)
    fig.tight_layout()
    import io

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    plt.close(fig)
    atomic_write_bytes(path, buffer.getvalue())


def sweep_panel(ax, report: dict) -> None:
    """RBLin's coverage against its in-place turn rate (the `--sweep-steps` cells); blank without a sweep."""
    sweep = report.get("rblin_sweep", {})
    if not sweep:
        ax.axis("off")
        return
    for v in sorted({row["speed"] for row in sweep.values()}):
        rows = sorted((row for row in sweep.values() if row["speed"] == v), key=lambda r: r["deg_per_s"])
        x = [r["deg_per_s"] for r in rows]
        y = [r["coverage"] for r in rows]
        err = np.abs(np.array([r["coverage_95ci"] for r in rows]).T - np.array(y))
        ax.errorbar(x, y, yerr=err, fmt="o-", capsize=3, label=f"ours, 150..210 deg, {v:g} m/s")
        paper = report["paper_150_210"].get(f"{v:g}")
        if paper is not None:
            ax.plot([18.0], [paper], "kx", ms=10, label=f"paper RBLin (100 steps), {v:g} m/s")
    ax.set_xscale("log")
    rates = sorted({r["deg_per_s"] for r in sweep.values()})
    ax.set_xticks(rates)
    ax.set_xticklabels([f"{r:.0f}" for r in rates], fontsize=7, rotation=60)
    ax.minorticks_off()
    ax.set_xlabel("RBLin in-place turn rate for 180 deg (deg/s)")
    ax.set_ylabel("mean coverage (%)")
    ax.set_title("turning in place")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, required=True, help="output folder")
    parser.add_argument("--n-starts", type=int, default=60, help="starts per cell (paper: 60)")
    parser.add_argument("--workers", type=int, default=2, help="contact-generator processes")
    parser.add_argument(
        "--variants", default="rblin,rbkino,rbkino_cruise", help=f"subset of {','.join(VARIANTS)}"
    )
    parser.add_argument(
        "--sweep-steps", default="5,10,20,50", help="RBLin rotation steps to sweep ('' for none)"
    )
    parser.add_argument("--sweep-speeds", default="0.04", help="initial speeds (m/s) of the swept cells")
    parser.add_argument(
        "--generator-strides", default="", help="generator strides re-judging RBKino's guides ('' for none)"
    )
    add_generator_settings_argument(parser)
    args = parser.parse_args(argv)
    settings = generator_settings(args.set, parser)
    variants = parse_list(args.variants, str, "--variants")
    unknown = [v for v in variants if v not in VARIANTS]
    if unknown or not variants:
        raise UsageError(
            f"--variants: unknown {','.join(unknown) or repr(args.variants)} (expected {','.join(VARIANTS)})"
        )
    steps = parse_list(args.sweep_steps, int, "--sweep-steps")
    sweep_speeds = parse_list(args.sweep_speeds, float, "--sweep-speeds")
    strides = parse_list(args.generator_strides, int, "--generator-strides")
    if args.n_starts < 1 or args.workers < 0 or any(s < 1 for s in steps + strides):
        raise UsageError("--n-starts, --sweep-steps and --generator-strides must be >= 1, --workers >= 0")

    from leas_jax.contacts import GeneratorConfig
    from leas_jax.env import EnvConfig, heightfield_from_terrain
    from leas_jax.eval.scenarios import PAPER_TABLE_II, cells_for
    from leas_jax.steering.baselines import BaselineConfig
    from leas_jax.terrain import load_terrain
    from leas_jax.terrain.generate import scenario_file

    load_before = load_average()
    began = time.perf_counter()
    terrain = load_terrain(scenario_file("ground"))
    env = EnvConfig()
    base = BaselineConfig.from_env(env)
    field = heightfield_from_terrain(terrain, env)
    cells = cells_for("ground", terrain.scenario)
    all_cells = list(range(len(cells)))
    jobs = [(v, VARIANTS[v][0], VARIANTS[v][1], all_cells) for v in variants]
    back = [k for k, c in enumerate(cells) if c.yaw_deg == (150.0, 210.0) and c.speed[0] in sweep_speeds]
    if steps and not back:
        raise UsageError(f"--sweep-speeds {args.sweep_speeds}: none of Table II's speeds")
    jobs += [(f"rblin_steps{s}", "rblin", {"rotation_steps": s}, back) for s in steps]
    trajectories = build(jobs, terrain, field, cells, args.n_starts, base, env)
    rejudged = {}
    for stride in strides:
        label = f"rbkino_stride{stride}"
        rejudged[stride] = build(
            [(label, "rbkino", {}, all_cells)], terrain, field, cells, args.n_starts, base, env
        )
    built = time.perf_counter()
    judge(terrain, trajectories, base.timestep, args.workers, None, settings)
    for stride, extra in rejudged.items():
        judge(terrain, extra, base.timestep, args.workers, stride, settings)
        trajectories += extra
    validated = time.perf_counter()
    titles = {
        "rblin": "RBLin (100 rotation steps)",
        "rbkino": "RBKino, HPP synchronisation (default)",
        "rbkino_cruise": "RBKino, former synchronisation (+-a_max)",
        "rbkino_vmax030": "RBKino, HPP Talos vMax 0.30 m/s",
        "rbkino_dt001": "RBKino, sampled every 0.01 s as HPP's generator",
    }
    described = {
        v: {"method": VARIANTS[v][0], "overrides": VARIANTS[v][1], "title": titles[v]} for v in variants
    }
    for stride in strides:
        described[f"rbkino_stride{stride}"] = {
            "method": "rbkino",
            "overrides": {},
            "generator_stride": stride,
            "title": f"RBKino (HPP), generator planning every {stride} pose(s)",
        }

    def rows(label, k):
        return [t for t in trajectories if t.method == label and t.cell == k]

    report = {
        "command": "python studies/table2_baselines.py "
        + " ".join(argv if argv is not None else sys.argv[1:]),
        "baseline_config": dataclasses.asdict(base),
        "generator_settings": {name: repr(value) for name, value in settings.items()},
        "cells": [
            {
                "name": c.name,
                "yaw_deg": list(c.yaw_deg),
                "speed": c.speed[0],
                "paper": dict(PAPER_TABLE_II.get(c.table_key, {})),
            }
            for c in cells
        ],
        "variants": described,
        "table": {v: {cells[k].name: summarize(rows(v, k)) for k in all_cells} for v in described},
        "rblin_sweep": {},
        "paper_150_210": {
            f"{c.speed[0]:g}": PAPER_TABLE_II[c.table_key]["rblin"]
            for c in cells
            if c.yaw_deg == (150.0, 210.0)
        },
    }
    for s in steps:
        for k in back:
            row = summarize(rows(f"rblin_steps{s}", k))
            row.update(rotation_steps=s, speed=cells[k].speed[0], deg_per_s=180.0 / (s * base.timestep))
            report["rblin_sweep"][f"{s} steps, {cells[k].name}"] = row
    for k in back:  # the shipped 100 steps, on the same starts
        if "rblin" in variants:
            row = dict(report["table"]["rblin"][cells[k].name])
            row.update(rotation_steps=base.rotation_steps, speed=cells[k].speed[0])
            row["deg_per_s"] = 180.0 / (base.rotation_steps * base.timestep)
            report["rblin_sweep"][f"{base.rotation_steps} steps, {cells[k].name}"] = row

    def half_second(t):  # guide poses in the generator's first planning interval
        return GeneratorConfig().planning_stride(t.timestep)

    report["trajectories"] = [
        {
            "variant": t.method,
            "cell": t.cell,
            "yaw_offset_deg": t.yaw_offset_deg,
            "speed": t.speed,
            "coverage": t.outcome.coverage,
            "success": t.outcome.success,
            "last_valid_index": t.outcome.last_valid_index,
            "guide_poses": len(t.guide),
            "timestep": t.timestep,
            "first_turn_deg": first_turn_deg(t.guide, half_second(t)),
            "max_turn_deg": max_turn_deg(t.guide, half_second(t)),
            "error": t.outcome.error,
        }
        for t in trajectories
    ]
    report["turn_separation"] = {v: turn_separation(report["trajectories"], v) for v in described}
    report["seconds"] = {"guides": built - began, "contact_planning": validated - built}
    report.update(provenance(load_before))

    import json

    from leas_jax.training.checkpoint import atomic_write_text

    args.out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(
        args.out / "table2_baselines.json", json.dumps(report, indent=1, allow_nan=False) + "\n"
    )
    figure(report, args.out / "table2_baselines.png")
    for v in described:
        print(v, report["turn_separation"][v])
        for c in cells:
            r = report["table"][v][c.name]
            paper = PAPER_TABLE_II.get(c.table_key, {}).get(described[v]["method"])
            print(
                f"  {c.name:28s} coverage {r['coverage']:5.1f}% [{r['coverage_95ci'][0]:5.1f}, "
                f"{r['coverage_95ci'][1]:5.1f}]  full {r['fully_covered']:5.1f}%  paper {paper}"
            )
    for name, r in report["rblin_sweep"].items():
        print(f"  rblin {name:40s} {r['deg_per_s']:6.1f} deg/s coverage {r['coverage']:5.1f}%")
    print(f"wrote {args.out}/table2_baselines.json and .png")


if __name__ == "__main__":
    try:
        main()
    except UsageError as error:
        sys.exit(f"error: {error}")
