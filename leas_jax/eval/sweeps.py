"""Hole-width sweep: how wide a hole LeaS still walks round (host).

`eval_hole` (paper §IV-B.2) puts a 3 m wide hole between every start and the
target. LeaS sees the terrain through an 11 x 7 heightmap whose columns reach
0.45 m to either side of the root (`HeightmapConfig`), so behind a hole wider
than that view it sees void in every column and, with the paper's reward,
stops at the edge. The paper says of the bridge that LeaS succeeds "as long as
it appears in its vision field", and does not give the hole's size. The sweep
runs the hole scenario on copies of `eval_hole` whose hole is `width` m across
(`leas_jax.terrain.generate.hole_terrain_toml`: same 2 m length, target, start
yaws and speeds; the start region spans the hole's width), for each steering
method, and plots success against width.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from leas_jax.errors import UsageError

DEFAULT_WIDTHS = (0.6, 0.9, 1.2, 1.5, 2.0, 2.5, 3.0)  # m; 3.0 is eval_hole's hole
DEFAULT_METHODS = ("rblin", "leas")
MAX_WIDTH = 7.0  # m, the 8 m wide terrain keeps 0.5 m of ground on either side


def parse_widths(text: str) -> tuple[float, ...]:
    """'0.6,1.2' -> (0.6, 1.2), sorted and unique; a bad entry raises UsageError naming --widths."""
    try:
        widths = [float(w) for w in text.split(",") if w.strip()]
    except ValueError:
        raise UsageError(f"--widths: expected comma-separated numbers (m), got {text!r}") from None
    return checked_widths(widths, repr(text))


def checked_widths(widths, shown: str) -> tuple[float, ...]:
    """Widths (m) sorted and unique; UsageError naming --widths (with `shown`) unless all lie in (0, 7]."""
    widths = sorted({float(w) for w in widths})
    if not widths or widths[0] <= 0.0 or widths[-1] > MAX_WIDTH:
        raise UsageError(f"--widths: expected widths in (0, {MAX_WIDTH:g}] m, got {shown}")
    return tuple(widths)


def hole_terrain(width: float):
    """The `eval_hole` scenario with a `width` m wide hole, as a `Terrain`."""
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.generate import hole_terrain_toml

    return loads_terrain(hole_terrain_toml(width), source=f"<hole sweep, width {width:g} m>")


def hole_width_sweep(
    widths=DEFAULT_WIDTHS,
    methods=DEFAULT_METHODS,
    checkpoint=None,
    n_starts: int | None = None,
    workers: int | None = None,
    out=None,
    progress: bool = True,
) -> dict:
    """Success and coverage of each method on holes of each width.

    Args:
        widths: hole widths (m) across the line to the target, each in (0, 7].
        methods: steering methods (`leas_jax.eval.scenarios.METHODS`).
        checkpoint: run directory or policy.ckpt (needed by leas and leas_rrt).
        n_starts: starts per width (default the scenario's 60).
        workers: contact-generator processes (None: one per CPU; 0: in-process).
        out: directory for hole_sweep.json, hole_sweep.md, hole_sweep.png and one
            scenario figure per width (None: write nothing).
        progress: progress bars.

    Returns:
        {"format", "policy", "widths", "methods", "view_half_width", "seconds",
         "rows": [{"width", "method", "n", "coverage", "success", "errors"}]}, percentages.
    """
    from leas_jax.eval.evaluate import default_workers, policy_env, policy_for, run_scenario

    began = time.perf_counter()
    widths = checked_widths(widths, repr(list(widths)))
    policy = policy_for(methods, checkpoint)
    workers = default_workers() if workers is None else workers
    env = policy_env(policy)
    rows, results = [], []
    for width in widths:
        result = run_scenario(
            f"hole_{width:g}m",
            hole_terrain(width),
            tuple(methods),
            policy,
            n_starts,
            workers,
            progress=progress,
        )
        summary = result.summary()
        rows += [{"width": width, "method": m, **summary[m]["all"]} for m in methods]
        results.append(result)
    report = {
        "format": "leas-hole-sweep-v1",
        "policy": None if policy is None else {"source": policy.source, "env_steps": int(policy.env_steps)},
        "widths": list(widths),
        "methods": list(methods),
        "view_half_width": env.heightmap.lateral_step * env.heightmap.lateral_half_count,
        "seconds": round(time.perf_counter() - began, 3),
        "rows": rows,
    }
    if out is not None:
        write_outputs(Path(out), report, results)
    return report


def markdown(report: dict) -> str:
    """Success / mean coverage (%) per width (rows) and method (columns)."""
    from leas_jax.eval.tables import METHOD_LABELS

    methods = report["methods"]
    lines = [
        "| hole width (m) | " + " | ".join(METHOD_LABELS.get(m, m) for m in methods) + " |",
        "|---|" + "---|" * len(methods),
    ]
    for width in report["widths"]:
        cells = []
        for method in methods:
            row = next(r for r in report["rows"] if r["width"] == width and r["method"] == method)
            cells.append(f"{row['success']:.1f} / {row['coverage']:.1f} %")
        lines.append(f"| {width:g} | " + " | ".join(cells) + " |")
    lines.append("")
    lines.append(
        f"Success / mean coverage, {report['rows'][0]['n']} starts per width; the heightmap sees "
        f"{report['view_half_width']:g} m to either side of the root."
    )
    return "\n".join(lines) + "\n"


def sweep_figure(report: dict):
    """Success (solid) and mean coverage (dotted) against hole width, one colour per method."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from leas_jax.eval.tables import METHOD_LABELS

    figure, axes = plt.subplots(figsize=(6.4, 3.8), layout="constrained")
    for method in report["methods"]:
        chosen = sorted((r for r in report["rows"] if r["method"] == method), key=lambda r: r["width"])
        widths = np.array([r["width"] for r in chosen])
        (line,) = axes.plot(
            widths, [r["success"] for r in chosen], "o-", label=f"{METHOD_LABELS.get(method, method)} success"
        )
        axes.plot(
            widths,
            [r["coverage"] for r in chosen],
            ":",
            color=line.get_color(),
            label=f"{METHOD_LABELS.get(method, method)} coverage",
        )
    axes.axvline(2 * report["view_half_width"], color="grey", linestyle="--", linewidth=1)
    axes.text(
        2 * report["view_half_width"],
        50,
        " heightmap width",
        color="grey",
        fontsize=8,
        rotation=90,
        va="center",
    )
    axes.set_xlabel("hole width across the line to the target (m)")
    axes.set_ylabel("%")
    axes.set_ylim(-3, 103)
    axes.legend(fontsize=8)
    axes.set_title("eval_hole with other hole widths", fontsize=9)
    return figure


def write_outputs(out: Path, report: dict, results) -> None:
    """hole_sweep.json, hole_sweep.md, hole_sweep.png and hole_<width>m.png into `out`."""
    import matplotlib.pyplot as plt

    from leas_jax.eval.figures import scenario_figures

    out.mkdir(parents=True, exist_ok=True)
    (out / "hole_sweep.json").write_text(json.dumps(report, indent=1) + "\n")
    (out / "hole_sweep.md").write_text(markdown(report))
    figure = sweep_figure(report)
    figure.savefig(out / "hole_sweep.png", dpi=100)
    plt.close(figure)
    scenario_figures(results, out)
