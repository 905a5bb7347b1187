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

from leas_jax.env.config import EnvConfig
from leas_jax.terrain import sources
from leas_jax.terrain.model import Box, Curriculum, Scenario, Terrain, TerrainError

MAX_CELLS = 50_000_000  # docs/design.md §4: larger heightfields are rejected

# Size and value bounds (validation helpers below enforce them; each names file, key and value).
# They keep every later computation finite and bounded in time and memory; the committed
# terrains are far inside them (the training arena: 545 boxes, 20 x 20 m).
MAX_TEXT_CHARS = 4_000_000  # a terrain file at MAX_BOXES boxes is ~0.5 MB
MAX_NESTING = 16  # arrays / tables inside each other (terrain format v1 needs 4); tomllib itself
# recurses on nesting and hits the interpreter's limit past ~330 levels
MAX_COORDINATE = 1.0e4  # m: |bounds|, |box centre|, box sizes, |heights|, scenario points
MAX_ANGLE = 4.0 * math.pi  # rad: |rpy| (two turns either way)
MAX_BOXES = 4096  # 4096 boxes of the training arena's sizes rasterise in 0.8 s (545 boxes: 0.11 s)
MIN_RASTER_POINTS = 2  # per axis: a raster of one point has no extent
MAX_STARTS = 10_000  # scenario.n_starts (the paper draws 60 per cell)
MAX_WAYPOINTS = 1_000
MAX_SEED = 2**63 - 1
MAX_YAW_DEG = 360.0  # |start_yaw_deg|, and the range spans at most one turn
# Speeds a scenario may start at: the env's bound on the root speed (EnvConfig.v_max).
MAX_START_SPEED = EnvConfig().v_max

TOP_KEYS = {"name", "bounds", "void_height", "resolution", "box", "scenario", "curriculum"} | sources.TOP_KEYS
CURRICULUM_KEYS = {"levels", "tile", "families"}
MAX_LEVELS = 100
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
    if len(text) > MAX_TEXT_CHARS:
        raise TerrainError(f"{source}: terrain file of {len(text)} characters exceeds {MAX_TEXT_CHARS}")
    data = parse_toml(text, source)
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
    check_raster(check, bounds, resolution, data)

    raw_boxes = data.get("box", [])
    if not isinstance(raw_boxes, list) or not all(isinstance(b, dict) for b in raw_boxes):
        check.fail("box", raw_boxes, "must be an array of tables ([[box]])")
    if not raw_boxes and not sources.has_geometry(data):
        if "box" not in data:
            raise TerrainError(
                f"{source}: box: missing required key in the top level (or [[mesh]], [elevation])"
            )
        check.fail("box", raw_boxes, "needs at least one [[box]]")
    if len(raw_boxes) > MAX_BOXES:
        raise TerrainError(f"{source}: box: {len(raw_boxes)} boxes exceed the bound of {MAX_BOXES}")
    boxes = tuple(_box(check, f"box[{k}]", raw) for k, raw in enumerate(raw_boxes))
    meshes, text = sources.load_sources(check, data, text, path)
    solids = boxes + meshes  # both have aabb() and column_top(x, y)
    lowest_top = min(float(solid.aabb()[1, 2]) for solid in solids)
    if void_height >= lowest_top:
        check.fail(
            "void_height",
            data["void_height"],
            f"must lie below the terrain: box tops start at z = {lowest_top:g} (the void is where no box is)",
        )

    scenario = None
    if "scenario" in data:
        scenario = _scenario(check, data["scenario"], bounds)
        check_scenario_ground(check, data["scenario"], scenario, solids, void_height)
    curriculum = _curriculum(check, data["curriculum"], bounds) if "curriculum" in data else None
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
        curriculum=curriculum,
    )


def _curriculum(check: _Checker, raw, bounds: np.ndarray) -> Curriculum:
    """Validate the [curriculum] table: its rows and columns of tiles lie within the bounds."""
    if not isinstance(raw, dict):
        check.fail("curriculum", raw, "must be a table ([curriculum])")
    check.keys(raw, "curriculum", CURRICULUM_KEYS, tuple(sorted(CURRICULUM_KEYS)))
    levels = check.integer("curriculum.levels", raw["levels"], 1, MAX_LEVELS)
    tile = check.array("curriculum.tile", raw["tile"], (2,))
    if np.any(tile <= 0.0):
        check.fail("curriculum.tile", raw["tile"], "both sides must be > 0")
    families = raw["families"]
    if not isinstance(families, list) or not families or not all(isinstance(f, str) for f in families):
        check.fail("curriculum.families", families, "must be a non-empty array of family names")
    extent = bounds[1] - bounds[0]
    needed = np.array([levels * tile[0], len(families) * tile[1]])
    if np.any(needed > extent + 1e-6):
        check.fail(
            "curriculum",
            raw,
            f"{levels} rows x {len(families)} columns of {tile[0]:g} x {tile[1]:g} m tiles exceed the bounds' "
            f"{extent[0]:g} x {extent[1]:g} m",
        )
    return Curriculum(levels=levels, tile=(float(tile[0]), float(tile[1])), families=tuple(families))


