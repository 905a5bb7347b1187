"""Training: config validation, atomic checkpoints, exact resume, policy loading, a real short run."""

import json
import pickle

import jax
import numpy as np
import pytest
from training_helpers import gap_field, tiny_config

from leas_jax.env import EnvConfig
from leas_jax.errors import LeasError, UsageError
from leas_jax.training import TrainConfig, checkpoint, load_policy, preset, train
from leas_jax.training.config import TRAINING_ENV, TRAINING_REACHABILITY, pretraining_config


@pytest.fixture(scope="module")
def field():
    return gap_field()


def test_presets_and_validation():
    assert preset("paper").num_timesteps == 80_000_000
    assert preset("quick").hidden_sizes == (64, 64)
    # the paper's five reward terms in `paper`; `quick` adds clearance, in both phases and its pretraining
    assert (
        preset("paper").env.rewards.clearance == 0.0 and preset("paper", mode="planner").env == TRAINING_ENV
    )
    # every preset trains with the looser TRAINING_REACHABILITY, not the calibrated default
    assert TRAINING_ENV.reachability == TRAINING_REACHABILITY != EnvConfig().reachability
    assert all(preset(name).env.reachability == TRAINING_REACHABILITY for name in ("smoke", "quick", "paper"))
    quick_planner = preset("quick", mode="planner")
    assert preset("quick").env.rewards.clearance > 0.0
    assert quick_planner.env == preset("quick").env == pretraining_config(quick_planner).env
    with pytest.raises(UsageError, match="unknown preset 'fast'"):
        preset("fast")
    with pytest.raises(UsageError, match="num_envs"):
        preset("smoke", num_envs=0)
    with pytest.raises(UsageError, match="multiple of num_minibatches"):
        preset("smoke", num_envs=100, num_minibatches=16)
    config = preset("quick", seed=3)
    assert TrainConfig.from_dict(json.loads(config.to_json())) == config
    with pytest.raises(UsageError, match="unknown TrainConfig keys: bogus"):
        TrainConfig.from_dict({**config.to_dict(), "bogus": 1})
    # a run saved before the optional terms existed loads with them off, whatever the defaults
    calibrated = preset("paper", env=EnvConfig())
    old = calibrated.to_dict()
    for key in (
        "leg_forward",
        "foothold_radius",
        "foothold_search",
        "foothold_spread",
        "hand_radius",
        "hand_forward",
        "hand_lateral",
        "hand_bottom",
    ):
        del old["env"]["reachability"][key]
    loaded = TrainConfig.from_dict(old).env.reachability
    assert loaded.leg_forward == 0.0 and loaded.hand_radius is None and loaded.foothold_spread is None
    assert loaded.trunk_bottom == calibrated.env.reachability.trunk_bottom
    assert TrainConfig.from_dict(calibrated.to_dict()) == calibrated  # a saved key wins


def test_atomic_write_leaves_no_temporary_files(tmp_path):
    checkpoint.atomic_write_text(tmp_path / "a.json", "{}")
    checkpoint.atomic_write_text(tmp_path / "a.json", '{"b": 1}')
    assert [p.name for p in tmp_path.iterdir()] == ["a.json"]
    assert json.loads((tmp_path / "a.json").read_text()) == {"b": 1}


