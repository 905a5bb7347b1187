"""Hostile terrain files: overflow, recursion, sizes and scenario nonsense are TerrainErrors naming the
key; a seeded fuzz run of the committed terrains raises nothing else."""

import sys
import time
from pathlib import Path

import numpy as np
import pytest

from leas_jax.terrain import TerrainError, loads_terrain
from leas_jax.terrain.loader import MAX_BOXES, MAX_NESTING, MAX_STARTS

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "studies"))
import terrain_fuzz  # noqa: E402

SOURCE = "hostile.toml"
BASE = """\
name = "unit"
bounds = [[0.0, 0.0], [4.0, 3.0]]
void_height = -2.0
resolution = 0.05

[[box]]
center = [2.0, 1.5, -0.1]
size = [4.0, 3.0, 0.2]

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
"""
HUGE = "1" + "0" * 400


def _rejects(text: str, key: str, fragment: str = "") -> str:
    with pytest.raises(TerrainError) as info:
        loads_terrain(text, SOURCE)
    message = str(info.value)
    assert message.startswith(f"{SOURCE}: ") and "\n" not in message and len(message) < 400, message
    assert key in message and fragment in message, message
    return message


@pytest.mark.parametrize(
    "old, new, key, fragment",
    [
        ("resolution = 0.05", "resolution = 5e-324", "resolution", "exceeds"),
        ("resolution = 0.05", "resolution = 1e30", "resolution", "must lie in"),
        ("resolution = 0.05", "resolution = 3.0", "resolution", "at least 2 per axis"),
        ("[4.0, 3.0]]", "[1e308, 3.0]]", "bounds", "must lie in"),
        ("[[0.0, 0.0]", "[[-1.7976931348623157e308, 0.0]", "bounds", "must lie in"),
        ("size = [4.0, 3.0, 0.2]", "size = [1e308, 3.0, 0.2]", "box[0].size", "must lie in"),
        ("center = [2.0, 1.5, -0.1]", f"center = [{HUGE}, 1.5, -0.1]", "box[0].center", "digits"),
        ("void_height = -2.0", f"void_height = -{HUGE}", "void_height", "must lie in"),
        ("seed = 0", f"seed = {HUGE}", "scenario.seed", "must lie in"),
        ("n_starts = 5", "n_starts = 9223372036854775807", "scenario.n_starts", f"[1, {MAX_STARTS}]"),
        ("void_height = -2.0", "void_height = 0.5", "void_height", "below the terrain"),
        ("target = [3.5, 1.5]", "target = [5.0, 1.5]", "scenario.target", "outside the terrain bounds"),
        ("[[0.5, 1.0], [1.0, 2.0]]", "[[0.5, 1.0], [1.0, 9.0]]", "scenario.start_region", "outside"),
        ("start_speed = [0.0, 0.07]", "start_speed = [0.0, 5.0]", "scenario.start_speed", "v_max"),
        (
            "start_yaw_deg = [-30.0, 30.0]",
            "start_yaw_deg = [-300.0, 300.0]",
            "scenario.start_yaw_deg",
            "spans",
        ),
        ("start_yaw_deg = [-30.0, 30.0]", "start_yaw_deg = [0.0, 1e9]", "scenario.start_yaw_deg", "must lie"),
    ],
)
def test_extreme_values_are_named_terrain_errors(old, new, key, fragment):
    assert old in BASE
    _rejects(BASE.replace(old, new), key, fragment)


def test_target_and_start_region_over_the_void_are_rejected():
    holed = BASE.replace("size = [4.0, 3.0, 0.2]", "size = [2.0, 3.0, 0.2]").replace(
        "center = [2.0, 1.5, -0.1]", "center = [1.0, 1.5, -0.1]"
    )  # ground only on x in [0, 2]
    _rejects(holed, "scenario.target", "over the void")
    moved = holed.replace("target = [3.5, 1.5]", "target = [1.5, 1.5]").replace(
        "[[0.5, 1.0], [1.0, 2.0]]", "[[2.5, 1.0], [3.5, 2.0]]"
    )
    _rejects(moved, "scenario.start_region", "over the void")
    loads_terrain(moved.replace("[[2.5, 1.0], [3.5, 2.0]]", "[[1.5, 1.0], [3.5, 2.0]]"), SOURCE)  # partly


@pytest.mark.parametrize("depth", [MAX_NESTING + 1, 331, 400, 3000])
@pytest.mark.parametrize("kind", ["arrays", "inline tables"])
def test_deep_nesting_is_a_terrain_error(depth, kind):
    value = "[" * depth + "1.0" + "]" * depth if kind == "arrays" else "{ a = " * depth + "1" + " }" * depth
    message = _rejects(BASE.replace("resolution = 0.05", f"resolution = {value}"), "nested")
    assert "nested" in message


def test_box_count_is_bounded_and_rejected_fast():
    block = BASE[BASE.index("[[box]]") : BASE.index("[scenario]")]
    many = BASE.replace("[scenario]", block * 10_000 + "[scenario]")
    start = time.perf_counter()
    _rejects(many, "box", f"bound of {MAX_BOXES}")
    assert time.perf_counter() - start < 5.0
    # at the bound it loads and rasterises (the arena's 545 boxes in ~0.1 s)
    at_bound = BASE.replace("[scenario]", block * (MAX_BOXES // 2 - 1) + "[scenario]")
    start = time.perf_counter()
    assert loads_terrain(at_bound, SOURCE).raster().shape == (81, 61)
    assert time.perf_counter() - start < 10.0


def test_messages_stay_on_one_line_for_hostile_strings():
    message = _rejects(BASE.replace('name = "unit"', 'name = "a\\nb"\nbogus = "x\\ny"'), "bogus")
    assert "\\n" in message


def test_a_target_inside_an_obstacle_is_refused_by_the_start_draw():
    from leas_jax.env import EnvConfig, heightfield_from_terrain
    from leas_jax.errors import UsageError
    from leas_jax.eval.scenarios import cells_for, draw_starts

    walled = BASE.replace(
        "[scenario]", "[[box]]\ncenter = [3.75, 1.5, 1.0]\nsize = [0.3, 3.0, 2.0]\n\n[scenario]"
    )  # a 2 m wall 0.1 m from the target: the trunk cannot stand there, whatever the yaw
    terrain = loads_terrain(walled, SOURCE)
    env = EnvConfig()
    field = heightfield_from_terrain(terrain, env)
    cell = cells_for("unit", terrain.scenario)[0]
    with pytest.raises(UsageError, match=r"scenario\.target \(3\.5, 1\.5\): the robot cannot stand there"):
        draw_starts(terrain.scenario, cell, 2, 0, field, env.nominal_root_height, env.reachability)
    fine = loads_terrain(BASE, SOURCE)
    starts = draw_starts(
        fine.scenario,
        cell,
        2,
        0,
        heightfield_from_terrain(fine, env),
        env.nominal_root_height,
        env.reachability,
    )
    assert starts.poses.shape == (2, 4)


def test_seeded_fuzz_of_the_committed_terrains_raises_only_terrain_errors():
    """300 mutants (the committed study runs 3000): no other exception, no hang."""
    report = terrain_fuzz.fuzz(300, seed=10_000, time_limit=20.0)
    assert report["non_terrain_errors"] == 0 and report["hangs"] == 0, report["failures"][:3]
    assert report["counts"]["TerrainError"] > 200 and report["counts"].get("accepted", 0) > 10
    assert np.isfinite(report["slowest_s"])
