"""FreshResetVmap draws only the finished envs' starts: fresh and identically distributed.

The wrapper gathers the envs whose episode ended into a short batch
(`reset_capacities`) instead of drawing a start for every env at every step.
These tests run it against the plain reference (a start drawn for every env,
then selected) and check that every episode of an env starts from a new draw
of its own key chain.
"""

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from leas_jax.env import FreshResetVmap, LeasEnv, heightfield_from_terrain
from leas_jax.env.wrappers import fresh_roots, reset_capacities
from leas_jax.terrain import load_terrain
from leas_jax.training.config import preset

B, STEPS = 64, 300


def _reference_step(env, state, action):
    """The plain fresh reset: `random_root` of every env, selected where done ([B] batch)."""

    def one(s, a):
        root, reward_value, done, metrics, truncation = env.transition(s.pipeline_state, a)
        fresh = env.random_root(root.rng)
        root = jax.tree.map(lambda new, old: jnp.where(done > 0, new, old), fresh, root)
        return s.replace(
            pipeline_state=root,
            obs=env.observe(root),
            reward=reward_value,
            done=done,
            metrics=metrics,
            info={**s.info, "truncation": truncation},
        )

    return jax.vmap(one)(state, action)


@pytest.fixture(scope="module")
def runs():
    """(wrapper run, reference run) of B envs for STEPS steps with the same random actions.

    Short episodes (20 steps) and the random policy's invalid poses make both
    single ends and simultaneous ends of the whole batch happen.
    """
    config = dataclasses.replace(preset("quick").env, episode_length=20)
    field = heightfield_from_terrain(load_terrain(preset("quick").terrain_path()), config)

    @jax.jit
    def run(field, key):
        env = LeasEnv(field, config)
        wrapped = FreshResetVmap(env)
        start = wrapped.reset(jax.random.split(key, B))
        actions = jax.random.uniform(jax.random.fold_in(key, 1), (STEPS, B, 4), minval=-1, maxval=1)

        def scan(step):
            def body(s, a):
                n = step(s, a)
                return n, (n.pipeline_state, n.done, n.obs)

            return jax.lax.scan(body, start, actions)[1]

        return start, scan(wrapped.step), scan(lambda s, a: _reference_step(env, s, a))

    start, new, ref = run(field, jax.random.PRNGKey(7))
    return config, field, jax.device_get(start.pipeline_state), jax.device_get(new), jax.device_get(ref)


def test_capacities():
    assert reset_capacities(2048) == (32, 128, 512, 2048)
    assert reset_capacities(64) == (1, 4, 16, 64)
    assert reset_capacities(3) == (3,)


def test_same_starts_as_drawing_every_env(runs):
    """Every step, every env: the same root state and observation as the reference."""
    _, _, _, (roots, done, obs), (ref_roots, ref_done, ref_obs) = runs
    assert done.sum(axis=1).max() > 1  # simultaneous ends happen
    np.testing.assert_array_equal(done, ref_done)
    # the key chain and step counters are exact; positions may differ by float rounding (other fusions)
    np.testing.assert_array_equal(roots.rng, ref_roots.rng)
    np.testing.assert_array_equal(roots.steps, ref_roots.steps)
    for name in ("pos", "vel", "yaw", "target_dir"):
        np.testing.assert_allclose(getattr(roots, name), getattr(ref_roots, name), atol=1e-5, err_msg=name)
    np.testing.assert_allclose(obs, ref_obs, rtol=1e-3, atol=1e-4)


@pytest.fixture(scope="module")
def capacity_fns(runs):
    """The runs' env's jitted `fresh_roots` and batched `random_root`, compiled once for
    every count of finished envs (the count is data, not a shape)."""
    config, field, _, _, _ = runs
    env = LeasEnv(field, config)
    return jax.jit(lambda root, done: fresh_roots(env, root, done)), jax.jit(jax.vmap(env.random_root))


@pytest.mark.parametrize("count", [0, 1, 3, 10, 40, B])
def test_each_capacity_draws_exactly_the_finished_envs(runs, capacity_fns, count):
    """Counts in every gathered size of `reset_capacities(64)` = (1, 4, 16, 64): finished
    envs get `random_root` of their own key, the others keep their root."""
    _, _, start, _, _ = runs
    fresh, draw = capacity_fns
    done = np.zeros(B, bool)
    done[np.random.default_rng(count).choice(B, count, replace=False)] = True
    got = fresh(start, jnp.asarray(done))
    drawn = draw(start.rng)
    for name in ("rng", "steps", "pos", "yaw", "vel", "target_dir"):
        want = np.where(
            done.reshape((B,) + (1,) * (np.ndim(getattr(start, name)) - 1)),
            getattr(drawn, name),
            getattr(start, name),
        )
        np.testing.assert_allclose(np.asarray(getattr(got, name)), want, atol=1e-6, err_msg=name)


def test_every_episode_starts_from_a_new_draw_of_its_key_chain(runs):
    """The k-th episode of env i starts at `random_root` of the k-th key of env i's chain; no start repeats."""
    config, field, start, (roots, done, _), _ = runs
    env = LeasEnv(field, config)
    draw = jax.jit(jax.vmap(env.random_root))
    episodes = 0
    for i in range(B):
        ends = np.flatnonzero(done[:, i] > 0)
        starts = np.concatenate([start.pos[i][None], roots.pos[ends, i]])
        yaws = np.concatenate([start.yaw[i][None], roots.yaw[ends, i]])
        keys = [start.rng[i]] + [roots.rng[t, i] for t in ends]
        # each key is the successor of the previous start's key: one split per episode
        expected = draw(jnp.stack(keys[:-1]))
        np.testing.assert_array_equal(np.asarray(expected.rng), np.stack(keys[1:]))
        np.testing.assert_allclose(np.asarray(expected.pos), starts[1:], atol=1e-5)
        np.testing.assert_allclose(np.asarray(expected.yaw), yaws[1:], atol=1e-6)
        assert len({tuple(k) for k in keys}) == len(keys), f"env {i} reuses a key"
        assert len({(round(float(y), 6), *np.round(p, 6)) for p, y in zip(starts, yaws)}) == len(starts), (
            f"env {i} replays a start"
        )
        episodes += len(ends)
    assert episodes > 5 * B


def test_start_distribution_matches_reset(runs):
    """The starts of later episodes are distributed like `LeasEnv.reset`'s first starts (two-sample KS tests)."""
    from scipy.stats import ks_2samp

    config, field, _, (roots, done, _), _ = runs
    first = jax.device_get(
        jax.jit(jax.vmap(LeasEnv(field, config).reset))(
            jax.random.split(jax.random.PRNGKey(11), 20_000)
        ).pipeline_state
    )
    later = done > 0
    assert later.sum() > 500
    speed = lambda vel: np.linalg.norm(vel[..., :2], axis=-1)  # noqa: E731
    samples = {
        "x": (roots.pos[later][:, 0], first.pos[:, 0]),
        "y": (roots.pos[later][:, 1], first.pos[:, 1]),
        "yaw": (roots.yaw[later], first.yaw),
        "speed": (speed(roots.vel[later]), speed(first.vel)),
        "target": (np.arctan2(*roots.target_dir[later].T), np.arctan2(*first.target_dir.T)),
    }
    for name, (a, b) in samples.items():
        assert ks_2samp(a, b).pvalue > 1e-3, name
