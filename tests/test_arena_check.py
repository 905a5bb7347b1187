"""`leas arena-check`: arena safety of a policy and the breakdown of its invalid episodes."""

import dataclasses
import json

import numpy as np
import pytest

from leas_jax.cli import main
from leas_jax.env import heightfield_from_terrain
from leas_jax.eval.geometric import (
    NO_CYLINDER_TERM,
    arena_episodes,
    bearing_sector,
    failure_breakdown,
    reachability_terms,
)
from leas_jax.terrain import load_terrain
from leas_jax.training import load_policy


@pytest.mark.parametrize(
    "bearing, sector",
    [
        (0, "ahead"),
        (44, "ahead"),
        (-44, "ahead"),
        (46, "left"),
        (134, "left"),
        (180, "behind"),
        (-170, "behind"),
        (-90, "right"),
        (270, "right"),
        (359, "ahead"),
    ],
)
def test_bearing_sectors(bearing, sector):
    assert bearing_sector(np.array([bearing]))[0] == sector


@pytest.fixture(scope="module")
def episodes_of_a_tiny_policy(run_dir):
    policy = load_policy(run_dir)
    field = heightfield_from_terrain(load_terrain(policy.config.terrain_path()), policy.config.env)
    return policy, field, arena_episodes(policy, field, n=64, seed=0, steps=200)


def test_failure_poses_are_the_first_invalid_poses(episodes_of_a_tiny_policy):
    policy, field, episodes = episodes_of_a_tiny_policy
    config = policy.config.env.reachability
    failed = ~np.isnan(episodes.failure_poses[:, 0])
    assert failed.sum() == round((1 - episodes.valid_fraction) * 64) > 0  # the tiny policy fails often
    velocities = episodes.failure_velocities
    assert np.isnan(velocities[~failed]).all() and not np.isnan(velocities[failed]).any()
    at_failure = reachability_terms(field, episodes.failure_poses[failed], config)
    assert not np.logical_and.reduce(list(at_failure.values())).any()  # each fails some term
    last_valid = episodes.poses[np.flatnonzero(failed), episodes.lengths[failed] - 1]
    before = reachability_terms(field, last_valid, config)
    assert np.logical_and.reduce(list(before.values())).all()  # the pose before it passes them all
    step = np.linalg.norm(episodes.failure_poses[failed, :2] - last_valid[:, :2], axis=1)
    assert (step <= policy.config.env.v_max * policy.config.env.timestep + 1e-5).all()  # one step further


def test_breakdown_counts_every_invalid_episode_once(episodes_of_a_tiny_policy):
    policy, field, episodes = episodes_of_a_tiny_policy
    breakdown = failure_breakdown(field, episodes, policy.config.env.reachability)
    invalid = int((~np.isnan(episodes.failure_poses[:, 0])).sum())
    assert (
        breakdown.invalid
        == invalid
        == sum(breakdown.terms.values())
        == sum(breakdown.motion_bearing.values())
    )
    trunk = sum(count for label, count in breakdown.terms.items() if "trunk_free" in label.split("+"))
    assert sum(breakdown.trunk_bearing.values()) == trunk
    assert breakdown.speed_quartiles == sorted(breakdown.speed_quartiles)


def test_an_invalid_pose_that_every_cylinder_term_accepts_is_named_so(episodes_of_a_tiny_policy):
    """The learned condition ends episodes where the cylinders hold: the breakdown says so."""
    policy, field, episodes = episodes_of_a_tiny_policy
    first = np.flatnonzero(~np.isnan(episodes.failure_poses[:, 0]))[0]
    failure_poses = episodes.failure_poses.copy()
    failure_poses[first] = episodes.poses[first, episodes.lengths[first] - 1]  # its last valid pose
    relabelled = dataclasses.replace(episodes, failure_poses=failure_poses)
    breakdown = failure_breakdown(field, relabelled, policy.config.env.reachability)
    assert breakdown.terms[NO_CYLINDER_TERM] == 1
    assert NO_CYLINDER_TERM not in failure_breakdown(field, episodes, policy.config.env.reachability).terms


def test_arena_check_writes_its_outputs(run_dir, tmp_path, capsys):
    code = main(
        [
            "arena-check",
            "--checkpoint",
            str(run_dir),
            "--episodes",
            "32",
            "--seeds",
            "0,3",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 0
    report = json.loads((tmp_path / "arena_check.json").read_text())
    assert sorted(report["arena"]) == ["0", "3"] and report["episodes"] == 32
    for seed in ("0", "3"):
        arena = report["arena"][seed]
        assert arena["failures"]["invalid"] == round((1 - arena["valid_fraction"]) * 32)
    assert (tmp_path / "arena_failures.png").stat().st_size > 0
    assert (
        "episodes without an invalid pose (32 episodes, seed 3)" in (tmp_path / "arena_check.md").read_text()
    )
    assert "eval_ground: mean speed" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (
            ["arena-check", "--checkpoint", "nowhere", "--seeds", "a", "--out", "o"],
            "--seeds: expected comma-separated",
        ),
        (["arena-check", "--checkpoint", "nowhere", "--seeds", "-1", "--out", "o"], "integers >= 0"),
        (["arena-check", "--checkpoint", "nowhere", "--out", "o"], "nowhere: no policy.ckpt found"),
        (
            ["arena-check", "--checkpoint", "nowhere", "--terrain", "missing.toml", "--out", "o"],
            "--terrain: no such file",
        ),
    ],
)
def test_usage_errors_are_one_line(capsys, tmp_path, monkeypatch, argv, fragment):
    monkeypatch.chdir(tmp_path)
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and fragment in err, err


def test_episode_count_must_be_positive(capsys):
    with pytest.raises(SystemExit) as info:
        main(["arena-check", "--checkpoint", "x", "--episodes", "0", "--out", "o"])
    assert info.value.code == 2 and "--episodes expects an integer >= 1" in capsys.readouterr().err


def test_the_run_report_breaks_its_invalid_episodes_down(run_dir, tmp_path):
    from leas_jax.eval.report import _geometric_section

    lines, results = _geometric_section(run_dir, tmp_path, n_episodes=16)
    line = next(text for text in lines if text.startswith("Episodes that end invalid"))
    invalid = round((1 - results["arena_valid_fraction"]) * 16)
    assert (f"{invalid} episodes. Failed terms:" in line) if invalid else line.endswith("none.")
    assert (tmp_path / "rollouts_arena.png").is_file()
    assert (tmp_path / "learning_curves.png").stat().st_size > 0  # the run's metrics, on its own canvas
