"""Resets where the contact generator stands (`EnvConfig.spawns="generator"`, leas_jax.feasibility.spawns)."""

import dataclasses

import jax
import numpy as np
import pytest

from leas_jax.contacts.planner.config import GeneratorConfig
from leas_jax.contacts.planner.generator import ContactGenerator
from leas_jax.env import EnvConfig, LeasEnv
from leas_jax.errors import UsageError
from leas_jax.feasibility import spawns
from leas_jax.terrain.loader import loads_terrain
from leas_jax.training.config import TRAINING_REACHABILITY

# 2.4 x 2.4 m of flat ground and a 0.20 m pillar at its centre: a trunk cylinder of 0.20 m
# keeps its spawn points 0.30 m from the pillar's axis, 0.20 m from its face, where Talos's
# shoulders (0.37 m to the side even with the arms held in, 0.25 m with the root shifted
# its 0.12 m off the guide) meet it at some yaws. (The presets' 0.30 m cylinder keeps them
# where the generator now stands at every yaw.)
PILLAR = """
name = "pillar_pad"
bounds = [[0.0, 0.0], [2.4, 2.4]]
void_height = -2.0
resolution = 0.02

[[box]]
center = [1.2, 1.2, -0.5]
size = [2.4, 2.4, 1.0]

[[box]]
center = [1.2, 1.2, 0.8]
size = [0.2, 0.2, 1.6]
"""
CONFIG = EnvConfig(
    reachability=dataclasses.replace(TRAINING_REACHABILITY, trunk_radius=0.20), spawns="generator"
)


@pytest.fixture(scope="module")
def pillar():
    return loads_terrain(PILLAR, "pillar_pad.toml")


