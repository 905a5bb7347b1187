"""Terrain file loading and validation (docs/design.md §4): every rejection names file, key and value."""

import math

import numpy as np
import pytest

from leas_jax.errors import LeasError
from leas_jax.terrain import Box, Scenario, Terrain, TerrainError, load_terrain, loads_terrain
from leas_jax.terrain.loader import MAX_CELLS

SOURCE = "unit.toml"

BASE = """\
name = "unit"
bounds = [[0.0, 0.0], [4.0, 3.0]]
void_height = -2.0
resolution = 0.05

[[box]]
center = [2.0, 1.5, -0.1]
size = [4.0, 3.0, 0.2]
rpy = [0.0, 0.0, 0.0]

[[box]]
center = [1.0, 1.0, 0.05]
size = [0.5, 0.5, 0.1]

[scenario]
target = [3.5, 1.5]
start_region = [[0.5, 1.0], [1.0, 2.0]]
start_yaw_deg = [-30.0, 30.0]
start_speed = [0.0, 0.07]
n_starts = 5
seed = 0
waypoints = [[2.0, 1.5]]
"""


def test_base_loads_with_every_field():
    terrain = loads_terrain(BASE, SOURCE)
    assert isinstance(terrain, Terrain)
    assert terrain.name == "unit"
    np.testing.assert_array_equal(terrain.bounds, [[0.0, 0.0], [4.0, 3.0]])
    assert terrain.void_height == -2.0 and terrain.resolution == 0.05
    assert terrain.boxes == (Box([2.0, 1.5, -0.1], [4.0, 3.0, 0.2]), Box([1.0, 1.0, 0.05], [0.5, 0.5, 0.1]))
    np.testing.assert_array_equal(terrain.boxes[1].rpy, [0.0, 0.0, 0.0])  # rpy is optional
    scenario = terrain.scenario
    assert isinstance(scenario, Scenario)
    np.testing.assert_array_equal(scenario.target, [3.5, 1.5])
    np.testing.assert_array_equal(scenario.start_region, [[0.5, 1.0], [1.0, 2.0]])
    np.testing.assert_array_equal(scenario.start_yaw_deg, [-30.0, 30.0])
    np.testing.assert_array_equal(scenario.start_speed, [0.0, 0.07])
    assert (scenario.n_starts, scenario.seed) == (5, 0)
    np.testing.assert_array_equal(scenario.waypoints, [[2.0, 1.5]])
    assert terrain.text == BASE and terrain.path is None
    # 4 m / 0.05 + 1 = 81 points along x, 3 m / 0.05 + 1 = 61 along y
    assert terrain.shape == (81, 61)


def test_optional_parts_may_be_left_out():
    text = BASE.replace("rpy = [0.0, 0.0, 0.0]\n", "").replace("waypoints = [[2.0, 1.5]]\n", "")
    terrain = loads_terrain(text, SOURCE)
    assert terrain.scenario.waypoints is None
    no_scenario = loads_terrain(text[: text.index("[scenario]")], SOURCE)
    assert no_scenario.scenario is None


def test_integers_are_accepted_for_floats():
    terrain = loads_terrain(BASE.replace("void_height = -2.0", "void_height = -2"), SOURCE)
    assert terrain.void_height == -2.0 and isinstance(terrain.void_height, float)


def test_arrays_are_read_only():
    terrain = loads_terrain(BASE, SOURCE)
    with pytest.raises(ValueError):
        terrain.boxes[0].center[0] = 1.0
    with pytest.raises(ValueError):
        terrain.bounds[0, 0] = 1.0


