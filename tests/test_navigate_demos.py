"""The HPP group's scenes (terrains/hpp/demos, terrains/hpp/rough) and
studies/navigate_demos.py, which navigates their queries and verifies each plan.

The demo files must hold the queries of hpp-rbprm-corba's Talos scripts (HPP_QUERIES,
copied from talos_*_path.py of its v4.12.0), the rough scenes 20 starts and a target on
either side of their difficult part. The quick tier runs the study on the flat-ground
demo (as a demo and as a one-start scene); the slow tier runs every demo query and wants
it reached with a plan that verifies.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from leas_jax.terrain import load_terrain

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "studies"), str(ROOT / "benchmarks")]

import common  # noqa: E402
import navigate_demos as study  # noqa: E402

DEMOS = sorted((ROOT / "terrains" / "hpp" / "demos").glob("*.toml"))
ROUGH = sorted((ROOT / "terrains" / "hpp" / "rough").glob("*.toml"))
FLAT = ROOT / "terrains" / "hpp" / "demos" / "talos_flatGround.toml"

# file stem -> (mesh, start (x, y, yaw deg), goal (x, y)) of hpp-rbprm-corba's scripts
# (the maze starts 0.5 m further in than the script's (0.1, 3.0), against the outer wall)
HPP_QUERIES = {
    "talos_flatGround": ("ground.stl", (0.0, 0.0, 0.0), (1.0, 0.0)),
    "talos_stairs10": ("bauzil_stairs_collision.stl", (0.0, 1.2, 0.0), (1.87, 1.2)),
    "talos_stairs15": ("bauzil_stairs_collision.stl", (-1.9, 1.9, -90.0), (-1.9, 0.9)),
    "talos_navBauzil": ("floor_bauzil.stl", (-0.9, 1.7, 0.0), (3.6, 1.2)),
    "talos_navBauzil_hard": ("floor_bauzil.stl", (-0.7, 2.0, 0.0), (0.0, -1.0)),
    "talos_navBauzil_obstacles": ("floor_bauzil_obstacles.stl", (-0.9, 1.7, 0.0), (2.0, 2.6)),
    "talos_plateformes": ("plateforme_surfaces_scale.stl", (0.18, 0.25, 0.0), (1.07, 0.25)),
    "talos_maze": ("maze_hard.stl", (0.6, 3.0, 0.0), (17.8, 15.0)),
}


def test_every_demo_file_holds_its_hpp_script_query():
    assert sorted(p.stem for p in DEMOS) == sorted(HPP_QUERIES)
    for path in DEMOS:
        mesh, (x, y, yaw_deg), goal = HPP_QUERIES[path.stem]
        terrain = load_terrain(path)
        assert terrain.meshes[0].source == f"hpp-environments:multicontact/{mesh}"
        start, target = study.demo_query(terrain.scenario)
        np.testing.assert_allclose(start[:2], (x, y), err_msg=path.stem)
        # the yaw offset in the file is rounded to 1e-6 deg
        assert math.remainder(start[2] - math.radians(yaw_deg), 2 * math.pi) == pytest.approx(0.0, abs=1e-7)
        assert target == goal
        assert np.all(terrain.height_at(np.array([start[:2], target])) > terrain.void_height + 1.0)


def test_demo_query_refuses_a_scenario_that_draws_starts():
    scenario = load_terrain(ROUGH[0]).scenario
    with pytest.raises(ValueError, match="one query"):
        study.demo_query(scenario)


@pytest.mark.parametrize("path", ROUGH, ids=lambda p: p.stem)
def test_rough_scene_crosses_its_difficult_part(path):
    """20 starts; start region and target stand on the scene, and the straight line between
    them passes over void or a height change of more than 0.1 m (the difficult part)."""
    terrain = load_terrain(path)
    scenario = terrain.scenario
    assert scenario.n_starts == 20
    corners = np.array([[x, y] for x in scenario.start_region[:, 0] for y in scenario.start_region[:, 1]])
    assert np.all(terrain.height_at(np.vstack([corners, scenario.target])) > terrain.void_height + 1.0)
    centre = scenario.start_region.mean(axis=0)
    line = centre + np.linspace(0.0, 1.0, 400)[:, None] * (scenario.target - centre)
    heights = terrain.height_at(line)
    assert heights.max() - heights.min() > 0.1


def _row(reached, verify_ok, reason="reached"):
    row = study.refused_row(reason, "m")
    row.update(reached=reached, verify_ok=verify_ok)
    return row


def test_scene_summary_counts_only_reached_plans_that_verify():
    rows = [_row(True, True), _row(True, False), _row(False, None, "no-path"), _row(False, None, "refused")]
    summary = study.scene_summary(rows)
    assert (summary["successes"], summary["trials"]) == (1, 4)
    assert summary["wilson_95"] == list(common.wilson(1, 4))
    assert summary["reasons"] == {"reached": 2, "no-path": 1, "refused": 1}
    table = study.demo_table([{"demo": "d", **rows[1]}, {"demo": "e", **rows[3]}])
    assert "| d | yes | reached |" in table and "| NO |" in table
    assert table.splitlines()[-1].endswith("| 0 | 0 | - |")


def test_other_seconds_is_the_total_less_the_parts():
    seconds = {"lattice": 1.0, "search": 0.5, "rollout": 2.0, "contact_planning": 0.25, "total": 5.0}
    assert study.other_seconds(seconds) == pytest.approx(1.25)
    assert study.other_seconds({**seconds, "total": None}) is None


def test_a_glob_that_matches_nothing_ends_the_run():
    with pytest.raises(SystemExit, match="matches no file"):
        study.expand(["terrains/hpp/demos/no_such_*.toml"])


def test_study_runs_the_flat_ground_demo_and_scene(tmp_path, capsys):
    """The flat-ground demo, once as a demo query (cold) and once as a scene of one start:
    both reach the goal with a plan that verifies; the JSON records machine, load and commit."""
    study.main(["--demos", str(FLAT), "--terrains", str(FLAT), "--out", str(tmp_path)])
    saved = json.loads((tmp_path / "navigate_demos.json").read_text())
    assert {"machine", "git", "load_average_before", "load_average_after"} <= set(saved)
    (demo,) = saved["demos"]
    assert demo["demo"] == "talos_flatGround" and demo["reached"] and demo["verify_ok"]
    assert demo["postures"] > 0 and demo["replans"] == 0
    assert all(demo["seconds"][p] > 0 for p in ("lattice", "rollout", "total"))
    assert demo["seconds"]["other"] >= 0
    (scene,) = saved["scenes"]
    assert (scene["successes"], scene["trials"]) == (1, 1) and scene["rows"][0]["verify_ok"]
    out = capsys.readouterr().out
    assert "| talos_flatGround | yes | reached |" in out and "| talos_flatGround | 1 | 1 (100 %) |" in out


# Demo queries navigate does not answer, and why (strict: the test fails once one is reached).
KNOWN_LIMITS = {
    "talos_plateformes": "the start is refused (left_foothold): the left lookahead leg lands on a "
    "15-degree stone whose flattest sole disk spans 0.043 m, more than the reachability "
    "condition's foothold_spread of 0.04 m",
}
SLOW_DEMOS = [
    pytest.param(p, marks=pytest.mark.xfail(strict=True, reason=KNOWN_LIMITS[p.stem]))
    if p.stem in KNOWN_LIMITS
    else p
    for p in DEMOS
]


@pytest.mark.slow
@pytest.mark.parametrize("path", SLOW_DEMOS, ids=lambda p: p.stem)
def test_demo_query_is_reached_and_its_plan_verifies(path):
    from leas_jax.training import load_policy

    row = study.run_demo(load_policy(ROOT / "checkpoints" / "leas_talos"), path, workers=0)
    assert row["reached"], row["message"]
    assert row["verify_ok"], row["verify_failures"]
