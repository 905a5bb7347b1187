"""Read and validate terrain files (TOML, docs/design.md §4 terrain format v1; v2 adds
`[[mesh]]` and `[elevation]`, parsed by `leas_jax.terrain.sources`).

Every rejection is a TerrainError with one line naming the file, the key and the value:
`terrains/x.toml: box[3].size = [1.0, 0.0, 0.2]: every element must be > 0`.
Boxes are numbered from 0 in file order.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import tomllib

from leas_jax.terrain import sources
from leas_jax.terrain.model import Box, Scenario, Terrain, TerrainError, raster_shape

MAX_CELLS = 50_000_000  # docs/design.md §4: larger heightfields are rejected

TOP_KEYS = {"name", "bounds", "void_height", "resolution", "box", "scenario"} | sources.TOP_KEYS
TOP_REQUIRED = ("name", "bounds", "void_height", "resolution")
BOX_KEYS = {"center", "size", "rpy"}
BOX_REQUIRED = ("center", "size")
SCENARIO_KEYS = {"target", "start_region", "start_yaw_deg", "start_speed", "n_starts", "seed", "waypoints"}
SCENARIO_REQUIRED = ("target", "start_region", "start_yaw_deg", "start_speed", "n_starts", "seed")


def load_terrain(path) -> Terrain:
    """Read and validate a terrain file.

    Args:
        path: file path (str or Path).

    Returns:
        the Terrain, with `text` the file contents and `path` the given path.

    Raises:
        TerrainError: unreadable file or invalid contents (one line naming file, key, value).
    """
    path = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as err:
        raise TerrainError(f"{path}: cannot read terrain file: {err.strerror or err}") from None
    except UnicodeDecodeError as err:
        raise TerrainError(f"{path}: terrain file is not UTF-8 text: {err.reason}") from None
    return loads_terrain(text, source=path, path=path)


def loads_terrain(text: str, source: str = "<string>", path: str | None = None) -> Terrain:
    """Parse and validate terrain TOML text.

    Args:
        text: TOML text (docs/design.md §4).
        source: name used in error messages (usually the file path).
        path: stored as `Terrain.path`.

    Returns:
        the Terrain.

    Raises:
        TerrainError: invalid TOML or contents (one line naming source, key, value).
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise TerrainError(f"{source}: invalid TOML: {err}") from None
    check = _Checker(source)
    check.keys(data, "", TOP_KEYS, TOP_REQUIRED)

    name = data["name"]
    if not isinstance(name, str) or not name.strip():
        check.fail("name", name, "must be a non-empty string")
    bounds = check.array("bounds", data["bounds"], (2, 2))
    if bounds[0, 0] >= bounds[1, 0]:
        check.fail("bounds", data["bounds"], f"xmin ({bounds[0, 0]}) must be < xmax ({bounds[1, 0]})")
    if bounds[0, 1] >= bounds[1, 1]:
        check.fail("bounds", data["bounds"], f"ymin ({bounds[0, 1]}) must be < ymax ({bounds[1, 1]})")
    void_height = check.number("void_height", data["void_height"])
    resolution = check.number("resolution", data["resolution"])
    if resolution <= 0.0:
        check.fail("resolution", data["resolution"], "must be > 0")
    nx, ny = raster_shape(bounds, resolution)
    if nx * ny > MAX_CELLS:
        check.fail(
            "resolution",
            data["resolution"],
            f"heightfield of {nx} x {ny} = {nx * ny} cells over bounds {data['bounds']} "
            f"exceeds {MAX_CELLS} cells",
        )

    raw_boxes = data.get("box", [])
    if not isinstance(raw_boxes, list) or not all(isinstance(b, dict) for b in raw_boxes):
        check.fail("box", raw_boxes, "must be an array of tables ([[box]])")
    if not raw_boxes and not sources.has_geometry(data):
        if "box" not in data:
            raise TerrainError(
                f"{source}: box: missing required key in the top level (or [[mesh]], [elevation])"
            )
        check.fail("box", raw_boxes, "needs at least one [[box]]")
    boxes = tuple(_box(check, f"box[{k}]", raw) for k, raw in enumerate(raw_boxes))

    scenario = None
    if "scenario" in data:
        scenario = _scenario(check, data["scenario"], bounds)
    meshes, text = sources.load_sources(check, data, text, path)
    return Terrain(
        name=name,
        bounds=bounds,
        void_height=void_height,
        resolution=resolution,
        boxes=boxes,
        scenario=scenario,
        text=text,
        path=path,
        meshes=meshes,
    )


def _box(check: _Checker, key: str, raw: dict) -> Box:
    """Validate one [[box]] table."""
    check.keys(raw, key, BOX_KEYS, BOX_REQUIRED)
    center = check.array(f"{key}.center", raw["center"], (3,))
    size = check.array(f"{key}.size", raw["size"], (3,))
    if np.any(size <= 0.0):
        check.fail(f"{key}.size", raw["size"], "every element must be > 0")
    rpy = check.array(f"{key}.rpy", raw["rpy"], (3,)) if "rpy" in raw else np.zeros(3)
    return Box(center=center, size=size, rpy=rpy)