@pytest.fixture(scope="module")
def verified(pillar, tmp_path_factory):
    cache = tmp_path_factory.mktemp("spawn-cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("LEAS_CACHE_DIR", str(cache))
        field = spawns.arena_field(pillar, CONFIG, workers=0, progress=False)
    return field, cache


def test_only_poses_the_generator_stands_on_are_kept(pillar, verified):
    field, _ = verified
    plain = spawns.arena_field(pillar, dataclasses.replace(CONFIG, spawns="condition"), progress=False)
    assert np.isnan(np.asarray(plain.spawn_yaw)).all()
    candidates = spawns.candidate_poses(plain, CONFIG)
    assert candidates.shape == (CONFIG.spawn_yaws * plain.spawn_xy.shape[0], 4)
    kept_xy, kept_yaw = np.asarray(field.spawn_xy), np.asarray(field.spawn_yaw)
    assert not np.isnan(kept_yaw).any()
    assert 0 < len(kept_xy) < len(candidates)  # the pillar rejects some, not all
    generator = ContactGenerator(pillar)
    table = np.column_stack([kept_xy, kept_yaw])
    gaps = np.abs(candidates[:, None, [0, 1, 3]] - table[None]).max(axis=2)  # [C, K]
    is_kept = gaps.min(axis=1) < 1e-4
    assert is_kept.sum() == len(table)
    rng = np.random.default_rng(0)
    for index in np.concatenate([rng.choice(np.flatnonzero(is_kept), 10), np.flatnonzero(~is_kept)[:10]]):
        assert (generator.double_support(candidates[index]) is not None) == is_kept[index]
    # the pillar rejects poses beside it (the pad's edges may reject others)
    assert np.linalg.norm(candidates[~is_kept, :2] - 1.2, axis=1).min() < 0.8


def test_resets_start_exactly_at_verified_poses(verified):
    field, _ = verified
    env = LeasEnv(field, CONFIG)
    states = jax.jit(jax.vmap(env.reset))(jax.random.split(jax.random.PRNGKey(3), 64))
    poses = np.asarray(states.pipeline_state.pose)
    table = np.column_stack([np.asarray(field.spawn_xy), np.asarray(field.spawn_yaw)])
    for pose in poses:
        distance = np.abs(table - pose[[0, 1, 3]]).max(axis=1)
        assert distance.min() < 1e-5
        assert abs(pose[2] - 1.0) < 1e-5  # flat ground at 0: nominal root height
    assert len({tuple(p) for p in poses.round(4)}) > 32  # drawn across the table


def test_verdicts_are_cached_and_rebuilt_when_the_generator_changes(pillar, verified, monkeypatch):
    field, cache = verified
    monkeypatch.setenv("LEAS_CACHE_DIR", str(cache))

    class NoPool:
        def __init__(self, *args, **kwargs):
            raise AssertionError("the cache should have answered")

    monkeypatch.setattr("leas_jax.contacts.validation.pool.ValidationPool", NoPool)
    again = spawns.arena_field(pillar, CONFIG, workers=0, progress=False)
    np.testing.assert_array_equal(np.asarray(again.spawn_yaw), np.asarray(field.spawn_yaw))
    poses = spawns.candidate_poses(
        spawns.arena_field(pillar, dataclasses.replace(CONFIG, spawns="condition")), CONFIG
    )
    assert spawns.spawn_key(pillar.text, poses, GeneratorConfig()) != spawns.spawn_key(
        pillar.text, poses, GeneratorConfig(max_foot_yaw=0.4)
    )
    with pytest.raises(AssertionError, match="cache should have answered"):
        spawns.verified_spawns(
            spawns.arena_field(pillar, dataclasses.replace(CONFIG, spawns="condition")),
            pillar,
            CONFIG,
            generator_config=GeneratorConfig(max_foot_yaw=0.4),
            workers=0,
            progress=False,
        )


def test_an_interrupted_build_resumes(pillar, tmp_path, monkeypatch):
    from leas_jax.contacts.validation import pool as pool_module

    monkeypatch.setenv("LEAS_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(spawns, "CHUNK", 50)
    poses = spawns.candidate_poses(
        spawns.arena_field(pillar, dataclasses.replace(CONFIG, spawns="condition")), CONFIG
    )
    poses = poses[:120]
    batches, interrupt = [], [True]

    class CountingPool(pool_module.ValidationPool):
        """Records each batch; the first build is interrupted after its first batch."""

        def map(self, guides, timestep, timeout=None):
            if interrupt[0] and batches:
                raise KeyboardInterrupt
            batches.append(len(guides))
            return super().map(guides, timestep, timeout)

    monkeypatch.setattr(pool_module, "ValidationPool", CountingPool)
    with pytest.raises(KeyboardInterrupt):
        spawns.standing_verdicts(pillar, poses, workers=0, progress=False)
    interrupt[0] = False
    every = spawns.standing_verdicts(pillar, poses, workers=0, progress=False)
    assert batches == [50, 50, 20]  # the second build read the first 50 from the cache
    generator = ContactGenerator(pillar)
    for index in (0, 49, 50, 119):
        assert every[index] == (generator.double_support(poses[index]) is not None)


def test_bad_spawn_settings_name_the_field(pillar):
    with pytest.raises(UsageError, match="EnvConfig.spawns"):
        spawns.arena_field(pillar, dataclasses.replace(CONFIG, spawns="anywhere"))
    with pytest.raises(UsageError, match="EnvConfig.spawn_yaws"):
        spawns.arena_field(pillar, dataclasses.replace(CONFIG, spawn_yaws=0))


def test_train_command_selects_the_spawns():
    from leas_jax.cli import build_parser
    from leas_jax.training.commands import config_from_args

    parser = build_parser()
    chosen = config_from_args(
        parser.parse_args(["train", "--out", "r", "--preset", "smoke", "--spawns", "generator"])
    )
    assert chosen.env.spawns == "generator"
    assert (
        config_from_args(parser.parse_args(["train", "--out", "r", "--preset", "smoke"])).env.spawns
        == "condition"
    )


def test_training_starts_its_episodes_at_verified_poses(pillar, tmp_path, monkeypatch):
    """`train` builds the verified spawns of its terrain (workers=0: in this process) and trains on them."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from training_helpers import tiny_config

    from leas_jax.training.loop import train

    monkeypatch.setenv("LEAS_CACHE_DIR", str(tmp_path / "cache"))
    terrain_file = tmp_path / "pillar_pad.toml"
    terrain_file.write_text(PILLAR)
    config = tiny_config(terrain=str(terrain_file))
    config = dataclasses.replace(config, env=dataclasses.replace(config.env, spawns="generator"))
    result = train(config, tmp_path / "run", progress=False, workers=0)
    assert result.env_steps == config.num_timesteps
    assert list((tmp_path / "cache").glob("spawns_*.npz"))  # the verdicts were made and cached
