"""Shared fixtures, and the test tiers.

`make test` runs the fast tier (`-m 'not slow'`, pyproject.toml), which must stay under 10
minutes on 2 cores, lint included, in 2 pytest-xdist processes that each take a whole
test file at a time (`--dist loadfile`: a file's module fixtures are built once);
`make test-slow` runs the rest. A test is slow when it is marked `@pytest.mark.slow` in
its file, or listed in `SLOW_TIER` here: tests that only run again, on more inputs, what
a fast test already checks (their assertions all still run in the slow tier). `make test`
lists the 30 slowest tests after each run.

The processes of a test run (pytest's and its xdist workers, CLI subprocesses, notebook
kernels) share one JAX compilation cache, made for the run and removed after it: many
tests train or roll out the same tiny configs, and a program compiled once loads from the
cache in the next test (benchmarks/compile_cache.py: identical `train` calls after the
first took 0.089 of their time without it, docs/results/2026-12-01-test-compile-cache).
A JAX_COMPILATION_CACHE_DIR set by the caller is used as it is and kept.

The test run also compiles with XLA's CPU backend at LLVM optimisation level 0
(`TEST_XLA_FLAG`): the tests' programs are compiled once or twice and run on a few
environments for a few steps, so compiling is most of their time, and level 0 halves it
(benchmarks/compile_cache.py, docs/results/2026-12-03-test-compile-level). The programs
compute the same thing (XLA uses no fast-math at either level). An optimisation level
already in the caller's XLA_FLAGS is kept.
"""

import os
import shutil
import sys
import tempfile

import pytest

_CACHE_ENV = "JAX_COMPILATION_CACHE_DIR"
_CACHE_KEY = pytest.StashKey[str]()
_FLAGS_ENV = "XLA_FLAGS"
_FLAGS_KEY = pytest.StashKey[str | None]()
TEST_XLA_FLAG = "--xla_backend_optimization_level=0"

# node id -> why it is in the slow tier (what the fast tier keeps of it)
_SMOKE = "tests/test_env_leas.py::test_smoke_jit_vmap_1024_envs"
SLOW_TIER = {
    f"{_SMOKE}[{name}]": "the same jitted reset and step on another raster; the fast tier keeps "
    "the training arena's, and tests/test_terrain_*.py load this terrain"
    for name in ("eval_bridge", "eval_circuit", "eval_ground", "eval_hole", "eval_stairs", "eval_stairs_side")
}


def pytest_configure(config):
    """Give the test run its compilation cache (JAX reads the variable when it is imported;
    subprocesses inherit it) and its XLA optimisation level (read when the backend starts)."""
    flags = os.environ.get(_FLAGS_ENV)
    if "xla_backend_optimization_level" not in (flags or ""):
        config.stash[_FLAGS_KEY] = flags
        os.environ[_FLAGS_ENV] = f"{flags or ''} {TEST_XLA_FLAG}".strip()
    if os.environ.get(_CACHE_ENV):
        return
    path = tempfile.mkdtemp(prefix="leas-jax-compile-cache-")
    os.environ[_CACHE_ENV] = path
    config.stash[_CACHE_KEY] = path
    if "jax" in sys.modules:  # imported already (by a plugin): tell it too
        sys.modules["jax"].config.update("jax_compilation_cache_dir", path)


def pytest_unconfigure(config):
    if _FLAGS_KEY in config.stash:
        flags = config.stash[_FLAGS_KEY]
        if flags is None:
            os.environ.pop(_FLAGS_ENV, None)
        else:
            os.environ[_FLAGS_ENV] = flags
    path = config.stash.get(_CACHE_KEY, None)
    if path is not None:
        os.environ.pop(_CACHE_ENV, None)
        shutil.rmtree(path, ignore_errors=True)


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """Mark the `SLOW_TIER` tests slow, before `-m` selects (tests/test_layout.py checks that
    every listed id exists)."""
    for item in items:
        if item.nodeid in SLOW_TIER:
            item.add_marker(pytest.mark.slow)


@pytest.fixture(scope="session")
def run_dir(tmp_path_factory):
    """A tiny policy trained on the real arena (a few seconds), shared by the tests that need one."""
    from leas_jax.training import preset, train

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