def test_resume_continues_exactly(tmp_path, field):
    """3 calls in one go == 1 call, stop, then resume for the remaining 2 (bit for bit)."""
    config = tiny_config()
    full = train(config, tmp_path / "full", progress=False, field=field)
    part = train(config, tmp_path / "split", progress=False, field=field, stop_after_iterations=2)
    assert part.env_steps == 64 * 8 * 2
    resumed = train(config, tmp_path / "split", progress=False, field=field)
    assert resumed.env_steps == full.env_steps == config.num_iterations * config.batch_size
    a = load_policy(tmp_path / "full")
    b = load_policy(tmp_path / "split")
    for x, y in zip(jax.tree.leaves(a.params), jax.tree.leaves(b.params)):
        np.testing.assert_array_equal(x, y)
    lines = (tmp_path / "split" / "metrics.jsonl").read_text().splitlines()
    assert [json.loads(line)["iteration"] for line in lines] == [2, 4, 6]
    # keep_checkpoints=3: three step files at most, the newest last
    steps = [s for s, _ in checkpoint.list_checkpoints(tmp_path / "split")]
    assert steps[-1] == full.env_steps and len(steps) <= 3
    # the state resumed from a file has a fresh state's argument types (weak-typed scalars
    # included), so the jitted iteration is not compiled again for it
    from leas_jax.training.ppo import init_state

    fresh = init_state(config, field)
    saved = checkpoint.load_state(checkpoint.list_checkpoints(tmp_path / "split")[0][1])
    assert jax.tree.map(jax.typeof, checkpoint.like(fresh, saved)) == jax.tree.map(jax.typeof, fresh)
    assert jax.tree.map(jax.typeof, jax.tree.map(jax.numpy.asarray, saved)) != jax.tree.map(jax.typeof, fresh)


def test_like_gives_a_loaded_tree_the_fresh_trees_leaf_kinds():
    """`checkpoint.like`: weakly typed scalars where the template has Python scalars, arrays
    of its dtypes, the loaded values; None where the loaded tree holds None (a planner run's
    unsaved env state)."""
    template = {"eps": 0.01, "count": jax.numpy.zeros((), jax.numpy.int32), "w": jax.numpy.zeros(3)}
    loaded = {"eps": np.float32(0.5), "count": np.array(7, np.int64), "w": np.arange(3.0)}
    like = checkpoint.like(template, loaded)
    assert jax.typeof(like["eps"]) == jax.typeof(0.01) and float(like["eps"]) == 0.5
    assert like["count"].dtype == jax.numpy.int32 and int(like["count"]) == 7
    assert like["w"].dtype == jax.numpy.float32 and np.array_equal(like["w"], [0.0, 1.0, 2.0])
    unsaved = checkpoint.like(template, {**loaded, "w": None})
    assert unsaved["w"] is None and int(unsaved["count"]) == 7


def test_resume_refuses_a_different_config(tmp_path, field):
    train(tiny_config(), tmp_path / "run", progress=False, field=field, stop_after_iterations=2)
    with pytest.raises(UsageError, match="differs in seed"):
        train(tiny_config(seed=5), tmp_path / "run", progress=False, field=field)


def test_policy_file_and_errors(tmp_path, field):
    train(tiny_config(), tmp_path / "run", progress=False, field=field)
    policy = load_policy(tmp_path / "run")
    assert policy.config == tiny_config()
    action = np.asarray(policy(np.zeros((5, 81), np.float32)))
    assert action.shape == (5, 4) and np.all(np.abs(action) <= 1.0)
    with pytest.raises(LeasError, match="no policy.ckpt"):
        load_policy(tmp_path / "nowhere")
    bad = tmp_path / "bad.ckpt"
    bad.write_bytes(checkpoint.dumps_tree({"format": "other"}))
    with pytest.raises(LeasError, match="not a leas policy"):
        load_policy(bad)
    bad.write_bytes(b"garbage")
    with pytest.raises(LeasError, match="not a leas checkpoint file"):
        load_policy(bad)
    legacy = tmp_path / "bad.pkl"
    legacy.write_bytes(pickle.dumps({"format": "other"}))
    with pytest.raises(LeasError, match="not a leas policy"), pytest.warns(checkpoint.LegacyPickleWarning):
        load_policy(legacy, allow_pickle=True)
    legacy.write_bytes(b"garbage")
    with pytest.raises(LeasError, match="cannot read policy"), pytest.warns(checkpoint.LegacyPickleWarning):
        load_policy(legacy, allow_pickle=True)


@pytest.mark.slow
def test_short_ppo_run_improves_the_return(tmp_path, field):
    """A real 1.5 M-step PPO run on a terrain with a gap: the return clearly rises."""
    config = preset("smoke", num_timesteps=1_500_000)
    records = []
    train(config, tmp_path / "run", progress=False, field=field, on_log=records.append)
    returns = [r["episode_return"] for r in records if "episode_return" in r]
    assert np.mean(returns[-3:]) > np.mean(returns[:3]) + 50.0
