"""Top-down pictures of terrains, scenarios and guides: the one heightmap renderer of the package.

Host-only (matplotlib). Every figure that shows a terrain from above draws it with
`draw_heightmap`: `leas terrain show` (`terrain_figure`), rollout and report plots
(`plot_paths`), the evaluation figures (`leas_jax.eval.figures`), `leas arena-check` and the
contact plan's footsteps (`leas_jax.contacts.viewer.write_footsteps_png`). Figures made
here use their own Agg canvas and leave pyplot's global state alone.

World frame: x to the right, y up; `Terrain.raster()[i, j]` is the height at
(xmin + i res, ymin + j res), shown transposed so that rows are y.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class HeightmapStyle:
    """How heights become colours.

    Attributes:
        cmap: matplotlib colormap name.
        void: colour of void cells (holes), drawn apart so that they stand out from low
            ground: with the void 2 m below the ground a shared scale would flatten the relief.
        limits: (lowest, highest) solid height (m) -> (vmin, vmax) of the colour scale.
    """

    cmap: str
    void: str
    limits: Callable[[float, float], tuple[float, float]]


STYLES = {
    # Behind dots and guides (evaluation figures): light greys, void dark grey.
    "backdrop": HeightmapStyle("Greys", "#303030", lambda low, high: (low - 0.3, high + 1.0)),
    # Under coloured footprints: mid greys keep the relief readable, void dark blue.
    "footsteps": HeightmapStyle(
        "gray", "#0b1a33", lambda low, high: (low - 0.25 - 0.5 * (high - low), high + 0.05)
    ),
    # The terrain alone (`leas terrain show`): colour by height over the full range.
    "relief": HeightmapStyle("viridis", "#202020", lambda low, high: (low, high)),
}


def draw_heightmap(axes, terrain, style: str = "backdrop"):
    """Draw a terrain's heightmap from above into `axes`, limits and aspect set to its bounds.

    Args:
        axes: matplotlib Axes.
        terrain: a `leas_jax.terrain.Terrain`.
        style: a key of `STYLES`.

    Returns:
        the AxesImage (for a colorbar).
    """
    import matplotlib

    look = STYLES[style]
    heights = np.asarray(terrain.raster(), np.float64)
    (xmin, ymin), (xmax, ymax) = terrain.bounds
    half = terrain.resolution / 2
    void = heights <= terrain.void_height + 1e-6
    solid = heights[~void]
    low, high = (float(solid.min()), float(solid.max())) if solid.size else (0.0, 1.0)
    vmin, vmax = look.limits(low, high)
    image = axes.imshow(
        np.ma.masked_array(heights, void).T,
        origin="lower",
        extent=(xmin - half, xmax + half, ymin - half, ymax + half),
        cmap=matplotlib.colormaps[look.cmap].with_extremes(bad=look.void),
        vmin=vmin,
        vmax=vmax,
        interpolation="nearest",
    )
    axes.set_xlim(xmin, xmax)
    axes.set_ylim(ymin, ymax)
    axes.set_aspect("equal")
    return image


def agg_figure(width: float, height: float, **kwargs):
    """A matplotlib Figure (inches) on its own Agg canvas, outside pyplot. kwargs: of Figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), **kwargs)
    FigureCanvasAgg(figure)
    return figure


def draw_scenario(axes, scenario) -> None:
    """A terrain's scenario into `axes`: start region (dashed rectangle), waypoints (numbered
    dots), the route through them (dotted) and the target (star)."""
    from matplotlib.patches import Rectangle

    (rx0, ry0), (rx1, ry1) = scenario.start_region
    axes.add_patch(
        Rectangle(
            (rx0, ry0),
            rx1 - rx0,
            ry1 - ry0,
            fill=False,
            edgecolor="red",
            linestyle="--",
            linewidth=1.5,
            label="start region",
        )
    )
    route = [np.mean(scenario.start_region, axis=0)]
    if scenario.waypoints is not None:
        route += list(scenario.waypoints)
        axes.plot(
            scenario.waypoints[:, 0],
            scenario.waypoints[:, 1],
            "o",
            color="gold",
            markeredgecolor="black",
            label="waypoints",
        )
        for k, (wx, wy) in enumerate(scenario.waypoints):
            axes.annotate(str(k + 1), (wx, wy), textcoords="offset points", xytext=(4, 4), fontsize=8)
    route.append(scenario.target)
    route = np.array(route)
    axes.plot(route[:, 0], route[:, 1], ":", color="black", linewidth=1)
    axes.plot(*scenario.target, "*", color="red", markersize=14, markeredgecolor="black", label="target")
    axes.legend(loc="upper right", fontsize=8)


def terrain_figure(terrain):
    """Figure of a terrain from above, coloured by height, with its scenario if it has one.

    Returns:
        matplotlib Figure on an Agg canvas (the caller saves it).
    """
    (xmin, ymin), (xmax, ymax) = terrain.bounds
    width = 8.0
    figure = agg_figure(width, max(3.0, width * (ymax - ymin) / (xmax - xmin)), layout="constrained")
    axes = figure.add_subplot(1, 1, 1)
    image = draw_heightmap(axes, terrain, "relief")
    figure.colorbar(
        image, ax=axes, label=f"height (m); void (z = {terrain.void_height:g}) in black", shrink=0.9
    )
    if terrain.scenario is not None:
        draw_scenario(axes, terrain.scenario)
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    meshes = len(terrain.meshes)
    parts = [f"{len(terrain.boxes)} boxes"] + (
        [f"{meshes} mesh{'es' if meshes > 1 else ''}"] if meshes else []
    )
    axes.set_title(f"{terrain.name}: {', '.join(parts)}, resolution {terrain.resolution:g} m")
    return figure


def plot_paths(terrain, paths, path: Path, title: str = "", colors=None, target=None) -> None:
    """Top-down PNG of guide paths over the terrain (`terrain_figure`): each path a line, its
    start a dot with its heading as an arrow.

    Args:
        terrain: the terrain (drawn with its scenario).
        paths: list of [T, 4] guides (x, y, z, yaw), world.
        path: PNG file (its folder is made).
        title: replaces the terrain's title if given.
        colors: one matplotlib colour per path (default blue).
        target: optional (x, y) drawn as a star.
    """
    figure = terrain_figure(terrain)
    axes = figure.axes[0]
    for k, guide in enumerate(paths):
        color = colors[k] if colors is not None else "tab:blue"
        axes.plot(guide[:, 0], guide[:, 1], "-", color=color, linewidth=1.2)
        axes.plot(guide[0, 0], guide[0, 1], "o", color=color, markersize=4)
        axes.arrow(
            guide[0, 0],
            guide[0, 1],
            0.3 * np.cos(guide[0, 3]),
            0.3 * np.sin(guide[0, 3]),
            width=0.02,
            color="black",
        )
    if target is not None:
        axes.plot(*target, "*", color="red", markersize=14, markeredgecolor="black")
    if title:
        axes.set_title(title)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)