# (text to replace in BASE, replacement, key the message must name, value it must show)
REJECTIONS = {
    # missing keys
    "missing name": ('name = "unit"\n', "", "name", None),
    "missing bounds": ("bounds = [[0.0, 0.0], [4.0, 3.0]]\n", "", "bounds", None),
    "missing void_height": ("void_height = -2.0\n", "", "void_height", None),
    "missing resolution": ("resolution = 0.05\n", "", "resolution", None),
    "missing box center": ("center = [1.0, 1.0, 0.05]\n", "", "box[1].center", None),
    "missing box size": ("size = [4.0, 3.0, 0.2]\n", "", "box[0].size", None),
    "missing scenario target": ("target = [3.5, 1.5]\n", "", "scenario.target", None),
    "missing scenario seed": ("seed = 0\n", "", "scenario.seed", None),
    "missing scenario n_starts": ("n_starts = 5\n", "", "scenario.n_starts", None),
    # wrong types
    "name not a string": ('name = "unit"', "name = 3", "name", "3"),
    "empty name": ('name = "unit"', 'name = ""', "name", '""'),
    "bounds a string": ("bounds = [[0.0, 0.0], [4.0, 3.0]]", 'bounds = "big"', "bounds", '"big"'),
    "bounds wrong shape": (
        "bounds = [[0.0, 0.0], [4.0, 3.0]]",
        "bounds = [0.0, 0.0, 4.0, 3.0]",
        "bounds",
        "[0.0, 0.0, 4.0, 3.0]",
    ),
    "void_height a string": ("void_height = -2.0", 'void_height = "low"', "void_height", '"low"'),
    "resolution a boolean": ("resolution = 0.05", "resolution = true", "resolution", "true"),
    "center of two numbers": (
        "center = [1.0, 1.0, 0.05]",
        "center = [1.0, 1.0]",
        "box[1].center",
        "[1.0, 1.0]",
    ),
    "size with a string": (
        "size = [0.5, 0.5, 0.1]",
        'size = [0.5, "a", 0.1]',
        "box[1].size",
        '[0.5, "a", 0.1]',
    ),
    "rpy a number": ("rpy = [0.0, 0.0, 0.0]", "rpy = 0.0", "box[0].rpy", "0.0"),
    "n_starts a float": ("n_starts = 5", "n_starts = 5.0", "scenario.n_starts", "5.0"),
    "seed a string": ("seed = 0", 'seed = "0"', "scenario.seed", '"0"'),
    "waypoints of three numbers": (
        "waypoints = [[2.0, 1.5]]",
        "waypoints = [[2.0, 1.5, 0.0]]",
        "scenario.waypoints",
        "[[2.0, 1.5, 0.0]]",
    ),
    # non-positive sizes or resolution
    "zero resolution": ("resolution = 0.05", "resolution = 0.0", "resolution", "0.0"),
    "negative resolution": ("resolution = 0.05", "resolution = -0.05", "resolution", "-0.05"),
    "zero size": ("size = [0.5, 0.5, 0.1]", "size = [0.5, 0.0, 0.1]", "box[1].size", "[0.5, 0.0, 0.1]"),
    "negative size": ("size = [4.0, 3.0, 0.2]", "size = [4.0, 3.0, -0.2]", "box[0].size", "[4.0, 3.0, -0.2]"),
    # bounds order
    "xmin == xmax": (
        "bounds = [[0.0, 0.0], [4.0, 3.0]]",
        "bounds = [[4.0, 0.0], [4.0, 3.0]]",
        "bounds",
        "[[4.0, 0.0], [4.0, 3.0]]",
    ),
    "xmin > xmax": (
        "bounds = [[0.0, 0.0], [4.0, 3.0]]",
        "bounds = [[5.0, 0.0], [4.0, 3.0]]",
        "bounds",
        "[[5.0, 0.0], [4.0, 3.0]]",
    ),
    "ymin > ymax": (
        "bounds = [[0.0, 0.0], [4.0, 3.0]]",
        "bounds = [[0.0, 3.5], [4.0, 3.0]]",
        "bounds",
        "[[0.0, 3.5], [4.0, 3.0]]",
    ),
    # NaN / inf
    "nan void_height": ("void_height = -2.0", "void_height = nan", "void_height", "nan"),
    "inf resolution": ("resolution = 0.05", "resolution = inf", "resolution", "inf"),
    "inf center": (
        "center = [1.0, 1.0, 0.05]",
        "center = [inf, 1.0, 0.05]",
        "box[1].center",
        "[inf, 1.0, 0.05]",
    ),
    "nan rpy": ("rpy = [0.0, 0.0, 0.0]", "rpy = [0.0, nan, 0.0]", "box[0].rpy", "[0.0, nan, 0.0]"),
    "-inf bounds": (
        "bounds = [[0.0, 0.0], [4.0, 3.0]]",
        "bounds = [[-inf, 0.0], [4.0, 3.0]]",
        "bounds",
        "[[-inf, 0.0], [4.0, 3.0]]",
    ),
    "nan target": ("target = [3.5, 1.5]", "target = [nan, 1.5]", "scenario.target", "[nan, 1.5]"),
    # heightfield too large: (1000 / 0.1 + 1)^2 = 100 020 001 cells > 50 million
    "too many cells": (
        "bounds = [[0.0, 0.0], [4.0, 3.0]]\nvoid_height = -2.0\nresolution = 0.05",
        "bounds = [[0.0, 0.0], [1000.0, 1000.0]]\nvoid_height = -2.0\nresolution = 0.1",
        "resolution",
        "0.1",
    ),
    # unknown keys
    "unknown top-level key": ('name = "unit"', 'name = "unit"\ncolour = "red"', "colour", '"red"'),
    "unknown box key": ("size = [0.5, 0.5, 0.1]", "size = [0.5, 0.5, 0.1]\nmass = 2.0", "box[1].mass", "2.0"),
    "unknown scenario key": ("seed = 0", "seed = 0\ngoal = [1.0, 1.0]", "scenario.goal", "[1.0, 1.0]"),
    # scenario values
    "start region inverted": (
        "start_region = [[0.5, 1.0], [1.0, 2.0]]",
        "start_region = [[1.5, 1.0], [1.0, 2.0]]",
        "scenario.start_region",
        "[[1.5, 1.0], [1.0, 2.0]]",
    ),
    "yaw range inverted": (
        "start_yaw_deg = [-30.0, 30.0]",
        "start_yaw_deg = [30.0, -30.0]",
        "scenario.start_yaw_deg",
        "[30.0, -30.0]",
    ),
    "negative speed": (
        "start_speed = [0.0, 0.07]",
        "start_speed = [-0.1, 0.07]",
        "scenario.start_speed",
        "[-0.1, 0.07]",
    ),
    "zero starts": ("n_starts = 5", "n_starts = 0", "scenario.n_starts", "0"),
    "negative seed": ("seed = 0", "seed = -1", "scenario.seed", "-1"),
    "target out of bounds": ("target = [3.5, 1.5]", "target = [4.5, 1.5]", "scenario.target", "[4.5, 1.5]"),
    "no waypoints": ("waypoints = [[2.0, 1.5]]", "waypoints = []", "scenario.waypoints", "[]"),
    "waypoint out of bounds": (
        "waypoints = [[2.0, 1.5]]",
        "waypoints = [[2.0, -1.5]]",
        "scenario.waypoints",
        "[[2.0, -1.5]]",
    ),
}


