"""`leas evaluate` end to end on a small scenario with a tiny policy; metrics and CLI errors."""

import csv
import json

import numpy as np
import pytest

from leas_jax.cli import main
from leas_jax.contacts import metrics
from leas_jax.eval.scenarios import PAPER_TABLE_II, cells_for

# 4.5 x 3.5 m floor, a wall across x = 2.2 from y = 0 to y = 2 (the RRT goes round it),
# starts near (1, 1), target (3.5, 1): short routes, since the generator plans RBKino's
# every 0.01 s.
WALL_TARGET = [3.5, 1.0]
WALL_SCENARIO = """name = "wall_scenario"
bounds = [[0.0, 0.0], [4.5, 3.5]]
void_height = -2.0
resolution = 0.05
[[box]]
center = [2.25, 1.75, -0.1]
size = [4.5, 3.5, 0.2]
[[box]]
center = [2.2, 1.0, 0.75]
size = [0.2, 2.0, 1.5]
[scenario]
target = [3.5, 1.0]
start_region = [[0.9, 0.9], [1.1, 1.1]]
start_yaw_deg = [-20.0, 20.0]
start_speed = [0.0, 0.05]
n_starts = 60
seed = 0
"""


def test_evaluate_writes_every_output(run_dir, tmp_path, capsys):
    terrain = tmp_path / "wall.toml"
    terrain.write_text(WALL_SCENARIO)
    out = tmp_path / "eval"
    code = main(
        [
            "evaluate",
            "--terrain",
            str(terrain),
            "--methods",
            "rblin,rbkino,rbkino_rrt,leas,leas_rrt",
            "--checkpoint",
            str(run_dir),
            "--n-starts",
            "2",
            "--workers",
            "0",
            "--no-progress",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    report = json.loads((out / "results.json").read_text())
    scenario = report["scenarios"]["wall_scenario"]
    trajectories = scenario["trajectories"]
    assert len(trajectories) == 2 * 5
    assert {t["method"] for t in trajectories} == {"rblin", "rbkino", "rbkino_rrt", "leas", "leas_rrt"}
    guides = np.load(out / "guides.npz")
    for k, t in enumerate(trajectories):
        assert 0.0 <= t["coverage"] <= 1.0
        if t["error"] is None:
            guide = guides[f"wall_scenario/{k}"]
            assert guide.shape == (t["guide_length"], 4)
            # success needs the whole guide covered (docs/design.md §8)
            assert not t["success"] or t["last_valid_index"] == len(guide) - 1
    # RBLin and RBKino drive straight into the wall: the plan cannot cover their guides.
    for t in trajectories:
        if t["method"] in ("rblin", "rbkino"):
            assert t["coverage"] < 1.0 and not t["success"]
        if t["method"] == "rbkino_rrt" and t["error"] is None:
            assert t["waypoints"][-1] == WALL_TARGET
    # RBKino's continuous paths come sampled every 0.01 s, as HPP's contact generator samples
    # them (the RRT's through its own nodes); the other guides at the env's 0.1 s.
    for k, t in enumerate(trajectories):
        if t["method"] in ("rbkino", "rbkino_rrt"):
            assert t["timestep"] == 0.01
            if t["error"] is None:
                guide = guides[f"wall_scenario/{k}"]
                step = np.hypot(*np.diff(guide[:, :2], axis=0).T)
                assert step.max() <= 0.18 * 0.01 * np.sqrt(2) + 1e-9  # v_max per axis
                for point in t["waypoints"] if t["method"] == "rbkino_rrt" else []:
                    assert np.hypot(*(guide[:, :2] - point).T).min() < 1e-6
        else:
            assert "timestep" not in t
    # the two starts share one seeded draw across methods
    starts = {tuple(t["start"]) for t in trajectories}
    assert len(starts) == 2
    rows = list(csv.DictReader((out / "table.csv").open()))
    assert {r["method"] for r in rows} == {"rblin", "rbkino", "rbkino_rrt", "leas", "leas_rrt"}
    summary = scenario["summary"]["rblin"]["all"]
    assert summary["coverage"] == pytest.approx(
        100 * np.mean([t["coverage"] for t in trajectories if t["method"] == "rblin"]), abs=1e-4
    )
    assert "wall_scenario" in (out / "table.md").read_text()
    assert (out / "wall_scenario.png").stat().st_size > 10_000
    assert "coverage" in capsys.readouterr().out


def test_outcome_success_needs_full_coverage_and_a_posture_near_target():
    guide = np.column_stack([np.linspace(0, 4, 11), np.zeros(11), np.ones(11), np.zeros(11)])

    class Plan:
        q = np.array([[0.0, 0.0], [3.8, 0.1]])

    full = metrics.outcome(guide, [4.0, 0.0], 1.0, 10, plan=Plan())
    assert full.success and full.final_distance == pytest.approx(np.hypot(0.2, 0.1))
    assert not metrics.outcome(guide, [4.0, 0.0], 0.9, 9, plan=Plan()).success  # not covered
    assert not metrics.outcome(guide, [4.5, 0.0], 1.0, 10, plan=Plan()).success  # 0.71 m away
    # without a plan the guide pose at the last valid index stands in
    assert metrics.outcome(guide, [4.2, 0.0], 1.0, 10).success
    failed = metrics.outcome(None, [4.0, 0.0], 0.0, -1, error="rrt: no path")
    assert failed.coverage == 0.0 and not failed.success and failed.error == "rrt: no path"
    assert metrics.summarize([full, failed]) == {"n": 2, "coverage": 50.0, "success": 50.0, "errors": 1}


def test_ground_runs_table_ii_cells():
    cells = cells_for("ground", None)
    assert len(cells) == 9 and all(c.table_key in PAPER_TABLE_II for c in cells)
    assert PAPER_TABLE_II[((150.0, 210.0), 0.01)] == {"rblin": 22.3, "rbkino": 76.5, "leas": 98.4}


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["evaluate", "--scenario", "moon", "--out", "o"], "unknown scenario moon"),
        (
            ["evaluate", "--scenario", "ground", "--methods", "rblin,teleport", "--out", "o"],
            "unknown method(s) teleport",
        ),
        (["evaluate", "--scenario", "ground", "--out", "o"], "--checkpoint is required"),
        (["evaluate", "--out", "o"], "one of --scenario or --terrain"),
        (["evaluate", "--scenario", "ground", "--terrain", "x.toml", "--out", "o"], "not both"),
        (["evaluate", "--terrain", "missing.toml", "--out", "o"], "--terrain: no such file"),
        (
            ["evaluate", "--terrain", "terrains/training_arena.toml", "--methods", "rblin", "--out", "o"],
            "no [scenario] table",
        ),
    ],
)
def test_usage_errors_are_one_line(capsys, tmp_path, monkeypatch, argv, fragment):
    from leas_jax.files import REPO_ROOT

    monkeypatch.chdir(REPO_ROOT if "training_arena" in " ".join(argv) else tmp_path)
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and fragment in err, err


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (
            ["evaluate", "--scenario", "ground", "--n-starts", "0", "--out", "o"],
            "--n-starts expects an integer >= 1",
        ),
        (
            ["evaluate", "--scenario", "ground", "--workers", "-1", "--out", "o"],
            "--workers expects an integer >= 0",
        ),
        (["evaluate", "--scenario", "ground"], "the following arguments are required: --out"),
    ],
)
def test_argument_errors_exit_2(capsys, argv, fragment):
    with pytest.raises(SystemExit) as info:
        main(argv)
    err = capsys.readouterr().err.strip()
    assert info.value.code == 2 and len(err.splitlines()) == 1 and fragment in err


