"""Planner-in-the-loop training: pruning, masked loss, end-to-end runs, worker deaths, resume."""

import functools
import os
import shutil

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from brax.training.agents.ppo import losses as ppo_losses
from brax.training.types import Transition

from leas_jax.env import heightfield_from_raster
from leas_jax.training import load_policy, preset, train
from leas_jax.training.networks import make_networks
from leas_jax.training.planner import masked_ppo_loss, prune_after_failure
from leas_jax.training.ppo import init_state

GROUND = "terrains/eval_ground.toml"


def test_prune_after_failure_by_hand():
    # 3 episodes of up to 5 steps. Episode 0 ran 5 steps (guide 6 poses), generator stopped at pose 2:
    # steps 0, 1 kept, step 2 (pose 2 -> 3) terminal, steps 3, 4 masked.
    # Episode 1 ended invalid at step 2 (guide 3 poses), fully covered (l = 2): unchanged.
    # Episode 2: no valid first stance (l = -1): all masked.
    alive = np.array([[1, 1, 1, 1, 1], [1, 1, 1, 0, 0], [1, 1, 1, 1, 1]], np.float32)
    done = np.array([[0, 0, 0, 0, 1], [0, 0, 1, 0, 0], [0, 0, 0, 0, 1]], np.float32)
    trunc = np.array([[0, 0, 0, 0, 1], [0, 0, 0, 0, 0], [0, 0, 0, 0, 1]], np.float32)
    mask, new_done, new_trunc = prune_after_failure(
        alive, done, trunc, np.array([6, 3, 6]), np.array([2, 2, -1])
    )
    np.testing.assert_array_equal(mask, [[1, 1, 1, 0, 0], [1, 1, 1, 0, 0], [0, 0, 0, 0, 0]])
    np.testing.assert_array_equal(new_done, [[0, 0, 1, 0, 0], [0, 0, 1, 0, 0], [0, 0, 0, 0, 0]])
    np.testing.assert_array_equal(new_trunc, np.zeros((3, 5)))