@pytest.mark.parametrize("case", sorted(REJECTIONS))
def test_rejection_names_file_key_and_value(case):
    old, new, key, value = REJECTIONS[case]
    assert old in BASE, f"test case {case!r} does not apply to BASE"
    text = BASE.replace(old, new, 1)
    with pytest.raises(TerrainError) as info:
        loads_terrain(text, SOURCE)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{SOURCE}: ")
    if key is not None:
        assert key in message
    if value is not None:
        assert f"= {value}:" in message


def test_no_box_is_rejected():
    text = BASE[: BASE.index("[[box]]")] + "box = []\n" + BASE[BASE.index("[scenario]") :]
    with pytest.raises(TerrainError, match=r"unit\.toml: box = \[\]: needs at least one"):
        loads_terrain(text, SOURCE)
    text = BASE[: BASE.index("[[box]]")] + BASE[BASE.index("[scenario]") :]
    with pytest.raises(TerrainError, match=r"unit\.toml: box: missing required key"):
        loads_terrain(text, SOURCE)


def test_tables_of_the_wrong_kind_are_rejected():
    head = BASE[: BASE.index("[[box]]")]
    with pytest.raises(TerrainError, match=r"^unit\.toml: box = 3: must be an array of tables"):
        loads_terrain("box = 3\n" + head, SOURCE)
    with pytest.raises(TerrainError, match=r"^unit\.toml: scenario = 3: must be a table"):
        loads_terrain("scenario = 3\n" + BASE[: BASE.index("[scenario]")], SOURCE)


def test_box_number_is_the_position_in_the_file():
    with pytest.raises(TerrainError, match=r"box\[1\]\.size"):
        loads_terrain(BASE.replace("size = [0.5, 0.5, 0.1]", "size = [0.5, 0.5, -1.0]"), SOURCE)


def test_cell_limit_is_50_million():
    assert MAX_CELLS == 50_000_000
    # 7070 x 7071 = 49 991 970 cells at 1 m: accepted, although nothing is rasterised yet
    ok = BASE.replace("bounds = [[0.0, 0.0], [4.0, 3.0]]", "bounds = [[0.0, 0.0], [7069.0, 7070.0]]")
    ok = ok.replace("resolution = 0.05", "resolution = 1.0")
    assert loads_terrain(ok, SOURCE).shape == (7070, 7071)
    # two more columns: 7072 x 7071 = 50 006 112 cells, rejected
    too_big = ok.replace("[7069.0, 7070.0]", "[7071.0, 7070.0]")
    with pytest.raises(TerrainError, match="exceeds 50000000 cells"):
        loads_terrain(too_big, SOURCE)


def test_invalid_toml_names_the_file():
    with pytest.raises(TerrainError, match=r"^unit\.toml: invalid TOML: .*line 1"):
        loads_terrain("name = = 3\n", SOURCE)


def test_load_terrain_reads_a_file_and_keeps_its_path(tmp_path):
    path = tmp_path / "t.toml"
    path.write_text(BASE)
    terrain = load_terrain(path)
    assert terrain.path == str(path) and terrain.text == BASE
    bad = tmp_path / "bad.toml"
    bad.write_text(BASE.replace("resolution = 0.05", "resolution = -1.0"))
    with pytest.raises(TerrainError, match=rf"^{bad}: resolution = -1\.0: must be > 0$"):
        load_terrain(bad)


def test_missing_file_is_a_terrain_error(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(TerrainError, match=rf"^{missing}: cannot read terrain file"):
        load_terrain(missing)


def test_terrain_error_is_a_leas_error():
    assert issubclass(TerrainError, LeasError)


def test_messages_show_toml_values():
    with pytest.raises(TerrainError) as info:
        loads_terrain(BASE.replace("seed = 0", "seed = true"), SOURCE)
    assert str(info.value) == "unit.toml: scenario.seed = true: must be an integer, not a boolean"
    assert math.isfinite(loads_terrain(BASE, SOURCE).void_height)
