"""`leas navigate --motion`: a reached plan becomes a whole-body motion simulated in MuJoCo."""

from __future__ import annotations

from pathlib import Path

from leas_jax.cli import main
from leas_jax.motion.config import MotionConfig

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = str(ROOT / "checkpoints" / "leas_talos")
WALL = str(ROOT / "tests" / "data" / "slab_with_wall.toml")
# A short query on the slab's flat top (0.8 m straight ahead, well clear of the wall).
QUERY = ["--start", "1.0,1.0,0", "--goal", "1.8,1.0", "--workers", "0"]


def _navigate(tmp_path, *extra):
    plan, motion = tmp_path / "plan.npz", tmp_path / "motion.npz"
    args = ["navigate", "--checkpoint", SHIPPED, "--terrain", WALL, "--out", str(plan), *QUERY]
    return main([*args, "--motion", str(motion), *extra]), plan, motion


def test_a_reached_plan_is_executed_and_its_motion_saved(tmp_path, capsys):
    from leas_jax.contacts import ContactPlan
    from leas_jax.motion.motion import Motion

    code, plan_file, motion_file = _navigate(tmp_path)
    out = capsys.readouterr().out
    assert code == 0, out
    (line,) = [x for x in out.splitlines() if x.startswith(f"{motion_file}:")]
    assert "executed:" in line and "fallen no" in line and "max landing error" in line
    assert "max slip" in line and "max torque ratio" in line
    motion = Motion.load(motion_file)
    plan = ContactPlan.load(plan_file)
    assert len(motion.key_index) == len(plan) and (motion.plan_q == plan.q).all()
    assert motion.duration > 10.0  # 0.8 m at rest between postures


def test_a_motion_that_cannot_be_made_is_one_line_and_exit_code_1(tmp_path, capsys, monkeypatch):
    """A torque bound of 0.3 x the effort limits fails a real check in the first phases."""
    import leas_jax.motion.motion as motion_module

    real = motion_module.make_motion
    monkeypatch.setattr(
        motion_module, "make_motion", lambda plan, config: real(plan, MotionConfig(torque_ratio=0.3))
    )
    code, plan_file, motion_file = _navigate(tmp_path)
    captured = capsys.readouterr()
    assert code == 1 and plan_file.is_file() and not motion_file.exists()
    assert "navigate: reached" in captured.out and "Traceback" not in captured.out + captured.err
    (line,) = [x for x in captured.out.splitlines() if x.startswith(f"{motion_file}:")]
    assert "no motion:" in line and "torque limits fails" in line and "between postures" in line


def test_a_plan_made_into_a_motion_has_its_transitions_checked():
    import argparse

    from leas_jax.contacts.planner.config import motion_generator_config
    from leas_jax.navigate.commands import navigate_config, register

    parser = argparse.ArgumentParser()
    register(parser.add_subparsers(dest="command"))
    base = ["navigate", "--checkpoint", SHIPPED, "--terrain", WALL, "--out", "plan.npz", *QUERY]
    assert navigate_config(parser.parse_args(base)).generator is None  # the generator's defaults
    checked = navigate_config(parser.parse_args([*base, "--motion", "motion.npz"])).generator
    assert checked == motion_generator_config() and checked.transitions is not None


def test_a_bad_motion_path_is_a_usage_error_before_navigating(tmp_path, capsys):
    code, plan_file, _ = _navigate(tmp_path / "nowhere")
    err = capsys.readouterr().err.strip()
    assert code == 2 and "--out:" in err and len(err.splitlines()) == 1
    args = ["navigate", "--checkpoint", SHIPPED, "--terrain", WALL, "--out", str(tmp_path / "p.npz"), *QUERY]
    assert main([*args, "--motion", str(tmp_path / "motion.txt")]) == 2
    err = capsys.readouterr().err.strip()
    assert "--motion:" in err and "expected a .npz file" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "p.npz").exists()


def test_execute_plan_keeps_the_phase_and_reason():
    from motion_helpers import straight_plan

    from leas_jax.motion.execute import execute_plan

    execution = execute_plan(straight_plan(0.3), MotionConfig(torque_ratio=0.3))
    assert execution.motion is None and execution.rollout is None and not execution.success
    assert execution.fallen is None and execution.summary()["made"] is False
    line = execution.line()
    assert "\n" not in line and line.startswith("no motion: ") and "torque limits fails" in line
