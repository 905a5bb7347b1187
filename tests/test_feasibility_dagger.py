"""The DAgger loop of the learned condition: the generator's verdicts on the policy's guides
become labelled poses, the policy's failed poses among them, and refresh the condition."""

import dataclasses
import os
import warnings
from types import SimpleNamespace

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from leas_jax.env import learned_feasibility as lf
from leas_jax.training import preset, train
from leas_jax.training.config import TRAINING_ENV
from leas_jax.training.planner import VERDICT_HORIZON, verdict_samples

FAIL_AT = 30  # the fake generator covers guide poses 0..FAIL_AT - 1


def _guide(n, x0=0.0):
    return np.column_stack([x0 + 0.01 * np.arange(n), np.zeros(n), np.ones(n), np.zeros(n)])


def test_verdict_samples_by_hand():
    # guide 0: 50 poses, covered to pose 29: pose 30 infeasible, covered picks among 0..9 (29 - 20)
    # guide 1: 15 poses, fully covered: picks among all 15; guide 2: no first stance: pose 0 infeasible
    # guide 3: covered to pose 5 of 40: pose 6 infeasible, no covered pose is sure (5 - 20 < 0)
    guides = [_guide(50), _guide(15, 1.0), _guide(10, 2.0), _guide(40, 3.0)]
    poses, labels = verdict_samples(guides, np.array([29, 14, -1, 5]), np.random.default_rng(0))
    failed = poses[~labels]
    np.testing.assert_allclose(failed, np.stack([guides[0][30], guides[2][0], guides[3][6]]))
    covered = poses[labels]
    assert len(covered) == 8  # four from guide 0, four from guide 1
    x = covered[:, 0]
    assert np.all((x[:4] >= 0.0) & (x[:4] <= 0.01 * (29 - VERDICT_HORIZON) + 1e-9))
    assert np.all((x[4:] >= 1.0) & (x[4:] <= 1.14 + 1e-9))
    empty_poses, empty_labels = verdict_samples([], np.zeros(0, int), np.random.default_rng(0))
    assert empty_poses.shape == (0, 4) and empty_labels.shape == (0,)


def _fail_at(terrain, guide, timestep, config=None):
    """plan_fn: covers poses 0..FAIL_AT - 1 of each guide; records each first uncovered pose."""
    last = min(FAIL_AT - 1, len(guide) - 1)
    if last < len(guide) - 1:
        with open(os.environ["LEAS_TEST_FAILED_POSES"], "a") as f:
            f.write(" ".join(repr(float(v)) for v in guide[last + 1]) + "\n")
    return SimpleNamespace(coverage=(last + 1) / len(guide), last_valid_index=last)


