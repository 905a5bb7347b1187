"""The shipped policy `checkpoints/leas_talos/`: small, trained by the project's own preset with the
learned condition, and it walks.

If a default of the environment or of the presets changes, its config no longer
equals the preset's and this fails: retrain it with the README's command.
"""

import dataclasses
from pathlib import Path

import numpy as np

from leas_jax.files import REPO_ROOT
from leas_jax.training import load_policy, preset
from leas_jax.training.config import learned_condition_env, pretraining_config

SHIPPED = REPO_ROOT / "checkpoints" / "leas_talos"


def _size(path: Path) -> int:
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file())


def test_shipped_policy_is_small_and_from_the_paper_preset_with_the_learned_condition():
    assert _size(SHIPPED) < 5 * 2**20
    policy = load_policy(SHIPPED)
    paper = preset("paper", mode="planner")
    # `leas train --mode planner --preset paper --reachability learned --condition-refresh-every 0`
    # with the learned condition it was trained with, its copy beside its policy.ckpt
    trained = dataclasses.replace(paper, env=learned_condition_env(paper.env))
    assert policy.config == dataclasses.replace(
        trained, env=learned_condition_env(trained.env, str(SHIPPED / "condition.npz"))
    )
    assert policy.env_steps >= policy.config.num_timesteps
    pretrained = load_policy(SHIPPED / "pretrain")
    assert pretrained.config == dataclasses.replace(
        pretraining_config(trained),
        env=learned_condition_env(trained.env, str(SHIPPED / "pretrain" / "condition.npz")),
    )
    assert (SHIPPED / "condition.npz").read_bytes() == (SHIPPED / "pretrain" / "condition.npz").read_bytes()
    assert pretrained.env_steps >= pretrained.config.num_timesteps
    # one full-state checkpoint per phase: `leas train` resumes (or fine-tunes with --init) from them
    assert len(list((SHIPPED / "checkpoints").glob("step_*.ckpt"))) == 1
    assert len(list((SHIPPED / "pretrain" / "checkpoints").glob("step_*.ckpt"))) == 1


def test_shipped_policy_walks_to_a_target_with_a_contact_plan():
    from leas_jax import load_terrain, rollout
    from leas_jax.contacts import plan_contacts, verify

    terrain = load_terrain(REPO_ROOT / "terrains" / "eval_ground.toml")
    policy = load_policy(SHIPPED)
    guide = rollout(policy, terrain, start=(4.0, 4.0, 0.0), target=(8.0, 4.0))
    assert np.linalg.norm(guide[-1, :2] - [8.0, 4.0]) <= policy.config.env.target_reached_distance + 1e-6
    plan = plan_contacts(terrain, guide, policy.config.env.timestep)
    assert plan.coverage == 1.0
    assert verify(plan).ok
