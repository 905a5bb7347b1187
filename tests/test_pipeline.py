"""`leas run`: its phases' configurations, with training and the report stood in for."""

import subprocess
import sys

import pytest

from leas_jax.cli import build_parser
from leas_jax.training.config import PLANNER_PRESETS


def _phases(monkeypatch, tmp_path, *args):
    """The TrainConfigs `leas run` trains with (geometric, then planner) and the report's arguments."""
    import leas_jax.eval.report
    import leas_jax.training.loop

    trained, reports = [], []
    monkeypatch.setattr(leas_jax.training.loop, "train", lambda config, out, **kw: trained.append(config))
    monkeypatch.setattr(
        leas_jax.eval.report, "write_report", lambda out, **kw: reports.append(kw) or out / "report.md"
    )
    parsed = build_parser().parse_args(["run", "--out", str(tmp_path / "run"), *args])
    assert parsed.func(parsed) == 0
    return trained, reports


@pytest.mark.parametrize("preset", ["quick", "paper"])
def test_run_fine_tunes_for_its_presets_planner_budget(monkeypatch, tmp_path, preset):
    trained, reports = _phases(monkeypatch, tmp_path, "--preset", preset)
    geometric, planner = trained
    assert (geometric.mode, planner.mode) == ("geometric", "planner")
    assert planner.num_timesteps == PLANNER_PRESETS[preset]["num_timesteps"]
    assert planner.init_from == str(tmp_path / "run" / "geometric") and planner.env == geometric.env
    assert len(reports) == 1


def test_run_planner_steps_override_the_budget_and_zero_skips_the_phase(monkeypatch, tmp_path):
    trained, _ = _phases(monkeypatch, tmp_path, "--planner-steps", "1234")
    assert trained[1].num_timesteps == 1234
    trained, reports = _phases(monkeypatch, tmp_path, "--planner-steps", "0")
    assert [c.mode for c in trained] == ["geometric"] and len(reports) == 1


def test_run_refuses_negative_planner_steps_in_one_line():
    result = subprocess.run(
        [sys.executable, "-m", "leas_jax.cli", "run", "--out", "x", "--planner-steps", "-5"],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 2
    assert "--planner-steps: expected an integer >= 0, got '-5'" in result.stderr
    assert "Traceback" not in result.stderr