def test_the_loop_adds_the_policys_failed_poses_and_refreshes_the_condition(tmp_path, monkeypatch):
    record_file = tmp_path / "failed.txt"
    monkeypatch.setenv("LEAS_TEST_FAILED_POSES", str(record_file))
    reach = TRAINING_ENV.reachability
    params = lf.init_params(jax.random.PRNGKey(0), hidden=(8, 4), reach=reach)
    weights = lf.save_params(tmp_path / "start.npz", {**params, "threshold": jnp.asarray(-1e9)})
    env = dataclasses.replace(TRAINING_ENV, condition="learned", learned_weights=str(weights))
    config = preset(
        "smoke",
        mode="planner",
        terrain="terrains/eval_ground.toml",
        num_timesteps=200,
        num_envs=8,
        num_minibatches=2,
        num_epochs=1,
        checkpoint_every_s=0.0,
        env=dataclasses.replace(env, episode_length=60),
        condition_refresh_every=1,
        condition_refresh_min_poses=10,
        condition_anchor_poses=50,
    )
    records = []
    train(
        config,
        tmp_path / "run",
        progress=False,
        workers=0,
        on_log=records.append,
        pool_options=dict(plan_fn=_fail_at),
    )
    assert records and all(r["condition_poses_added"] > 0 for r in records)
    assert "condition_threshold" in records[0]  # refreshed at the first iteration already
    with np.load(tmp_path / "run" / "condition_data.npz") as data:
        poses, labels = data["poses"], data["labels"]
        anchors, anchor_labels = data["anchor_poses"], data["anchor_labels"]
    # the anchors: drawn as resets are (flat eval_ground: z = nominal root height), labelled by
    # the starting condition (threshold -1e9: every pose feasible)
    assert anchors.shape == (50, 4) and anchor_labels.all()
    np.testing.assert_allclose(anchors[:, 2], TRAINING_ENV.nominal_root_height, atol=1e-5)
    recorded = np.loadtxt(record_file, ndmin=2)
    failed = poses[~labels]
    # every failed pose of the validated batches is in the data, labelled infeasible (the
    # recorded file may also hold the batch in flight when the run stopped)
    assert len(failed) > 0 and len(failed) <= len(recorded)
    for pose in failed:
        assert np.min(np.abs(recorded - pose).max(axis=1)) < 1e-5
    assert labels.any()
    refreshed, _ = lf.load_params(tmp_path / "run" / "condition.npz")
    assert not np.array_equal(np.asarray(refreshed["w0"]), np.asarray(params["w0"]))
    assert float(refreshed["threshold"]) > -1e9
    # the trained policy carries the condition its last updates were made with
    from leas_jax.training.policy import load_policy

    assert load_policy(tmp_path / "run").config.env.learned_weights == str(tmp_path / "run" / "condition.npz")


def test_a_run_saved_before_the_learned_condition_existed_still_resumes():
    """config.json of an earlier version lacks the condition fields: their defaults are what it trained."""
    import json

    from leas_jax.training.loop import _config_differences

    config = preset("smoke")
    saved = json.loads(config.to_json())
    del saved["condition_refresh_every"], saved["condition_refresh_min_poses"]
    del saved["env"]["condition"], saved["env"]["learned_weights"]
    assert _config_differences(saved, config) == []
    saved["seed"] = 5
    assert _config_differences(saved, config) == ["seed"]


