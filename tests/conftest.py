"""Shared fixtures."""

import pytest

from leas_jax.training import preset, train


@pytest.fixture(scope="session")
def run_dir(tmp_path_factory):
    """A tiny policy trained on the real arena (a few seconds), shared by the tests that need one."""
    out = tmp_path_factory.mktemp("run")
    config = preset(
        "smoke",
        num_timesteps=64 * 8 * 2,
        num_envs=64,
        unroll_length=8,
        num_minibatches=2,
        num_epochs=1,
        iterations_per_call=2,
    )
    train(config, out, progress=False)
    return out