def test_rrt_searches_are_the_same_in_worker_processes():
    """RRT searches are seeded and bounded by iterations: 2 spawned processes give the in-process plans."""
    from leas_jax.env import EnvConfig, heightfield_from_terrain
    from leas_jax.eval.evaluate import _rrt_plans
    from leas_jax.eval.scenarios import Starts
    from leas_jax.steering.baselines import BaselineConfig
    from leas_jax.steering.rrt import RRTConfig
    from leas_jax.terrain import loads_terrain

    terrain, env = loads_terrain(WALL_SCENARIO), EnvConfig()
    field = heightfield_from_terrain(terrain, env)
    starts = Starts(
        np.array([[1.0, 1.0, 1.0, 0.0], [1.1, 0.9, 1.0, 0.2]]), np.array([0.0, 0.05]), np.zeros(2)
    )
    args = (
        terrain,
        env,
        starts,
        np.array(WALL_TARGET),
        BaselineConfig.from_env(env),
        RRTConfig(seed=3, max_iterations=400),
    )
    here = _rrt_plans(field, *args, workers=0, progress=False)
    spawned = _rrt_plans(field, *args, workers=2, progress=False)
    assert [p.success for p in here] == [p.success for p in spawned]
    assert any(p.iterations > 1 for p in here)
    for a, b in zip(here, spawned):
        np.testing.assert_array_equal(a.states, b.states)
        assert a.iterations == b.iterations


def test_leas_horizon_scales_with_the_route_and_keeps_the_minimum():
    from leas_jax.steering.horizon import HORIZON_FACTOR, leas_horizon

    # 6 m at 0.18 m/s and 0.1 s per step: 333.3 steps at the target speed.
    points = np.array([[6.0, 0.0]])
    assert leas_horizon([0.0, 0.0], points, 0.18, 0.1, 400) == int(np.ceil(HORIZON_FACTOR * 6.0 / 0.018))
    assert leas_horizon([0.0, 0.0], points, 0.18, 0.1, 400, factor=1.0) == 400  # the minimum wins
    # a polyline counts its whole length: 3 m + 4 m
    route = np.array([[3.0, 0.0], [3.0, 4.0]])
    assert leas_horizon([0.0, 0.0], route, 0.18, 0.1, 0, factor=1.0) == int(np.ceil(7.0 / 0.018))


def test_rbkino_timestep_is_chosen_on_the_command_line(tmp_path, capsys):
    """`--rbkino-timestep 0.05` samples RBKino's path every 0.05 s (results.json says so, the
    guide's steps are bounded by v_max x 0.05 s); a non-positive or non-numeric value is a
    one-line error naming the option."""
    terrain = tmp_path / "wall.toml"
    terrain.write_text(WALL_SCENARIO)
    common = ["evaluate", "--terrain", str(terrain), "--methods", "rbkino", "--n-starts", "1"]
    common += ["--workers", "0", "--no-progress"]
    assert main([*common, "--rbkino-timestep", "0.05", "--out", str(tmp_path / "eval")]) == 0
    (t,) = json.loads((tmp_path / "eval" / "results.json").read_text())["scenarios"]["wall_scenario"][
        "trajectories"
    ]
    guide = np.load(tmp_path / "eval" / "guides.npz")["wall_scenario/0"]
    assert t["timestep"] == 0.05 and guide.shape == (t["guide_length"], 4)
    step = np.hypot(*np.diff(guide[:, :2], axis=0).T)
    assert 0.18 * 0.01 * np.sqrt(2) < step.max() <= 0.18 * 0.05 * np.sqrt(2) + 1e-9
    for bad in ("0", "-0.1", "fast", "inf"):
        with pytest.raises(SystemExit):
            main([*common, "--rbkino-timestep", bad, "--out", str(tmp_path / "bad")])
        assert "--rbkino-timestep expects" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()