def test_masked_loss_equals_brax_loss_without_mask():
    """With every step kept, our masked loss is Brax's PPO loss (episodes ending in a termination)."""
    config = preset("smoke", mode="planner")
    heights = np.zeros((101, 101), np.float32)
    state = init_state(config, heightfield_from_raster(heights, (0.0, 0.0), 0.02, -2.0))
    network = make_networks(config)
    b, t = 4, 6
    k = jax.random.split(jax.random.PRNGKey(0), 4)
    obs = jax.random.normal(k[0], (b, t, 81))
    raw = jax.random.normal(k[1], (b, t, 4))
    reward = jax.random.uniform(k[2], (b, t))
    done = jnp.zeros((b, t)).at[:, -1].set(1.0)
    logp = jax.random.normal(k[3], (b, t)) - 3.0
    ours, ours_m = jax.jit(lambda *args: masked_ppo_loss(*args, network, config))(
        state.params,
        state.normalizer,
        dict(
            observation=obs,
            raw_action=raw,
            log_prob=logp,
            reward=reward,
            done=done,
            truncation=jnp.zeros((b, t)),
            mask=jnp.ones((b, t)),
        ),
        jax.random.PRNGKey(1),
    )
    data = Transition(
        observation=obs,
        action=jnp.tanh(raw),
        reward=reward,
        discount=1 - done,
        next_observation=obs,
        extras={
            "policy_extras": {"raw_action": raw, "log_prob": logp, "distribution_params": obs[..., :8]},
            "state_extras": {"truncation": jnp.zeros((b, t))},
        },
    )
    brax_loss = functools.partial(
        ppo_losses.compute_ppo_loss,
        ppo_network=network,
        entropy_cost=config.entropy_cost,
        discounting=config.discounting,
        gae_lambda=config.gae_lambda,
        clipping_epsilon=config.clipping_epsilon,
        vf_coefficient=config.vf_coefficient,
    )
    theirs, theirs_m = jax.jit(brax_loss)(state.params, state.normalizer, data, jax.random.PRNGKey(1))
    np.testing.assert_allclose(ours_m["policy_loss"], theirs_m["policy_loss"], rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(ours_m["v_loss"], theirs_m["v_loss"], rtol=1e-4, atol=1e-6)
    # the entropy of a tanh-Gaussian is estimated from samples, drawn in another layout: compare the rest
    ours_rest = ours + config.entropy_cost * ours_m["entropy"]
    theirs_rest = theirs - theirs_m["entropy_loss"]
    np.testing.assert_allclose(ours_rest, theirs_rest, rtol=1e-4, atol=1e-6)


def tiny_planner_config(**overrides):
    return preset(
        "smoke",
        mode="planner",
        terrain=GROUND,
        **{
            **dict(num_timesteps=300, num_envs=4, num_minibatches=2, num_epochs=1, checkpoint_every_s=0.0),
            **overrides,
        },
    )


def test_planner_training_runs_and_logs(tmp_path):
    """In-process validation (workers=0): every iteration logs the planner metrics."""
    records = []
    result = train(tiny_planner_config(), tmp_path / "run", progress=False, workers=0, on_log=records.append)
    assert result.env_steps >= 300 and records
    for key in (
        "env_steps",
        "discarded_fraction",
        "mean_coverage",
        "full_coverage_fraction",
        "validation_wait_s",
        "wait_fraction",
        "kept_steps",
        "rolled_steps",
    ):
        assert key in records[-1], key
    assert 0.0 <= records[-1]["discarded_fraction"] <= 1.0 and 0.0 <= records[-1]["mean_coverage"] <= 1.0
    assert load_policy(tmp_path / "run").config.mode == "planner"


def _die_once(terrain, guide, timestep, config=None):
    """plan_fn for the pool: the first call in a fresh worker kills it (marker file), later calls plan."""
    marker = os.environ["LEAS_TEST_DIE_MARKER"]
    if not os.path.exists(marker):
        open(marker, "w").close()
        os._exit(1)
    from leas_jax.contacts import plan_contacts

    return plan_contacts(terrain, guide, timestep)


def test_a_killed_worker_costs_a_retry_not_the_run(tmp_path, monkeypatch):
    monkeypatch.setenv("LEAS_TEST_DIE_MARKER", str(tmp_path / "died"))
    records = []
    result = train(
        tiny_planner_config(),
        tmp_path / "run",
        progress=False,
        workers=1,
        on_log=records.append,
        pool_options=dict(plan_fn=_die_once),
    )
    assert (tmp_path / "died").exists(), "the worker was killed once"
    assert result.env_steps >= 300
    assert all(r["generator_errors"] == 0 for r in records), "the killed path was retried, not lost"


def test_interrupted_planner_run_resumes(tmp_path):
    config = tiny_planner_config(num_timesteps=600)
    first = train(config, tmp_path / "run", progress=False, workers=0, stop_after_iterations=1)
    assert 0 < first.env_steps < 600
    resumed = train(config, tmp_path / "run", progress=False, workers=0)
    assert resumed.env_steps >= 600
    iterations = [
        int(line.split('"iteration": ')[1].split(",")[0])
        for line in (tmp_path / "run" / "metrics.jsonl").read_text().splitlines()
    ]
    assert iterations == list(range(1, len(iterations) + 1)), "the resumed run continues the iteration count"


def test_init_from_a_geometric_run(tmp_path):
    geo = preset(
        "smoke",
        terrain=GROUND,
        num_timesteps=64 * 8 * 2,
        num_envs=64,
        unroll_length=8,
        num_minibatches=2,
        num_epochs=1,
        iterations_per_call=2,
    )
    train(geo, tmp_path / "geo", progress=False)
    config = tiny_planner_config(init_from=str(tmp_path / "geo"), num_timesteps=1)
    train(config, tmp_path / "fine", progress=False, workers=0, stop_after_iterations=0)
    a, b = load_policy(tmp_path / "geo"), load_policy(tmp_path / "fine")
    for x, y in zip(jax.tree.leaves(a.params), jax.tree.leaves(b.params)):
        np.testing.assert_array_equal(x, y)


def test_planner_learning_rate_decays_linearly_over_kept_steps():
    from leas_jax.training.ppo import planner_learning_rate

    config = tiny_planner_config(learning_rate=1e-3, num_timesteps=1000, learning_rate_schedule="linear")
    assert float(planner_learning_rate(config, jnp.int32(0))) == pytest.approx(1e-3)
    assert float(planner_learning_rate(config, jnp.int32(250))) == pytest.approx(7.5e-4)
    assert float(planner_learning_rate(config, jnp.int32(5000))) == 0.0
    constant = tiny_planner_config(learning_rate=1e-3, learning_rate_schedule="constant")
    assert float(planner_learning_rate(constant, jnp.int32(5000))) == pytest.approx(1e-3)


def test_planner_update_applies_the_scheduled_rate(tmp_path):
    """Past the end of the linear schedule the rate is 0: the update moves no parameter."""
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.terrain import load_terrain
    from leas_jax.training.planner import make_planner_fns, training_batch

    config = tiny_planner_config(num_timesteps=1000, learning_rate_schedule="linear")
    field = heightfield_from_terrain(load_terrain(config.terrain_path()), config.env)
    rollout, update = make_planner_fns(config)
    state = init_state(config, field)
    episodes = rollout(state, field, jax.random.PRNGKey(1))
    batch, _ = training_batch(episodes, np.full(config.num_envs, 10_000))
    moved, metrics = update(state, batch, jax.random.PRNGKey(2))
    assert float(metrics["learning_rate"]) == pytest.approx(config.learning_rate)
    assert any(
        not np.array_equal(a, b) for a, b in zip(jax.tree.leaves(state.params), jax.tree.leaves(moved.params))
    )
    finished = state.replace(env_steps=jnp.int32(config.num_timesteps))
    frozen, metrics = update(finished, batch, jax.random.PRNGKey(2))
    assert float(metrics["learning_rate"]) == 0.0
    for a, b in zip(jax.tree.leaves(state.params), jax.tree.leaves(frozen.params)):
        np.testing.assert_array_equal(a, b)


def test_planner_preset_pretrains_a_geometric_policy_first(tmp_path, monkeypatch):
    """Without --init, a planner config with `pretrain` trains that geometric preset in <out>/pretrain
    and starts from it; a second call resumes instead of pretraining again."""
    from leas_jax.training import config as config_module

    monkeypatch.setitem(
        config_module.PRESETS,
        "tiny",
        dict(
            num_timesteps=64 * 8 * 2,
            num_envs=64,
            unroll_length=8,
            num_minibatches=2,
            num_epochs=1,
            iterations_per_call=2,
        ),
    )
    config = tiny_planner_config(pretrain="tiny", num_timesteps=1)
    train(config, tmp_path / "run", progress=False, workers=0, stop_after_iterations=0)
    pretrained = load_policy(tmp_path / "run" / "pretrain")
    assert pretrained.config.mode == "geometric" and pretrained.config.seed == config.seed
    for x, y in zip(
        jax.tree.leaves(pretrained.params), jax.tree.leaves(load_policy(tmp_path / "run").params)
    ):
        np.testing.assert_array_equal(x, y)
    pretrain_files = {
        p: p.stat().st_mtime_ns for p in (tmp_path / "run" / "pretrain").rglob("*") if p.is_file()
    }
    train(config, tmp_path / "run", progress=False, workers=0, stop_after_iterations=0)
    # a finished pretraining is not opened again, even when the planner phase has no checkpoint yet
    shutil.rmtree(tmp_path / "run" / "checkpoints")
    train(config, tmp_path / "run", progress=False, workers=0, stop_after_iterations=0)
    assert {
        p: p.stat().st_mtime_ns for p in (tmp_path / "run" / "pretrain").rglob("*") if p.is_file()
    } == pretrain_files


def test_unknown_pretrain_preset_is_rejected():
    from leas_jax.errors import UsageError

    with pytest.raises(UsageError, match="pretrain"):
        tiny_planner_config(pretrain="nope")