def test_anchor_samples_carry_the_conditions_own_verdicts():
    """`anchor_samples` labels its poses with the field's condition (here the cylinders of a
    field with a gap: poses over the gap are infeasible)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from training_helpers import gap_field

    from leas_jax.env import condition
    from leas_jax.env.config import EnvConfig
    from leas_jax.training.planner import anchor_samples

    field = gap_field()  # its spawn points: the default cylinders hold at every yaw
    # legs 0.6 m to the side: beside the gap they reach over it at some yaws
    env = EnvConfig(reachability=dataclasses.replace(EnvConfig().reachability, leg_lateral_offset=0.6))
    poses, labels = anchor_samples(field, env, 400, np.random.default_rng(0))
    assert poses.shape == (400, 4) and labels.shape == (400,)
    expected = np.array([bool(condition.valid(field, jnp.asarray(p, jnp.float32), env)) for p in poses[:60]])
    np.testing.assert_array_equal(labels[:60], expected)
    assert 0.0 < labels.mean() < 1.0  # some beside the gap fail, most pass


def test_seed_data_is_fitted_at_every_refresh(tmp_path, monkeypatch):
    """`TrainConfig.condition_seed_data`: its labelled poses join the verdicts in every refit."""
    import leas_jax.feasibility.fit as feasibility
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.terrain import load_terrain
    from leas_jax.training.planner import VerdictData

    reach = TRAINING_ENV.reachability
    params = lf.init_params(jax.random.PRNGKey(0), hidden=(8, 4), reach=reach)
    weights = lf.save_params(tmp_path / "start.npz", {**params, "threshold": jnp.asarray(0.0)})
    env = dataclasses.replace(TRAINING_ENV, condition="learned", learned_weights=str(weights))
    seed_poses = np.column_stack(
        [np.linspace(3.0, 5.0, 30), np.full(30, 4.0), np.full(30, 1.0), np.zeros(30)]
    )
    seed_labels = np.arange(30) % 3 == 0
    np.savez(tmp_path / "seed.npz", poses=seed_poses, labels=seed_labels)
    config = dataclasses.replace(
        preset("smoke", mode="planner"),
        env=env,
        condition_refresh_every=1,
        condition_seed_data=str(tmp_path / "seed.npz"),
    )
    field = heightfield_from_terrain(load_terrain("terrains/eval_ground.toml"), env)
    verdicts = VerdictData(config)
    verdicts.add([_guide(50, 3.0), _guide(40, 4.0)], np.array([29, 39]))
    fitted = {}

    def spy(x, y, *args, **kwargs):
        fitted["x"], fitted["y"] = x, y
        return fit(x, y, *args, **kwargs)

    fit = feasibility.fit
    monkeypatch.setattr(feasibility, "fit", spy)
    verdicts.refresh(field)
    own = len(verdicts.labels)
    assert len(fitted["y"]) == 30 + own
    np.testing.assert_array_equal(fitted["y"][:30], seed_labels)
    expected = feasibility.features_of(field.condition, field, seed_poses, reach)
    np.testing.assert_allclose(fitted["x"][:30], expected, rtol=1e-5, atol=1e-5)


def test_bad_seed_data_is_refused_naming_the_field(tmp_path):
    import pytest

    from leas_jax.errors import UsageError
    from leas_jax.training.planner import seed_data

    cases = {
        "missing.npz": None,
        "no_labels.npz": {"poses": np.zeros((3, 4))},
        "short_poses.npz": {"poses": np.zeros((3, 3)), "labels": np.ones(3, bool)},
        "float_labels.npz": {"poses": np.zeros((3, 4)), "labels": np.ones(3)},
        "nan.npz": {"poses": np.full((3, 4), np.nan), "labels": np.ones(3, bool)},
    }
    for name, arrays in cases.items():
        if arrays is not None:
            np.savez(tmp_path / name, **arrays)
        with pytest.raises(UsageError, match=f"TrainConfig.condition_seed_data: .*{name}"):
            seed_data(tmp_path / name)
    np.savez(tmp_path / "good.npz", poses=np.zeros((3, 4)), labels=np.array([True, False, True]))
    poses, labels = seed_data(tmp_path / "good.npz")
    assert poses.shape == (3, 4) and labels.tolist() == [True, False, True]


def test_train_command_takes_seed_data_for_the_dagger_phase_only(tmp_path):
    import pytest

    from leas_jax.cli import build_parser
    from leas_jax.errors import UsageError
    from leas_jax.training.commands import config_from_args

    np.savez(tmp_path / "seed.npz", poses=np.zeros((3, 4)), labels=np.array([True, False, True]))
    parser = build_parser()
    base = ["train", "--out", "r", "--preset", "smoke", "--condition-seed-data", str(tmp_path / "seed.npz")]
    chosen = config_from_args(parser.parse_args([*base, "--mode", "planner", "--reachability", "learned"]))
    assert chosen.condition_seed_data == str(tmp_path / "seed.npz")
    for extra in ([], ["--reachability", "learned"], ["--mode", "planner"]):
        with pytest.raises(
            UsageError, match="--condition-seed-data is for --mode planner --reachability learned"
        ):
            config_from_args(parser.parse_args([*base, *extra]))


def test_a_refit_sets_its_threshold_for_the_configured_sensitivity(tmp_path, monkeypatch):
    """`TrainConfig.condition_refresh_sensitivity` is the target sensitivity a refit sets its
    threshold for (None: FitConfig's); a higher one gives a threshold no higher, from the same
    data and weights."""
    import leas_jax.feasibility.fit as feasibility
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.errors import UsageError
    from leas_jax.feasibility.fit import FitConfig
    from leas_jax.terrain import load_terrain
    from leas_jax.training.planner import VerdictData

    reach = TRAINING_ENV.reachability
    params = lf.init_params(jax.random.PRNGKey(0), hidden=(8, 4), reach=reach)
    weights = lf.save_params(tmp_path / "start.npz", {**params, "threshold": jnp.asarray(0.0)})
    env = dataclasses.replace(TRAINING_ENV, condition="learned", learned_weights=str(weights))
    field = heightfield_from_terrain(load_terrain("terrains/eval_ground.toml"), env)
    guides = [_guide(60, x0) for x0 in np.linspace(2.0, 6.0, 12)]
    last_valid = np.array([29 if k % 2 else 59 for k in range(12)])
    fit, used = feasibility.fit, []

    def spy(x, y, config, **kwargs):
        used.append(config.target_sensitivity)
        return fit(x, y, config, **kwargs)

    monkeypatch.setattr(feasibility, "fit", spy)
    thresholds = []
    for sensitivity in (None, 1.0):
        config = dataclasses.replace(
            preset("smoke", mode="planner"),
            env=env,
            condition_refresh_every=1,
            condition_refresh_sensitivity=sensitivity,
        )
        verdicts = VerdictData(config, seed=0)
        verdicts.add(guides, last_valid)
        _, info = verdicts.refresh(field)
        thresholds.append(info["threshold"])
    assert used == [FitConfig().target_sensitivity, 1.0]
    assert thresholds[1] <= thresholds[0]
    with pytest.raises(UsageError, match="condition_refresh_sensitivity"):
        dataclasses.replace(preset("smoke", mode="planner"), condition_refresh_sensitivity=1.5).validate()


def test_a_run_keeps_the_learned_condition_it_started_with(tmp_path, monkeypatch):
    """A run with the learned condition copies its weights beside its policy: relabelling the
    default weights afterwards changes neither the resumed run nor its policy's environment."""
    from leas_jax.feasibility import spawns
    from leas_jax.training.policy import load_policy

    params = lf.init_params(jax.random.PRNGKey(0), hidden=(8, 4), reach=TRAINING_ENV.reachability)
    weights = lf.save_params(tmp_path / "walking.npz", {**params, "threshold": jnp.asarray(-1e9)})
    started_with = weights.read_bytes()
    env = dataclasses.replace(
        TRAINING_ENV, condition="learned", learned_weights=str(weights), episode_length=20
    )
    config = preset(
        "smoke", terrain="terrains/eval_ground.toml", num_timesteps=2 * 64 * 16, num_envs=64,
        num_minibatches=2, num_epochs=1, iterations_per_call=1, checkpoint_every_s=0.0, env=env,
    )  # fmt: skip
    built_from = []
    arena_field = spawns.arena_field
    monkeypatch.setattr(
        spawns, "arena_field", lambda terrain, env, **kw: built_from.append(env.learned_weights) or arena_field(terrain, env, **kw)
    )  # fmt: skip
    run = tmp_path / "run"
    train(config, run, progress=False, stop_after_iterations=1)
    assert (run / "condition.npz").read_bytes() == started_with
    lf.save_params(weights, {**params, "threshold": jnp.asarray(1e9)})  # relabelled: rejects every pose
    train(config, run, progress=False)  # resumes to the end
    assert built_from == [str(weights), str(run / "condition.npz")]
    assert (run / "condition.npz").read_bytes() == started_with
    assert load_policy(run).config.env.learned_weights == str(run / "condition.npz")


def test_a_run_starting_with_weights_of_another_generator_warns(tmp_path):
    """A new run copying weights whose labels' key is not the current generator's warns once,
    naming the file; a run that holds its copy already (resuming) does not check again."""
    from leas_jax.feasibility.walking_truth import StaleConditionWarning
    from leas_jax.training.loop import RUN_CONDITION, _pin_condition

    params = lf.init_params(jax.random.PRNGKey(0), hidden=(8, 4), reach=TRAINING_ENV.reachability)
    weights = lf.save_params(
        tmp_path / "walking.npz", params, data_key="0" * 64, terrain="terrains/training_arena.toml"
    )
    env = dataclasses.replace(TRAINING_ENV, condition="learned", learned_weights=str(weights))
    with pytest.warns(StaleConditionWarning, match="walking.npz: the learned condition was fitted"):
        _pin_condition(tmp_path / "run", env)
    assert (tmp_path / "run" / RUN_CONDITION).read_bytes() == weights.read_bytes()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _pin_condition(tmp_path / "run", env)
