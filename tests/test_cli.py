"""The `leas` command line: one-line errors with exit code 2, rollout end to end."""

import subprocess
import sys

import numpy as np
import pytest

from leas_jax.cli import attach_negative_values, build_parser, main
from leas_jax.errors import UsageError

ARENA = "terrains/training_arena.toml"
ROLLOUT = ["rollout", "--checkpoint", "c", "--terrain", ARENA, "--out", "g.npz"]
NAVIGATE = ["navigate", "--checkpoint", "c", "--terrain", ARENA, "--out", "p.npz"]


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["train", "--preset", "fast", "--out", "x"], "invalid choice: 'fast'"),
        (["train", "--out", "x", "--timesteps", "-5"], "expected a positive integer"),
        (
            [
                "rollout",
                "--checkpoint",
                "nowhere",
                "--terrain",
                ARENA,
                "--start",
                "1,2",
                "--target",
                "3,4",
                "--out",
                "g.npz",
            ],
            "--start expects 3",
        ),
        (["rollout"], "the following arguments are required"),
        (["bogus"], "invalid choice: 'bogus'"),
        ([*ROLLOUT, "--start", "-0.9,abc,0", "--target", "3,4"], "--start expects 3"),
        ([*ROLLOUT, "--start", "1,2,0", "--target", "-1"], "--target expects 2"),
        ([*ROLLOUT, "--start", "1,2,0", "--target", "-1,-2,-3"], "--target expects 2"),
        ([*NAVIGATE, "--start", "-1,-2,nan", "--goal", "3,4"], "--start expects 3"),
        ([*NAVIGATE, "--start", "1,2,0", "--goal", "-.5,x"], "--goal expects 2"),
        ([*NAVIGATE, "--start", "1,2,0", "--goal", "3,4", "--via", "-1,2,3"], "--via expects 2"),
        ([*NAVIGATE, "--start", "1,2,0", "--goal", "3,4", "--degrees", "-1,2"], "ignored explicit argument"),
    ],
)
def test_argument_errors_are_one_line_with_exit_code_2(capsys, argv, fragment):
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    err = capsys.readouterr().err.strip()
    assert exit_info.value.code == 2
    assert len(err.splitlines()) == 1 and fragment in err and "Traceback" not in err


@pytest.mark.parametrize(
    "argv, expected",
    [
        (
            [*ROLLOUT, "--start", "-0.9,1.7,0", "--target", "-1,-2"],
            {"start": [-0.9, 1.7, 0.0], "target": [-1.0, -2.0]},
        ),
        (
            [*ROLLOUT, "--start", "-.5,3,0", "--target", "-2.5e-1,4", "--speed", "-0.1"],
            {"start": [-0.5, 3.0, 0.0], "target": [-0.25, 4.0], "speed": -0.1},
        ),
        (
            [*NAVIGATE, "--start", "-0.9,1.7,0", "--goal", "-1,-2", "--via", "-.5,3", "--via", "1,-2"],
            {"start": [-0.9, 1.7, 0.0], "goal": [-1.0, -2.0], "via": [[-0.5, 3.0], [1.0, -2.0]]},
        ),
        (
            [*NAVIGATE, "--goal=-1,-2", "--start", "-3,-4,-90", "--degrees"],
            {"start": [-3.0, -4.0, -90.0], "goal": [-1.0, -2.0], "degrees": True},
        ),
    ],
)
def test_negative_comma_separated_values_follow_their_option(argv, expected):
    args = build_parser().parse_args(argv)
    assert {name: getattr(args, name) for name in expected} == expected


def test_attach_negative_values_leaves_other_tokens_and_the_end_of_options():
    argv = ["navigate", "--start", "-1,2,0", "--degrees", "--goal=-3,4", "plan.npz", "--", "--x", "-1,2"]
    assert attach_negative_values(argv) == [
        "navigate",
        "--start=-1,2,0",
        "--degrees",
        "--goal=-3,4",
        "plan.npz",
        "--",
        "--x",
        "-1,2",
    ]


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (
            [
                "rollout",
                "--checkpoint",
                "nowhere",
                "--terrain",
                ARENA,
                "--start",
                "1,2,0",
                "--target",
                "3,4",
                "--out",
                "g.npz",
            ],
            "no policy.ckpt",
        ),
        (["train", "--out", "x", "--terrain", "missing.toml"], "--terrain: no such file"),
        (["terrain", "show", "missing.toml", "--out", "m.png"], "missing.toml"),
    ],
)
def test_bad_files_are_one_line_with_exit_code_2(capsys, tmp_path, monkeypatch, argv, fragment):
    monkeypatch.chdir(tmp_path)
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and fragment in err