def parse_toml(text: str, source: str) -> dict:
    """tomllib.loads with every failure a TerrainError, and nesting bounded by MAX_NESTING.

    tomllib recurses once per nesting level, so a deeply nested file raises
    RecursionError inside it; a shallower one still too deep for the format is
    caught by an iterative depth count before any recursive check walks it.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise TerrainError(f"{source}: invalid TOML: {err}") from None
    except RecursionError:
        raise TerrainError(f"{source}: invalid TOML: arrays or tables nested too deeply") from None
    except ValueError as err:  # e.g. an integer past Python's int-from-text digit limit
        raise TerrainError(f"{source}: invalid TOML: {err}") from None
    depth = nesting_depth(data)
    if depth > MAX_NESTING:
        raise TerrainError(f"{source}: arrays or tables nested {depth} deep (at most {MAX_NESTING})")
    return data


def nesting_depth(value) -> int:
    """Deepest nesting of lists and dicts in a parsed TOML value (iterative: any depth is safe)."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            item = list(item.values())
        elif not isinstance(item, list):
            continue
        deepest = max(deepest, depth + 1)
        stack.extend((sub, depth + 1) for sub in item)
    return deepest


def check_raster(check: _Checker, bounds: np.ndarray, resolution: float, data: dict) -> None:
    """The raster of `bounds` at `resolution` has MIN_RASTER_POINTS to MAX_CELLS points (checked in floats,
    before any integer conversion can overflow)."""
    extent = bounds[1] - bounds[0]
    with np.errstate(over="ignore"):
        points = extent / resolution + 1.0
    if not np.all(np.isfinite(points)) or float(points[0]) * float(points[1]) > MAX_CELLS:
        check.fail(
            "resolution",
            data["resolution"],
            f"heightfield of {points[0]:.4g} x {points[1]:.4g} cells over bounds {_show(data['bounds'])} "
            f"exceeds {MAX_CELLS} cells",
        )
    if np.any(points < MIN_RASTER_POINTS + 0.5):
        check.fail(
            "resolution",
            data["resolution"],
            f"gives a heightfield of {points[0]:.3g} x {points[1]:.3g} points over bounds "
            f"{_show(data['bounds'])}: at least {MIN_RASTER_POINTS} per axis are needed",
        )


def _box(check: _Checker, key: str, raw: dict) -> Box:
    """Validate one [[box]] table."""
    check.keys(raw, key, BOX_KEYS, BOX_REQUIRED)
    center = check.array(f"{key}.center", raw["center"], (3,))
    size = check.array(f"{key}.size", raw["size"], (3,))
    if np.any(size <= 0.0):
        check.fail(f"{key}.size", raw["size"], "every element must be > 0")
    rpy = check.array(f"{key}.rpy", raw["rpy"], (3,), bound=MAX_ANGLE) if "rpy" in raw else np.zeros(3)
    return Box(center=center, size=size, rpy=rpy)


def _scenario(check: _Checker, raw, bounds: np.ndarray) -> Scenario:
    """Validate the [scenario] table; positions must lie within the terrain bounds."""
    if not isinstance(raw, dict):
        check.fail("scenario", raw, "must be a table ([scenario])")
    check.keys(raw, "scenario", SCENARIO_KEYS, SCENARIO_REQUIRED)
    target = check.array("scenario.target", raw["target"], (2,))
    region = check.array("scenario.start_region", raw["start_region"], (2, 2))
    yaw = check.array("scenario.start_yaw_deg", raw["start_yaw_deg"], (2,), bound=MAX_YAW_DEG)
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
    if yaw[1] - yaw[0] > MAX_YAW_DEG:
        check.fail("scenario.start_yaw_deg", raw["start_yaw_deg"], f"spans more than {MAX_YAW_DEG:g} deg")
    if speed[0] < 0.0 or speed[1] > MAX_START_SPEED:
        check.fail(
            "scenario.start_speed",
            raw["start_speed"],
            f"speeds must lie in [0, {MAX_START_SPEED:g}] m/s (the env's v_max)",
        )
    n_starts = check.integer("scenario.n_starts", raw["n_starts"], 1, MAX_STARTS)
    seed = check.integer("scenario.seed", raw["seed"], 0, MAX_SEED)
    waypoints = None
    if "waypoints" in raw:
        waypoints = check.array("scenario.waypoints", raw["waypoints"], (-1, 2), max_length=MAX_WAYPOINTS)
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


