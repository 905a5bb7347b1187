"""`leas evaluate --motion`: a few covered LeaS and navigate plans per scenario are executed in MuJoCo."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from leas_jax.cli import main
from leas_jax.contacts.metrics import Outcome
from leas_jax.eval.motions import aggregate, motion_candidates

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = str(ROOT / "checkpoints" / "leas_talos")

# A flat slab and a 1 m walk: one start, so the evaluation stays short.
SHORT_SLAB = """
name = "motion_slab"
bounds = [[0.0, 0.0], [4.0, 3.0]]
void_height = -2.0
resolution = 0.02
[[box]]
center = [2.0, 1.5, -0.3]
size = [4.0, 3.0, 0.6]
[scenario]
target = [2.3, 1.5]
start_region = [[1.2, 1.4], [1.3, 1.6]]
start_yaw_deg = [-10.0, 10.0]
start_speed = [0.01, 0.02]
n_starts = 1
seed = 0
"""


def _trajectory(method, covered, guide=10, plan=5, cell=0):
    outcome = Outcome(1.0 if covered else 0.5, covered, guide - 1 if covered else 3, 0.1)
    return SimpleNamespace(
        method=method, cell=cell, outcome=outcome, guide=np.zeros((guide, 4)), plan=[None] * plan
    )


def test_candidates_are_covered_leas_and_navigate_plans_spread_over_the_cells():
    trajectories = (
        [_trajectory("rblin", True)]
        + [_trajectory("leas", k % 2 == 0, cell=k) for k in range(10)]
        + [_trajectory("navigate", False), _trajectory("navigate", True, plan=1)]
    )
    chosen = motion_candidates(trajectories, 3)
    assert chosen == [1, 5, 9]  # covered leas at cells 0, 2, 4, 6, 8: first, middle, last
    assert motion_candidates(trajectories, 10) == [1, 3, 5, 7, 9]
    assert motion_candidates(trajectories, 0) == []


def test_aggregate_counts_falls_and_keeps_the_worst_figures():
    figures = dict(max_landing_angle_deg=0.2, max_slip_m=0.001, max_torque_ratio=0.6)
    executions = [
        {"method": "leas", "made": True, "fallen": False, "success": True, "max_landing_position_m": 0.002}
        | figures,
        {"method": "leas", "made": True, "fallen": True, "success": False, "max_landing_position_m": 0.05}
        | figures,
        {"method": "leas", "made": False, "fallen": None, "success": False},
    ]
    (summary,) = aggregate(executions).values()
    assert summary["n"] == 3 and summary["made"] == 2 and summary["without_fall"] == 1
    assert summary["executed"] == 1 and summary["max_landing_position_m"] == 0.05


def test_a_tiny_evaluation_executes_its_plans(tmp_path, capsys):
    terrain = tmp_path / "motion_slab.toml"
    terrain.write_text(SHORT_SLAB)
    out = tmp_path / "out"
    args = ["evaluate", "--terrain", str(terrain), "--methods", "leas,navigate", "--checkpoint", SHIPPED]
    args += ["--workers", "0", "--no-progress", "--out", str(out), "--motion", "--motion-plans", "1"]
    assert main(args) == 0
    printed = capsys.readouterr().out
    report = json.loads((out / "results.json").read_text())
    assert report["transitions_checked"]  # the plans made for motions had their lift-offs checked
    scenario = report["scenarios"]["motion_slab"]
    assert [t["success"] for t in scenario["trajectories"]] == [True, True]
    motion = scenario["motion"]
    assert [e["method"] for e in motion["executions"]] == ["leas", "navigate"]
    for method in ("leas", "navigate"):
        s = motion["summary"][method]
        assert s["n"] == s["made"] == s["without_fall"] == s["executed"] == 1, motion["executions"]
        assert 0 <= s["max_landing_position_m"] < 0.03 and s["max_torque_ratio"] < 1.0
        assert f"{method:11s} motions: 1/1 made, 1 without a fall, 1 executed" in printed
    assert scenario["seconds"]["motion"] > 0
    table = (out / "table.md").read_text()
    assert "## Whole-body motions" in table and "| motion_slab | LeaS | 1 | 1 | 1 | 1 |" in table


def test_motion_plans_without_motion_is_a_usage_error(tmp_path, capsys):
    args = ["evaluate", "--scenario", "ground", "--out", str(tmp_path / "o"), "--motion-plans", "2"]
    assert main(args) == 2
    assert "--motion-plans: give --motion too" in capsys.readouterr().err