def test_rollout_writes_guide_and_plot(run_dir, tmp_path, capsys):
    out = tmp_path / "guide.npz"
    code = main(
        [
            "rollout",
            "--checkpoint",
            str(run_dir),
            "--terrain",
            ARENA,
            "--start",
            "3.0,3.0,0.0",
            "--target",
            "6.0,3.0",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    data = np.load(out)
    guide = data["guide"]
    assert guide.ndim == 2 and guide.shape[1] == 4 and len(guide) >= 1
    np.testing.assert_allclose(guide[0, :2], [3.0, 3.0], atol=1e-5)
    assert float(data["timestep"]) == pytest.approx(0.1)
    assert "training_arena" in str(data["terrain"]) and data["target"].tolist() == [6.0, 3.0]
    assert out.with_suffix(".png").stat().st_size > 10_000
    assert "poses" in capsys.readouterr().out


def test_rollout_rejects_a_start_outside_the_terrain(run_dir, tmp_path, capsys):
    code = main(
        [
            "rollout",
            "--checkpoint",
            str(run_dir),
            "--terrain",
            ARENA,
            "--start",
            "30,3,0",
            "--target",
            "6,3",
            "--out",
            str(tmp_path / "g.npz"),
        ]
    )
    assert code == 2 and "outside the terrain bounds" in capsys.readouterr().err


def test_train_with_the_calibrated_reachability_condition(tmp_path, capsys):
    """`--reachability calibrated` trains with ReachabilityConfig() (both phases); the default
    keeps the presets' TRAINING_REACHABILITY, and the choice is saved in config.json."""
    from leas_jax.cli import build_parser
    from leas_jax.env import ReachabilityConfig
    from leas_jax.training import load_policy
    from leas_jax.training.commands import config_from_args
    from leas_jax.training.config import TRAINING_REACHABILITY

    small = ["--preset", "smoke", "--timesteps", "4096", "--num-envs", "64", "--no-progress"]
    assert main(["train", *small, "--reachability", "calibrated", "--out", str(tmp_path / "c")]) == 0
    assert load_policy(tmp_path / "c").config.env.reachability == ReachabilityConfig()
    assert "trained" in capsys.readouterr().out
    # the default: the same command line without the option, up to the config it trains
    default = config_from_args(build_parser().parse_args(["train", *small, "--out", str(tmp_path / "p")]))
    assert default.env.reachability == TRAINING_REACHABILITY


def test_train_sets_the_gradient_steps_per_epoch(tmp_path, capsys):
    """`--num-minibatches N` sets TrainConfig.num_minibatches in either mode (the preset's
    otherwise); one that does not divide the envs is one UsageError, zero is refused by argparse."""
    from leas_jax.cli import build_parser
    from leas_jax.training.commands import config_from_args
    from leas_jax.training.config import PLANNER_PRESETS

    parser = build_parser()
    base = ["train", "--preset", "paper", "--out", str(tmp_path / "r")]
    planner = config_from_args(parser.parse_args([*base, "--mode", "planner", "--num-minibatches", "64"]))
    assert planner.num_minibatches == 64 and planner.num_envs == 64
    default = config_from_args(parser.parse_args([*base, "--mode", "planner"]))
    assert default.num_minibatches == PLANNER_PRESETS["paper"]["num_minibatches"]
    with pytest.raises(UsageError, match="num_minibatches \\(48\\)"):
        config_from_args(parser.parse_args([*base, "--mode", "planner", "--num-minibatches", "48"]))
    with pytest.raises(SystemExit):
        parser.parse_args([*base, "--num-minibatches", "0"])
    assert "--num-minibatches" in capsys.readouterr().err


def test_train_summary_of_a_run_with_nothing_left_to_train(tmp_path):
    """`leas train`'s last line gives the speed of what it trained, and says "already trained"
    (not "nan steps/s") when a resumed run had nothing left to train."""
    from leas_jax.training.commands import training_summary
    from leas_jax.training.loop import TrainResult

    def result(metrics):
        return TrainResult(tmp_path, tmp_path / "policy.ckpt", 1_214_793, 5.2, metrics)

    assert training_summary(result({"sps": 801.9})) == (
        f"trained 1,214,793 env steps in 5 s (802 steps/s); policy: {tmp_path / 'policy.ckpt'}"
    )
    assert (
        training_summary(result({}))
        == f"already trained: 1,214,793 env steps; policy: {tmp_path / 'policy.ckpt'}"
    )


def test_console_script_runs():
    """The installed `leas` entry point answers --help without importing JAX errors."""
    result = subprocess.run([sys.executable, "-m", "leas_jax.cli", "--help"], capture_output=True, text=True)
    assert result.returncode == 0 and "rollout" in result.stdout and "train" in result.stdout


# Modules whose start-up is what makes a command line slow (JAX, Brax and what they pull in).
HEAVY = ("jax", "jaxlib", "brax", "flax", "optax", "mujoco", "pinocchio", "coal", "matplotlib", "scipy")

_HELP_PROBE = """
import contextlib, io, json, sys
from leas_jax.cli import build_parser

parser = build_parser()
commands = sorted(parser._subparsers._group_actions[0].choices)
answers = {}
for argv in [["--help"], *([name, "--help"] for name in commands), ["train", "--preset", "fast", "--out", "x"]]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            parser.parse_args(argv)
        except SystemExit as exit_:
            answers[" ".join(argv)] = [exit_.code, len(out.getvalue()), err.getvalue()]
heavy = sorted({m.split(".")[0] for m in sys.modules} & set(sys.argv[1:]))
print(json.dumps({"commands": commands, "answers": answers, "heavy": heavy}))
"""


def test_help_and_argument_errors_start_no_jax():
    """`leas --help`, every command's --help and an argument error are answered without
    importing JAX, Brax or the other heavy libraries (what made `leas --help` take seconds)."""
    import json

    done = subprocess.run(
        [sys.executable, "-c", _HELP_PROBE, *HEAVY], capture_output=True, text=True, timeout=120, check=True
    )
    probe = json.loads(done.stdout)
    assert {"train", "run", "rollout", "plan", "verify", "show", "evaluate"} <= set(probe["commands"])
    for argv, (code, out_chars, err) in probe["answers"].items():
        if argv.endswith("--help"):
            assert code == 0 and out_chars > 100, argv
        else:
            assert code == 2 and "invalid choice: 'fast'" in err, argv
    assert len(probe["answers"]) == len(probe["commands"]) + 2
    assert probe["heavy"] == []