# Points of the start region tested for ground under them (a GROUND_SAMPLES x GROUND_SAMPLES grid).
GROUND_SAMPLES = 5


def ground_height(boxes, xy: np.ndarray) -> np.ndarray:
    """[N] highest box point on the vertical lines through xy [N, 2] (-inf over the void), world, m."""
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    top = np.full(len(xy), -np.inf)
    for box in boxes:
        top = np.maximum(top, box.column_top(xy[:, 0], xy[:, 1]))
    return top


def check_scenario_ground(check: _Checker, raw: dict, scenario: Scenario, boxes, void_height: float) -> None:
    """The target, the waypoints and part of the start region stand over a box, not over the void.

    Whether the robot fits there (no wall, pillar or ceiling in the way) depends on
    the env's reachability condition: `leas_jax.eval.scenarios.check_scenario` tests that.
    """
    for key, xy in (("target", scenario.target[None]), ("waypoints", scenario.waypoints)):
        if xy is None:
            continue
        height = ground_height(boxes, xy)
        if np.any(height <= void_height):
            k = int(np.argmax(height <= void_height))
            where = "" if key == "target" else f" (point {k})"
            check.fail(f"scenario.{key}", raw[key], f"lies over the void, on no box{where}")
    lo, hi = scenario.start_region
    u = np.linspace(0.0, 1.0, GROUND_SAMPLES)
    grid = np.stack(np.meshgrid(lo[0] + u * (hi[0] - lo[0]), lo[1] + u * (hi[1] - lo[1])), -1).reshape(-1, 2)
    if np.all(ground_height(boxes, grid) <= void_height):
        check.fail("scenario.start_region", raw["start_region"], "lies over the void, on no box")


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

    def number(self, key: str, value, lo: float = -MAX_COORDINATE, hi: float = MAX_COORDINATE) -> float:
        """A finite float in [lo, hi] (TOML integers accepted; booleans are not numbers)."""
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(key, value, f"must be a number, not {_toml_type(value)}")
        if isinstance(value, float) and not math.isfinite(value):
            self.fail(key, value, "must be finite (no nan or inf)")
        if not lo <= value <= hi:  # compared before float(): a 400-digit integer stays an int here
            self.fail(key, value, f"must lie in [{lo:g}, {hi:g}]")
        return float(value)

    def integer(self, key: str, value, lo: int, hi: int) -> int:
        """A TOML integer in [lo, hi]."""
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(key, value, f"must be an integer, not {_toml_type(value)}")
        if not lo <= value <= hi:
            self.fail(key, value, f"must lie in [{lo}, {hi}]")
        return int(value)

    def array(
        self,
        key: str,
        value,
        shape: tuple[int, ...],
        bound: float = MAX_COORDINATE,
        max_length: int | None = None,
    ) -> np.ndarray:
        """A nested array of finite numbers in [-bound, bound] of the given shape (-1: any length >= 0,
        at most `max_length`)."""

        def element(item, index) -> float:
            if isinstance(item, bool) or not isinstance(item, (int, float)):
                self.fail(key, value, f"element {index} must be a number, not {_toml_type(item)}")
            if isinstance(item, float) and not math.isfinite(item):
                self.fail(key, value, f"element {index} must be finite (no nan or inf)")
            if not -bound <= item <= bound:
                self.fail(key, value, f"element {index} must lie in [{-bound:g}, {bound:g}]")
            return float(item)

        def walk(item, dims, index):
            if not dims:
                return element(item, index)
            if not isinstance(item, list):
                self.fail(key, value, f"must be an array of shape {_shape_text(shape)}")
            if dims[0] != -1 and len(item) != dims[0]:
                self.fail(key, value, f"must be an array of shape {_shape_text(shape)}")
            if dims[0] == -1 and max_length is not None and len(item) > max_length:
                self.fail(key, value, f"holds {len(item)} entries, at most {max_length}")
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
        # control characters escaped, so that a message stays on one line
        text = value[:200].encode("unicode_escape").decode("ascii").replace('"', '\\"')
        return _clip('"' + text + '"')
    if isinstance(value, dict):
        text = "{" + ", ".join(f"{k} = {_show(v)}" for k, v in value.items()) + "}"
    elif isinstance(value, list):
        text = "[" + ", ".join(_show(v) for v in value) + "]"
    elif isinstance(value, int) and abs(value) >= 10**30:  # str() of a huge int is slow or refused
        text = f"an integer of about {int(abs(value).bit_length() * math.log10(2)) + 1} digits"
    else:
        text = str(value).encode("unicode_escape").decode("ascii")
    return _clip(text)


def _clip(text: str) -> str:
    return text if len(text) <= 120 else text[:117] + "..."
