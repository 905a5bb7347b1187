"""`leas navigate` on the command line: bad input (one line, exit 2) and a real plan that
passes `leas verify` (the contact generator in this process)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from leas_jax.cli import main

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = str(ROOT / "checkpoints" / "leas_talos")
WALL = str(ROOT / "tests" / "data" / "slab_with_wall.toml")


def _navigate(*extra, out):
    return main(["navigate", "--checkpoint", SHIPPED, "--terrain", WALL, "--out", str(out), *extra])


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--start", "1,2", "--goal", "2,2"], "--start expects 3 finite comma-separated numbers"),
        (["--start", "1,2,0", "--goal", "2,x"], "--goal expects 2 finite comma-separated numbers"),
    ],
)
def test_malformed_arguments_are_one_line_and_exit_code_2(tmp_path, capsys, extra, message):
    with pytest.raises(SystemExit) as caught:
        _navigate(*extra, out=tmp_path / "plan.npz")
    err = capsys.readouterr().err
    assert caught.value.code == 2 and message in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    "extra, message",
    [
        (
            ["--start", "1,2,0", "--goal", "2,2", "--max-replans", "-1"],
            "--max-replans: expected an integer >= 0",
        ),
        (["--start", "4.15,3,0", "--goal", "1,1"], "--start: the start (4.15, 3.00, 0.00) is in collision"),
        (["--start", "1,1,0", "--goal", "7,1"], "--goal: (7.00, 1.00) lies off the terrain"),
    ],
)
def test_bad_values_are_one_line_and_exit_code_2(tmp_path, capsys, extra, message):
    code = _navigate(*extra, out=tmp_path / "plan.npz")
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "plan.npz").exists()


def test_missing_output_folder_and_checkpoint_are_named(tmp_path, capsys):
    code = _navigate("--start", "1,1,0", "--goal", "2,1", out=tmp_path / "nowhere" / "plan.npz")
    assert code == 2 and "--out:" in capsys.readouterr().err
    code = main(
        ["navigate", "--checkpoint", str(tmp_path / "none"), "--terrain", WALL, "--start", "1,1,0"]
        + ["--goal", "2,1", "--out", str(tmp_path / "plan.npz")]
    )
    assert code == 2 and "--checkpoint:" in capsys.readouterr().err


def test_a_navigate_plan_passes_verify(tmp_path, capsys):
    from leas_jax.contacts import ContactPlan

    out = tmp_path / "plan.npz"
    code = _navigate("--start", "1.0,1.0,0", "--goal", "2.5,1.6", "--workers", "0", out=out)
    captured = capsys.readouterr()
    assert code == 0, captured.out + captured.err
    assert "navigate: reached" in captured.out and "contact_planning" in captured.out
    assert "lattice:" in captured.err and "query 0: search" in captured.err  # progress
    plan = ContactPlan.load(out)
    assert plan.last_valid_index == len(plan.guide) - 1
    assert np.min(np.hypot(*(plan.q[:, :2] - [2.5, 1.6]).T)) <= 0.30
    assert main(["verify", str(out)]) == 0
    assert "OK" in capsys.readouterr().out


SCENARIO_SLAB = """
name = "navigate_slab"
bounds = [[0.0, 0.0], [5.0, 3.0]]
void_height = -2.0
resolution = 0.02
[[box]]
center = [2.5, 1.5, -0.3]
size = [5.0, 3.0, 0.6]
[scenario]
target = [3.8, 1.5]
start_region = [[1.0, 1.2], [1.4, 1.8]]
start_yaw_deg = [-30.0, 30.0]
start_speed = [0.01, 0.05]
n_starts = 2
seed = 0
"""


def test_evaluate_adds_a_navigate_row(tmp_path):
    import json

    from leas_jax.eval.evaluate import evaluate

    terrain = tmp_path / "navigate_slab.toml"
    terrain.write_text(SCENARIO_SLAB)
    report = evaluate(
        [],
        ["navigate"],
        SHIPPED,
        tmp_path / "out",
        workers=0,
        terrain_file=terrain,
        progress=False,
        figures=False,
    )
    (row,) = [r for r in report["rows"] if r["method"] == "navigate"]
    assert row["n"] == 2 and row["success"] == 100.0 and row["errors"] == 0
    saved = json.loads((tmp_path / "out" / "results.json").read_text())
    trajectories = saved["scenarios"]["navigate_slab"]["trajectories"]
    assert [t["method"] for t in trajectories] == ["navigate", "navigate"]
    assert all(t["replans"] >= 0 and t["guide_length"] > 100 for t in trajectories)
    assert "Navigate (lattice search, LeaS, replans)" in (tmp_path / "out" / "table.md").read_text()
    seconds = saved["scenarios"]["navigate_slab"]["seconds"]
    assert {"navigate", "navigate_search", "navigate_rollout", "navigate_contact_planning"} <= set(seconds)


def test_the_report_section_runs_one_query_and_writes_its_plan_and_figure(tmp_path):
    from leas_jax.navigate.report import navigate_section

    terrain = tmp_path / "navigate_slab.toml"
    terrain.write_text(SCENARIO_SLAB)
    lines, summary = navigate_section(SHIPPED, tmp_path, workers=0, terrain_file=terrain)
    assert summary["success"] and summary["postures"] > 10
    assert lines[0] == "## Navigate" and "![navigate](navigate/navigate.png)" in lines
    assert (tmp_path / "navigate" / "plan.npz").is_file() and (
        tmp_path / "navigate" / "navigate.png"
    ).is_file()
    assert main(["verify", str(tmp_path / "navigate" / "plan.npz")]) == 0


@pytest.mark.slow
def test_the_real_generator_gives_the_same_plans_with_1_and_2_workers(tmp_path):
    from leas_jax.navigate.loop import Navigator
    from leas_jax.terrain import load_terrain
    from leas_jax.training import load_policy

    terrain = load_terrain(ROOT / "terrains" / "eval_bridge.toml")
    navigator = Navigator(load_policy(SHIPPED), terrain)
    queries = [navigator.query((2.0, y, 0.0), (9.5, 5.0)) for y in (2.0, 4.0, 6.0)]
    one = navigator.run(queries, workers=1)
    two = navigator.run(queries, workers=2)
    for a, b in zip(one, two):
        assert a.reason == b.reason and a.replans == b.replans
        np.testing.assert_array_equal(a.plan.q, b.plan.q)
        np.testing.assert_array_equal(a.guide, b.guide)


def test_policy_only_turns_the_searched_paths_fallback_off():
    """`leas navigate --policy-only` and `leas evaluate --navigate-policy-only` give the loop a
    NavigateConfig without the fallback; without them it is on (the default)."""
    import argparse

    from leas_jax.eval.commands import _navigate_config
    from leas_jax.eval.commands import register as register_evaluate
    from leas_jax.navigate.commands import navigate_config
    from leas_jax.navigate.commands import register as register_navigate

    parser = argparse.ArgumentParser()
    commands = parser.add_subparsers()
    register_navigate(commands)
    register_evaluate(commands)
    base = ["navigate", "--checkpoint", SHIPPED, "--terrain", WALL, "--start", "1,1,0", "--goal", "2,1"]
    base += ["--out", "plan.npz"]
    assert navigate_config(parser.parse_args(base)).path_fallback
    assert not navigate_config(parser.parse_args([*base, "--policy-only"])).path_fallback
    evaluate = ["evaluate", "--scenario", "bridge", "--methods", "navigate", "--out", "o"]
    assert _navigate_config(parser.parse_args(evaluate)) is None  # NavigateConfig's defaults
    assert not _navigate_config(parser.parse_args([*evaluate, "--navigate-policy-only"])).path_fallback
