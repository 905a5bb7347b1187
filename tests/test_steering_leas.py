"""LeaS rollouts: where a path ends when it meets a pose the reachability condition rejects."""

from types import SimpleNamespace

import jax.numpy as jnp
import numpy as np

from leas_jax.env import EnvConfig, heightfield_from_terrain
from leas_jax.steering.leas import rollout_batch, start_poses
from leas_jax.terrain import loads_terrain

# Flat ground over x in [0, 3], void beyond (a hole the root walks into).
CLIFF_TEXT = (
    'name = "cliff"\nbounds = [[0.0, -1.0], [6.0, 1.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
    "[[box]]\ncenter = [1.5, 0.0, -0.1]\nsize = [3.0, 2.0, 0.2]\n"
)
CLIFF = loads_terrain(CLIFF_TEXT)


class FullSpeedAhead:
    """A stand-in policy: full forward acceleration whatever it sees."""

    config = SimpleNamespace(env=EnvConfig())

    def __call__(self, obs):
        return jnp.array([1.0, 0.0, 0.0, 0.0])


def test_a_path_ends_before_an_invalid_pose_unless_told_to_roll_on():
    policy = FullSpeedAhead()
    field = heightfield_from_terrain(CLIFF, policy.config.env)
    start = start_poses(field, np.array([[1.0, 0.0, 0.0]]), 1.0)
    target = np.array([[5.5, 0.0]])
    stopped = rollout_batch(policy, field, start, target, max_steps=200)
    assert stopped.invalid[0] and stopped.lengths[0] < 201
    assert stopped.guide(0)[-1, 0] < 3.05  # ends with the legs on the edge of the ground
    rolled = rollout_batch(policy, field, start, target, max_steps=200, stop_at_invalid=False)
    assert rolled.invalid[0] and rolled.reached[0] and rolled.lengths[0] > stopped.lengths[0]
    assert rolled.guide(0)[-1, 0] > 5.2  # carried on over the void to the target
    n = stopped.lengths[0]
    np.testing.assert_allclose(rolled.guide(0)[:n], stopped.guide(0))  # same path up to there


def test_evaluation_lets_the_contact_generator_judge_leas_paths_by_default():
    from leas_jax.eval.evaluate import build_trajectories
    from leas_jax.eval.scenarios import cells_for
    from leas_jax.steering.baselines import BaselineConfig
    from leas_jax.steering.rrt import RRTConfig

    terrain = loads_terrain(
        # a landing slab beyond 2 m of void: the target stands on ground, as the loader requires
        CLIFF_TEXT + "[[box]]\ncenter = [5.5, 0.0, -0.1]\nsize = [1.0, 2.0, 0.2]\n"
        "[scenario]\ntarget = [5.5, 0.0]\nstart_region = [[0.9, -0.1], [1.1, 0.1]]\n"
        "start_yaw_deg = [-5.0, 5.0]\nstart_speed = [0.0, 0.0]\nn_starts = 2\nseed = 0\n"
    )
    policy = FullSpeedAhead()
    env = policy.config.env
    field = heightfield_from_terrain(terrain, env)
    args = (
        "cliff",
        terrain,
        field,
        cells_for("cliff", terrain.scenario),
        ("leas",),
        policy,
        2,
        BaselineConfig.from_env(env),
        RRTConfig(),
    )
    rolled, _ = build_trajectories(*args, progress=False, env=env)
    stopped, _ = build_trajectories(*args, progress=False, env=env, leas_stop_at_invalid=True)
    assert all(t.guide[-1, 0] > 5.0 for t in rolled)  # over the void, to the target
    assert all(t.guide[-1, 0] < 3.05 for t in stopped)
