"""LeasEnv: smoke test on every committed terrain, resets, targets, termination."""

import dataclasses
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from leas_jax.env import (
    EnvConfig,
    FreshResetVmap,
    LeasEnv,
    RewardWeights,
    heightfield_from_raster,
    heightfield_from_terrain,
    reachability,
)
from leas_jax.terrain import load_terrain
from leas_jax.training.config import TRAINING_ENV

TERRAINS = sorted(Path(__file__).resolve().parents[1].glob("terrains/*.toml"))


def flat_field(config=EnvConfig(), size=201):
    return heightfield_from_raster(np.zeros((size, size), np.float32), (0.0, 0.0), 0.02, -2.0, config)


@pytest.mark.parametrize("path", TERRAINS, ids=lambda p: p.stem)
def test_smoke_jit_vmap_1024_envs(path):
    """jit reset and step, vmap over 1024 envs: shapes match, no NaN, resets are valid."""
    field = heightfield_from_terrain(load_terrain(path))
    env = LeasEnv(field)

    @jax.jit
    def run(field, key):
        wrapped = FreshResetVmap(env.with_field(field))
        state = wrapped.reset(jax.random.split(key, 1024))
        first = state
        actions = jax.random.uniform(key, (20, 1024, 4), minval=-1, maxval=1)
        state, dones = jax.lax.scan(lambda s, a: (wrapped.step(s, a), s.done), state, actions)
        return first, state, dones

    first, state, dones = run(field, jax.random.PRNGKey(0))
    assert first.obs.shape == (1024, 81) and state.obs.shape == (1024, 81)
    assert state.reward.shape == (1024,) and state.done.shape == (1024,)
    assert np.isfinite(np.asarray(state.obs)).all() and np.isfinite(np.asarray(state.reward)).all()
    valid = jax.jit(jax.vmap(lambda p: reachability.valid(field, p)))(first.pipeline_state.pose)
    assert bool(valid.all()), "every reset pose satisfies the reachability condition"


def test_fresh_reset_draws_a_new_start():
    """After an episode ends the env restarts from a new random draw, not its first state."""
    config = EnvConfig(episode_length=3)
    env = FreshResetVmap(LeasEnv(flat_field(config), config))
    state = jax.jit(env.reset)(jax.random.split(jax.random.PRNGKey(3), 8))
    starts = [np.asarray(state.pipeline_state.pos)]
    step = jax.jit(env.step)
    for _ in range(3):
        state = step(state, jnp.zeros((8, 4)))
    assert np.asarray(state.done).all()
    assert np.asarray(state.info["truncation"]).all()
    assert (np.asarray(state.pipeline_state.steps) == 0).all()
    starts.append(np.asarray(state.pipeline_state.pos))
    assert not np.allclose(starts[0], starts[1]), "second episodes start elsewhere"


def test_reset_distribution():
    """Speed along the heading in [0, 0.07], unit target directions, nominal height above ground."""
    env = LeasEnv(flat_field())
    states = jax.jit(jax.vmap(env.reset))(jax.random.split(jax.random.PRNGKey(0), 512))
    root = states.pipeline_state
    speed = np.linalg.norm(np.asarray(root.vel), axis=1)
    assert speed.max() <= 0.07 + 1e-6 and speed.min() >= 0.0
    heading = np.stack([np.cos(root.yaw), np.sin(root.yaw)], axis=1)
    np.testing.assert_allclose(np.einsum("ij,ij->i", np.asarray(root.vel[:, :2]), heading), speed, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(np.asarray(root.target_dir), axis=1), 1.0, atol=1e-5)
    np.testing.assert_allclose(np.asarray(root.pos[:, 2]), 1.0, atol=1e-5)
    assert np.ptp(np.asarray(root.yaw)) > 5.0, "yaws cover the circle"