def _scenario(check: _Checker, raw, bounds: np.ndarray) -> Scenario:
    """Validate the [scenario] table; positions must lie within the terrain bounds."""
    if not isinstance(raw, dict):
        check.fail("scenario", raw, "must be a table ([scenario])")
    check.keys(raw, "scenario", SCENARIO_KEYS, SCENARIO_REQUIRED)
    target = check.array("scenario.target", raw["target"], (2,))
    region = check.array("scenario.start_region", raw["start_region"], (2, 2))
    yaw = check.array("scenario.start_yaw_deg", raw["start_yaw_deg"], (2,))
    speed = check.array("scenario.start_speed", raw["start_speed"], (2,))
    for key, pair, what in (
        ("scenario.start_region", region[:, 0], "x"),
        ("scenario.start_region", region[:, 1], "y"),
        ("scenario.start_yaw_deg", yaw, "value"),
        ("scenario.start_speed", speed, "value"),
    ):
        if pair[0] > pair[1]:
            check.fail(
                key, raw[key.split(".")[1]], f"minimum {what} ({pair[0]}) must be <= maximum ({pair[1]})"
            )
    if speed[0] < 0.0:
        check.fail("scenario.start_speed", raw["start_speed"], "speeds must be >= 0")
    n_starts = check.integer("scenario.n_starts", raw["n_starts"])
    if n_starts <= 0:
        check.fail("scenario.n_starts", raw["n_starts"], "must be > 0")
    seed = check.integer("scenario.seed", raw["seed"])
    if seed < 0:
        check.fail("scenario.seed", raw["seed"], "must be >= 0")
    waypoints = None
    if "waypoints" in raw:
        waypoints = check.array("scenario.waypoints", raw["waypoints"], (-1, 2))
        if len(waypoints) == 0:
            check.fail("scenario.waypoints", raw["waypoints"], "must hold at least one [x, y] point")
    points = [
        ("scenario.target", raw["target"], target[None]),
        ("scenario.start_region", raw["start_region"], region),
    ]
    if waypoints is not None:
        points.append(("scenario.waypoints", raw["waypoints"], waypoints))
    for key, value, xy in points:
        if np.any(xy < bounds[0]) or np.any(xy > bounds[1]):
            check.fail(key, value, f"lies outside the terrain bounds {bounds.tolist()}")
    return Scenario(
        target=target,
        start_region=region,
        start_yaw_deg=yaw,
        start_speed=speed,
        n_starts=n_starts,
        seed=seed,
        waypoints=waypoints,
    )


class _Checker:
    """Type checks that raise TerrainError naming the source, the key and the value."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, key: str, value, problem: str):
        """Raise TerrainError('<source>: <key> = <value>: <problem>')."""
        raise TerrainError(f"{self.source}: {key} = {_show(value)}: {problem}")

    def keys(self, table: dict, prefix: str, allowed: set, required: tuple):
        """Reject unknown keys, then missing ones, of a table (`prefix` names it, '' = top level)."""
        where = f"table {prefix}" if prefix else "the top level"
        for key in table:
            if key not in allowed:
                full = f"{prefix}.{key}" if prefix else key
                self.fail(full, table[key], f"unknown key in {where} (allowed: {', '.join(sorted(allowed))})")
        for key in required:
            if key not in table:
                full = f"{prefix}.{key}" if prefix else key
                raise TerrainError(f"{self.source}: {full}: missing required key in {where}")

    def number(self, key: str, value) -> float:
        """A finite float (TOML integers accepted; booleans are not numbers)."""
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(key, value, f"must be a number, not {_toml_type(value)}")
        if not math.isfinite(value):
            self.fail(key, value, "must be finite (no nan or inf)")
        return float(value)

    def integer(self, key: str, value) -> int:
        """A TOML integer."""
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(key, value, f"must be an integer, not {_toml_type(value)}")
        return int(value)

    def array(self, key: str, value, shape: tuple[int, ...]) -> np.ndarray:
        """A nested array of finite numbers of the given shape (-1: any length >= 0)."""

        def walk(item, dims, index):
            if not dims:
                if isinstance(item, bool) or not isinstance(item, (int, float)):
                    self.fail(key, value, f"element {index} must be a number, not {_toml_type(item)}")
                if not math.isfinite(item):
                    self.fail(key, value, f"element {index} must be finite (no nan or inf)")
                return float(item)
            if not isinstance(item, list):
                self.fail(key, value, f"must be an array of shape {_shape_text(shape)}")
            if dims[0] != -1 and len(item) != dims[0]:
                self.fail(key, value, f"must be an array of shape {_shape_text(shape)}")
            return [walk(sub, dims[1:], index + [k]) for k, sub in enumerate(item)]

        nested = walk(value, list(shape), [])
        return np.array(nested, dtype=np.float64).reshape([len(nested)] + [d for d in shape[1:]])


def _shape_text(shape) -> str:
    return "[" + ", ".join("N" if d == -1 else str(d) for d in shape) + "]"


def _toml_type(value) -> str:
    """TOML name of a parsed value's type, for messages."""
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, int):
        return "an integer"
    if isinstance(value, float):
        return "a float"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    return f"a {type(value).__name__}"


def _show(value) -> str:
    """Short TOML-like rendering of a value for messages."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, dict):
        text = "{" + ", ".join(f"{k} = {_show(v)}" for k, v in value.items()) + "}"
    elif isinstance(value, list):
        text = "[" + ", ".join(_show(v) for v in value) + "]"
    else:
        text = str(value)
    return text if len(text) <= 120 else text[:117] + "..."
