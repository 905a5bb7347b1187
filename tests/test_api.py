"""The public Python API, end to end on the real arena."""

import numpy as np


def test_public_api_trains_and_rolls_out(tmp_path):
    from leas_jax import LeasEnv, TrainConfig, load_policy, load_terrain, rollout, train  # noqa: F401
    from leas_jax.training import preset

    terrain = load_terrain("terrains/eval_ground.toml")
    config = preset(
        "smoke",
        num_timesteps=64 * 8 * 2,
        num_envs=64,
        unroll_length=8,
        num_minibatches=2,
        num_epochs=1,
        iterations_per_call=2,
    )
    assert isinstance(config, TrainConfig)
    result = train(config, tmp_path / "run", progress=False)
    policy = load_policy(result.run_dir)
    guide = rollout(policy, terrain, start=(4.0, 4.0, 0.0), target=(8.0, 4.0), max_steps=50)
    assert guide.ndim == 2 and guide.shape[1] == 4 and 1 <= len(guide) <= 51
    np.testing.assert_allclose(guide[0], [4.0, 4.0, 1.0, 0.0], atol=1e-5)  # nominal height over flat ground
    steps = np.linalg.norm(np.diff(guide[:, :3], axis=0), axis=1)
    assert np.all(steps <= 0.30 * 0.1 + 1e-6), "never faster than v_max"