def test_target_point_mode_and_stop_at_target():
    config = EnvConfig(stop_at_target=True)
    env = LeasEnv(flat_field(config), config)
    state = env.reset_to(jnp.array([2.0, 2.0, 1.0, 0.0]), 0.1, target_point=jnp.array([2.15, 2.0]))
    assert float(state.obs[3]) == pytest.approx(0.0, abs=1e-6)  # target straight ahead
    state = jax.jit(env.step)(state, jnp.zeros(4))
    # moved 0.01 m: 0.14 m from the target < 0.20 m -> reached, episode over, not an invalid pose
    assert float(state.done) == 1.0 and float(state.metrics["reached"]) == 1.0
    assert float(state.metrics["invalid"]) == 0.0
    side = env.reset_to(jnp.array([2.0, 2.0, 1.0, 0.0]), 0.0, target_point=jnp.array([2.0, 3.0]))
    assert float(side.obs[3]) == pytest.approx(np.pi / 2, abs=1e-5)  # target to the left


def test_invalid_pose_ends_the_episode():
    heights = np.zeros((201, 201), np.float32)
    heights[110:, :] = -2.0  # void from x = 2.2 m
    env = LeasEnv(heightfield_from_raster(heights, (0.0, 0.0), 0.02, -2.0))
    state = env.reset_to(jnp.array([2.15, 2.0, 1.0, 0.0]), 0.3, target_dir=jnp.array([1.0, 0.0]))
    step = jax.jit(env.step)
    for _ in range(30):
        state = step(state, jnp.array([1.0, 0.0, 0.0, 0.0]))
        if float(state.done):
            break
    assert float(state.done) == 1.0 and float(state.metrics["invalid"]) == 1.0
    assert float(state.info["truncation"]) == 0.0


def test_clearance_term_is_off_by_default_and_costs_its_weight_near_the_edge():
    """Solid ground up to x = 2.18 m, then void. A leg disk (r 0.05 m) at x = 2.14 m touches it;
    the probe shifted 0.10 m ahead (x = 2.24 m) does not, so the clearance term is -1/6 and the
    reward drops by its weight."""
    heights = np.zeros((201, 201), np.float32)
    heights[110:, :] = -2.0
    pose = jnp.array([2.14, 2.0, 1.0, 0.0])
    stand = jnp.zeros(4)

    def first_step(config):
        env = LeasEnv(heightfield_from_raster(heights, (0.0, 0.0), 0.02, -2.0, config), config)
        return jax.jit(lambda: env.step(env.reset_to(pose, 0.0, target_dir=jnp.array([1.0, 0.0])), stand))()

    paper = first_step(
        TRAINING_ENV
    )  # the presets' condition (the default's lookahead legs would be over the void)
    assert float(paper.metrics["reward/clearance"]) == 0.0
    weighted = dataclasses.replace(TRAINING_ENV, rewards=RewardWeights(clearance=2.0), clearance_margin=0.10)
    near = first_step(weighted)
    assert float(near.metrics["invalid"]) == 0.0
    assert float(near.metrics["reward/clearance"]) == pytest.approx(-1.0 / 6.0)
    assert float(near.reward) == pytest.approx(float(paper.reward) - 2.0 / 6.0, abs=1e-6)


def test_observation_velocity_is_in_the_root_frame():
    env = LeasEnv(flat_field())
    state = env.reset_to(jnp.array([2.0, 2.0, 1.0, np.pi / 2]), 0.2, target_dir=jnp.array([1.0, 0.0]))
    np.testing.assert_allclose(state.obs[:3], [0.2, 0.0, 0.0], atol=1e-6)  # moving forward
    assert float(state.obs[3]) == pytest.approx(-np.pi / 2, abs=1e-6)  # target on the right


def test_a_terrain_is_accepted_and_anything_else_is_a_type_error():
    """`LeasEnv(load_terrain(path))` builds the heightfield; a path or an array is a TypeError
    that says what to pass."""
    terrain = load_terrain(Path(__file__).resolve().parent / "data" / "slab_with_wall.toml")
    config = dataclasses.replace(EnvConfig(), episode_length=7)
    from_terrain = LeasEnv(terrain, config)
    built = heightfield_from_terrain(terrain, config)
    for a, b in zip(jax.tree.leaves(from_terrain.field), jax.tree.leaves(built)):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))
    assert from_terrain.config is config
    state = jax.jit(from_terrain.reset)(jax.random.PRNGKey(0))
    assert state.obs.shape == (config.observation_size,)
    for wrong in ("terrains/eval_ground.toml", np.zeros((10, 10))):
        with pytest.raises(
            TypeError, match=r"expected a Heightfield or a Terrain, got .*load_terrain\(path\)"
        ):
            LeasEnv(wrong)
