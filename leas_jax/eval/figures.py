"""Figures in the style of the paper's Figs. 6-9 (host, matplotlib Agg).

One PNG per scenario, one panel per (cell, method): the terrain heightmap
(void in black), each start as a dot coloured by outcome (blue: success,
yellow: failure, paper Fig. 6), its initial orientation as a black arrow, the
part of each guide the contact plan covers in blue and the failed rest in
red, waypoints in black (RRT) or gold (manual circuit), the target as a star.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from leas_jax.eval.tables import METHOD_LABELS
from leas_jax.plotting import draw_heightmap

SUCCESS_COLOR = "tab:blue"
FAILURE_COLOR = "gold"
FAILED_PART_COLOR = "red"


def draw_trajectories(axes, terrain, trajectories, title: str = "") -> None:
    """Guides, start dots, orientation arrows and waypoints of trajectories into `axes` (see module docstring)."""
    draw_heightmap(axes, terrain)
    scenario = terrain.scenario
    for t in trajectories:
        o = t.outcome
        if t.guide is not None:
            last = len(t.guide) - 1 if o is None else max(o.last_valid_index, 0)
            axes.plot(t.guide[: last + 1, 0], t.guide[: last + 1, 1], "-", color=SUCCESS_COLOR, linewidth=0.8)
            if last < len(t.guide) - 1:
                axes.plot(t.guide[last:, 0], t.guide[last:, 1], "-", color=FAILED_PART_COLOR, linewidth=0.8)
        if t.waypoints is not None and t.method in ("rbkino_rrt", "leas_rrt", "navigate"):
            w = np.asarray(t.waypoints)
            axes.plot(w[:, 0], w[:, 1], ".", color="black", markersize=3)
        color = SUCCESS_COLOR if (o is not None and o.success) else FAILURE_COLOR
        axes.plot(t.start[0], t.start[1], "o", color=color, markeredgecolor="black", markersize=4, zorder=5)
        axes.arrow(
            t.start[0],
            t.start[1],
            0.25 * np.cos(t.start[3]),
            0.25 * np.sin(t.start[3]),
            width=0.015,
            color="black",
            zorder=6,
        )
    if scenario is not None:
        if scenario.waypoints is not None:
            w = np.asarray(scenario.waypoints)
            axes.plot(w[:, 0], w[:, 1], "o", color="gold", markeredgecolor="black", markersize=6, zorder=4)
        axes.plot(*scenario.target, "*", color="red", markeredgecolor="black", markersize=12, zorder=7)
    if title:
        axes.set_title(title, fontsize=9)


def scenario_figure(result):
    """Figure of one `ScenarioResult`: rows = cells, columns = methods. Returns a matplotlib Figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cells, methods = result.cells, result.methods
    # Table II's nine cells share a terrain: group them by yaw range (rows), speeds overlaid.
    groups = {}
    for k, cell in enumerate(cells):
        groups.setdefault(tuple(cell.yaw_deg), []).append(k)
    (xmin, ymin), (xmax, ymax) = result.terrain.bounds
    width = 4.2
    height = width * (ymax - ymin) / (xmax - xmin) + 0.5
    figure, axes = plt.subplots(
        len(groups),
        len(methods),
        figsize=(width * len(methods), height * len(groups)),
        squeeze=False,
        layout="constrained",
    )
    for row, (yaw, members) in enumerate(groups.items()):
        for col, method in enumerate(methods):
            chosen = [t for t in result.trajectories if t.method == method and t.cell in members]
            n = len(chosen)
            coverage = 100 * np.mean([t.outcome.coverage for t in chosen]) if n else float("nan")
            success = sum(t.outcome.success for t in chosen)
            title = (
                f"{METHOD_LABELS.get(method, method)}, yaw {yaw[0]:g}..{yaw[1]:g} deg\n"
                f"coverage {coverage:.1f}%, success {success}/{n}"
            )
            draw_trajectories(axes[row][col], result.terrain, chosen, title)
    figure.suptitle(
        f"{result.name}: blue dot success, yellow dot failure; blue path covered by the contact plan, "
        "red failed part",
        fontsize=9,
    )
    return figure


def scenario_figures(results, out: Path) -> list[Path]:
    """Write `<out>/<scenario>.png` for every scenario; returns the paths."""
    import matplotlib.pyplot as plt

    paths = []
    for result in results:
        figure = scenario_figure(result)
        path = Path(out) / f"{result.name}.png"
        figure.savefig(path, dpi=90)
        plt.close(figure)
        paths.append(path)
    return paths
