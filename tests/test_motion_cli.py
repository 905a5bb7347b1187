"""`leas motion` and `leas simulate` on the command line."""

import pytest
from motion_helpers import straight_plan

from leas_jax.cli import main


@pytest.fixture(scope="module")
def plan_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("motion") / "plan.npz"
    straight_plan(0.3).save(path)
    return path


def test_motion_then_simulate(plan_file, tmp_path, capsys):
    motion_file = tmp_path / "motion.npz"
    assert main(["motion", str(plan_file), "--out", str(motion_file)]) == 0
    out = capsys.readouterr().out
    assert "motion of" in out and "max torque ratio" in out and motion_file.is_file()
    html = tmp_path / "view.html"
    assert main(["simulate", str(motion_file), "--html", str(html)]) == 0
    out = capsys.readouterr().out
    assert "success" in out and "phases" in out
    assert html.is_file() and html.stat().st_size > 10_000


def test_bad_files_are_one_line_usage_errors(plan_file, tmp_path, capsys):
    assert main(["simulate", str(tmp_path / "absent.npz")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "no such file" in err
    assert main(["simulate", str(plan_file)]) == 2  # a plan, not a motion
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "missing key" in err
    assert main(["motion", str(tmp_path / "absent.npz"), "--out", str(tmp_path / "m.npz")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and not (tmp_path / "m.npz").exists()
