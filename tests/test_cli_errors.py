"""Bad input on the command line: one line, exit code 2, nothing written; files keep the user's umask;
guides past MAX_GUIDE_POSES are refused."""

import os
import stat

import numpy as np
import pytest

from leas_jax.cli import main
from leas_jax.contacts.plan import MAX_GUIDE_POSES, ContactPlan
from leas_jax.training import checkpoint

GROUND = "terrains/eval_ground.toml"
ROLLOUT = ["rollout", "--terrain", GROUND, "--start", "4,4,0", "--target", "8,4"]


def _one_line_error(capsys, argv) -> str:
    """Run `leas argv`: exit code 2 (returned or argparse's SystemExit), one line on stderr."""
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    return err


def _policy_file(tmp_path, run_dir, edit) -> str:
    """A policy.ckpt: the shared tiny run's payload, changed by `edit(payload)`."""
    payload = checkpoint.read_policy_payload(run_dir / "policy.ckpt")
    edit(payload)
    path = tmp_path / "edited.ckpt"
    path.write_bytes(checkpoint.dumps_tree(payload))
    return str(path)


def _kernel(payload):
    return payload["policy_params"]["params"]["hidden_0"]["kernel"]


@pytest.mark.parametrize(
    "edit, fragment",
    [
        (lambda p: p.pop("config"), "policy file without config"),
        (lambda p: p["config"].update(num_envs="many"), "the policy's config is invalid"),
        (
            lambda p: p["policy_params"]["params"]["hidden_0"].update(kernel=np.zeros((3, 3), np.float32)),
            "the config's networks need float32[81, ",
        ),
        (lambda p: p["policy_params"].pop("params"), "do not fit the config's networks"),
        (lambda p: _kernel(p).__setitem__((0, 0), np.nan), "holds NaN or inf"),
        (lambda p: p["normalizer"].mean.__setitem__(0, np.inf), "normalizer"),
    ],
    ids=["no config", "bad config", "wrong shape", "wrong tree", "NaN params", "inf normaliser"],
)
def test_broken_policies_are_one_line_errors(capsys, tmp_path, run_dir, edit, fragment):
    policy = _policy_file(tmp_path, run_dir, edit)
    out = tmp_path / "g.npz"
    err = _one_line_error(capsys, [*ROLLOUT, "--checkpoint", policy, "--out", str(out)])
    assert fragment in err and not out.exists()


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--max-steps", "-5"], "--max-steps"),
        (["--max-steps", "0"], "--max-steps"),
        (["--max-steps", str(MAX_GUIDE_POSES)], f"1 to {MAX_GUIDE_POSES - 1} steps"),
        (["--speed", "nan"], "expected a finite number"),
        (["--speed", "inf"], "expected a finite number"),
        (["--speed", "2.0"], "v_max"),
        (["--speed", "-0.1"], "v_max"),
    ],
)
def test_rollout_arguments_are_checked(capsys, tmp_path, run_dir, extra, fragment):
    out = tmp_path / "g.npz"
    err = _one_line_error(capsys, [*ROLLOUT, "--checkpoint", str(run_dir), "--out", str(out), *extra])
    assert fragment in err and not out.exists()


def test_object_array_guide_is_a_one_line_error(capsys, tmp_path):
    guide = tmp_path / "objects.npz"
    np.savez(guide, guide=np.array([{"x": 1}, None], dtype=object), timestep=0.1)
    err = _one_line_error(
        capsys, ["plan", "--guide", str(guide), "--terrain", GROUND, "--out", str(tmp_path / "p.npz")]
    )
    assert "key 'guide' cannot be read" in err
    np.savez(guide, guide=np.zeros((3, 4)), timestep=0.1, target=np.array([object(), object()], dtype=object))
    assert "key 'target'" in _one_line_error(
        capsys, ["plan", "--guide", str(guide), "--terrain", GROUND, "--out", str(tmp_path / "p.npz")]
    )


def _plan(guide_poses: int) -> ContactPlan:
    guide = np.zeros((guide_poses, 4))
    guide[:, 0] = np.linspace(4.0, 5.0, guide_poses)
    guide[:, 1] = 4.0
    guide[:, 2] = 1.0
    return ContactPlan(
        q=np.zeros((0, 39)),
        feet=np.zeros((0, 2, 7)),
        guide_index=np.zeros(0, np.int64),
        last_valid_index=-1,
        coverage=0.0,
        terrain=open(GROUND).read(),
        guide=guide,
    )


def test_show_checks_its_outputs_before_writing_anything(capsys, tmp_path):
    plan = tmp_path / "p.npz"
    _plan(5).save(plan)
    html = tmp_path / "view.html"
    err = _one_line_error(capsys, ["show", str(plan), "--out", str(html), "--png", str(tmp_path / "f.txt")])
    assert "--png" in err and "*.png" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.npz"]
    assert "--out" in _one_line_error(capsys, ["show", str(plan), "--out", str(tmp_path / "view.png")])


def test_guides_past_the_bound_are_refused_by_plan_show_and_verify(capsys, tmp_path):
    long_guide = tmp_path / "long.npz"
    np.savez(long_guide, guide=_plan(MAX_GUIDE_POSES + 1).guide, timestep=0.1)
    err = _one_line_error(
        capsys, ["plan", "--guide", str(long_guide), "--terrain", GROUND, "--out", str(tmp_path / "p.npz")]
    )
    assert f"{MAX_GUIDE_POSES + 1} poses, more than the {MAX_GUIDE_POSES}" in err
    plan = tmp_path / "long_plan.npz"
    _plan(MAX_GUIDE_POSES + 1).save(plan)
    for command in (["show", str(plan), "--no-robot"], ["verify", str(plan)]):
        assert f"more than {MAX_GUIDE_POSES}" in _one_line_error(capsys, command)
    assert not (tmp_path / "long_plan.html").exists()


@pytest.mark.parametrize("umask", [0o022, 0o027])
def test_written_files_follow_the_umask(tmp_path, run_dir, umask):
    from leas_jax.steering.commands import save_guide

    policy = checkpoint.read_policy_payload(run_dir / "policy.ckpt")
    old = os.umask(umask)
    try:
        save_guide(tmp_path / "g.npz", np.zeros((2, 4)), 0.1, "text", [1.0, 2.0])
        _plan(3).save(tmp_path / "p.npz")
        checkpoint.save_policy(tmp_path, policy["normalizer"], policy["policy_params"], policy["config"], 1)
        checkpoint.atomic_write_text(tmp_path / "c.json", "{}")
    finally:
        os.umask(old)
    for name in ("g.npz", "p.npz", "policy.ckpt", "c.json"):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o666 & ~umask, name


def test_n_starts_is_bounded_on_the_command_line(capsys, tmp_path):
    from leas_jax.terrain.loader import MAX_STARTS

    for command in (["evaluate", "--scenario", "ground"], ["hole-sweep"]):
        err = _one_line_error(
            capsys,
            [*command, "--methods", "rblin", "--n-starts", str(MAX_STARTS + 1), "--out", str(tmp_path / "o")],
        )
        assert f"<= {MAX_STARTS}" in err
    assert not (tmp_path / "o").exists()
