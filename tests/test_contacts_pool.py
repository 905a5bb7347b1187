"""Worker pool of the contact generator: determinism, crash recovery, errors, reuse.

These tests inject `plan_fn` (the pool's documented test hook) with the
module-level functions below: the spawned workers import this module by name
(pytest puts tests/ on sys.path and spawn copies sys.path to the children).
A guide selects a behaviour through its first yaw value (guide[0, 3]), which
real guides never set to these magic numbers.
"""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from leas_jax.contacts.validation.pool import (
    PathResult,
    ValidationPool,
    ValidationPoolError,
    path_seed,
    register_backend,
    validate_paths,
)
from leas_jax.errors import UsageError
from leas_jax.terrain import loads_terrain

TERRAIN = """
name = "pool_test_flat"
bounds = [[0.0, 0.0], [4.0, 2.0]]
void_height = -2.0
resolution = 0.05

[[box]]
center = [2.0, 1.0, -0.1]
size = [4.0, 2.0, 0.2]
"""

EXIT = 101.0  # os._exit(3) inside the worker, every attempt
SIGKILL = 102.0  # SIGKILL to itself, every attempt
KILL_ONCE = 103.0  # SIGKILL on the first attempt only (marker file in $LEAS_TEST_MARKER_DIR)
RAISE = 104.0  # raise ValueError
SLEEP = 105.0  # sleep 60 s (timeout test)


@dataclass(frozen=True)
class FakePlan:
    """Stand-in for ContactPlan: the attributes the pool reads, plus probes."""

    coverage: float
    last_valid_index: int
    noise: float  # first draw of the global NumPy generator: checks per-path seeding
    pid: int  # worker process that planned it
    calls: int  # paths this worker planned so far, this one included
    terrain_name: str


_CALLS = 0

# Start-up failure hooks, active only in workers spawned by
# test_worker_startup_failure_* (they inherit the variable; this process
# imported the module before it was set).
if os.environ.get("LEAS_TEST_BREAK_WORKER") == "import":
    raise ImportError("crafted import failure in a worker")
if os.environ.get("LEAS_TEST_BREAK_WORKER") == "terrain":
    import leas_jax.terrain

    def _refuse_terrain(*args, **kwargs):
        raise RuntimeError("crafted terrain failure in a worker")

    leas_jax.terrain.loads_terrain = _refuse_terrain


def fake_plan(terrain, guide, timestep, config):
    """Deterministic function of (guide, terrain, path seed), with crash/raise hooks."""
    global _CALLS
    _CALLS += 1
    mode = guide[0, 3]
    if mode == EXIT:
        os._exit(3)
    if mode == SIGKILL:
        os.kill(os.getpid(), signal.SIGKILL)
    if mode == KILL_ONCE:
        marker = Path(os.environ["LEAS_TEST_MARKER_DIR"]) / f"killed_{guide[0, 0]:.3f}"
        if not marker.exists():
            marker.write_text("x")
            os.kill(os.getpid(), signal.SIGKILL)
    if mode == RAISE:
        raise ValueError(f"crafted failure at x={guide[0, 0]:.1f}\nsecond line")
    if mode == SLEEP:
        time.sleep(60.0)
    # "Coverage": fraction of guide poses over the terrain; last valid index:
    # the last such pose. Depends only on the inputs.
    inside = (guide[:, 0] <= terrain.bounds[1, 0]) & (guide[:, 0] >= terrain.bounds[0, 0])
    last = int(np.nonzero(inside)[0][-1]) if inside.any() else -1
    return FakePlan(
        coverage=float(inside.mean()),
        last_valid_index=last,
        noise=float(np.random.random()),
        pid=os.getpid(),
        calls=_CALLS,
        terrain_name=terrain.name,
    )


def _guide(x0: float, length: int = 20, yaw: float = 0.0) -> np.ndarray:
    """[length, 4] straight guide along +x from (x0, 1.0), 0.02 m per step."""
    guide = np.zeros((length, 4))
    guide[:, 0] = x0 + 0.02 * np.arange(length)
    guide[:, 1] = 1.0
    guide[:, 2] = 1.0
    guide[0, 3] = yaw
    return guide


def _batch() -> list[np.ndarray]:
    # Guides 3 and 5 leave the terrain (x > 4): coverage < 1.
    return [_guide(0.5 * i, length=20 + i) for i in range(8)]


def _summary(results: list[PathResult]):
    return [
        (
            r.index,
            r.coverage,
            r.last_valid_index,
            r.error,
            r.attempts,
            None if r.plan is None else r.plan.noise,
        )
        for r in results
    ]


def test_same_results_for_0_1_2_workers():
    guides = _batch()
    inline = validate_paths(TERRAIN, guides, 0.1, workers=0, plan_fn=fake_plan)
    one = validate_paths(TERRAIN, guides, 0.1, workers=1, plan_fn=fake_plan)
    two = validate_paths(TERRAIN, guides, 0.1, workers=2, plan_fn=fake_plan)
    assert [r.index for r in one] == list(range(8))
    assert _summary(inline) == _summary(one) == _summary(two)
    assert inline == one == two  # dataclass equality ignores plan/seconds
    # The guides leaving the terrain are the ones the fake planner cuts short:
    # guide 5 starts at x=2.5 with 25 poses to x=2.98: inside; guide 7 at x=3.5
    # with 27 poses reaches 4.02 > 4: last valid index 25 (x=4.0).
    assert two[7].last_valid_index == 25 and two[7].coverage == pytest.approx(26 / 27)
    assert all(r.ok and r.attempts == 1 for r in two)
    # Seeds depend on the index only, and differ between paths.
    assert len({r.plan.noise for r in two}) == 8
    assert os.getpid() not in {r.plan.pid for r in two} and len({r.plan.pid for r in two}) <= 2


def test_killed_workers_are_retried_once_then_reported():
    guides = [_guide(0.1), _guide(0.2, yaw=EXIT), _guide(0.3), _guide(0.4, yaw=SIGKILL), _guide(0.5)]
    start = time.monotonic()
    results = validate_paths(TERRAIN, guides, 0.1, workers=2, plan_fn=fake_plan, task_timeout=60.0)
    assert time.monotonic() - start < 60.0
    assert [r.index for r in results] == [0, 1, 2, 3, 4]
    for i in (0, 2, 4):
        assert results[i].ok and results[i].attempts == 1 and results[i].coverage == 1.0
    for i, how in ((1, "exited with code 3"), (3, "killed by SIGKILL")):
        result = results[i]
        assert not result.ok and result.plan is None
        assert result.attempts == 2
        assert result.coverage == 0.0 and result.last_valid_index == -1
        assert result.error.startswith("WorkerDied:") and how in result.error and f"path {i}" in result.error


def test_worker_killed_once_succeeds_on_retry(tmp_path, monkeypatch, caplog):
    # Spawned workers inherit the environment at their start.
    monkeypatch.setenv("LEAS_TEST_MARKER_DIR", str(tmp_path))
    guides = [_guide(0.1, yaw=KILL_ONCE), _guide(0.2)]
    with caplog.at_level(logging.WARNING, logger="leas_jax.contacts.validation.process"):
        with ValidationPool(TERRAIN, workers=1, plan_fn=fake_plan) as pool:
            killed_pid = pool._backend._pool[0].process.pid  # white-box: the first worker
            results = pool.map(guides, 0.1, timeout=60)
    # The death is logged, naming the worker and the path retried.
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1, warnings
    assert f"pid {killed_pid} killed by SIGKILL" in warnings[0]
    assert "path 0 (attempt 1 of 2)" in warnings[0] and "retrying" in warnings[0]
    assert (tmp_path / "killed_0.100").exists()
    assert results[0].ok and results[0].attempts == 2 and results[0].coverage == 1.0
    assert results[1].ok and results[1].attempts == 1
    # Same answer as a path that never crashed (deterministic seed per index).
    clean = validate_paths(TERRAIN, [_guide(0.1, yaw=KILL_ONCE)], 0.1, workers=0, plan_fn=fake_plan)
    assert results[0].plan.noise == clean[0].plan.noise


def test_planner_exception_is_an_error_result_not_dropped():
    guides = [_guide(0.1), _guide(1.0, yaw=RAISE), _guide(0.3)]
    for workers in (0, 2):
        results = validate_paths(TERRAIN, guides, 0.1, workers=workers, plan_fn=fake_plan)
        assert len(results) == 3
        bad = results[1]
        assert bad.error == "ValueError: crafted failure at x=1.0"
        assert bad.attempts == 1 and bad.plan is None and bad.last_valid_index == -1
        assert "crafted failure" in bad.traceback and "fake_plan" in bad.traceback
        assert results[0].ok and results[2].ok


def test_timeout_kills_the_worker_and_reports_the_path():
    start = time.monotonic()
    with ValidationPool(TERRAIN, workers=1, plan_fn=fake_plan, task_timeout=1.0) as pool:
        results = pool.map([_guide(0.1, yaw=SLEEP), _guide(0.2)], 0.1, timeout=60)
    assert time.monotonic() - start < 30.0
    assert results[0].error.startswith("TimeoutError:") and results[0].attempts == 1
    assert results[1].ok  # planned by the respawned worker


def test_pool_reuses_workers_and_overlaps_batches():
    with ValidationPool(loads_terrain(TERRAIN), workers=2, plan_fn=fake_plan) as pool:
        assert pool.workers == 2
        first = pool.submit(_batch(), 0.1)  # non-blocking: both batches queued at once
        second = pool.submit(_batch()[:3], 0.1)
        results_1, results_2 = first.result(timeout=60), second.result(timeout=60)
        third = pool.map(_batch()[:4], 0.1, timeout=60)
    assert [r.index for r in results_2] == [0, 1, 2]
    assert _summary(results_2) == _summary(results_1[:3]) == _summary(third[:3])
    pids = {r.plan.pid for r in results_1 + results_2 + third}
    assert len(pids) <= 2  # no respawn between batches
    # Each worker loaded the terrain once and kept planning with it.
    assert max(r.plan.calls for r in third) > 4
    assert {r.plan.terrain_name for r in third} == {"pool_test_flat"}
    with pytest.raises(ValidationPoolError, match="closed"):
        pool.submit(_batch(), 0.1)


def test_return_plans_false_sends_back_numbers_only():
    full = validate_paths(TERRAIN, _batch()[:4], 0.1, workers=1, plan_fn=fake_plan)
    lean = validate_paths(TERRAIN, _batch()[:4], 0.1, workers=1, plan_fn=fake_plan, return_plans=False)
    assert lean == full
    assert all(r.ok and r.plan is None for r in lean) and all(r.plan is not None for r in full)


def test_max_tasks_per_worker_recycles_workers():
    with ValidationPool(TERRAIN, workers=1, plan_fn=fake_plan, max_tasks_per_worker=2) as pool:
        results = pool.map(_batch()[:5], 0.1, timeout=60)
    assert all(r.ok for r in results)
    assert len({r.plan.pid for r in results}) == 3  # 2 + 2 + 1 paths
    assert max(r.plan.calls for r in results) == 2


def test_bad_inputs_raise_usage_errors():
    with pytest.raises(UsageError, match=r"guides\[1\]: expected shape \[T, 4\]"):
        validate_paths(TERRAIN, [_guide(0.1), np.zeros((5, 3))], 0.1, workers=0, plan_fn=fake_plan)
    with pytest.raises(UsageError, match=r"guides\[0\]: contains NaN"):
        validate_paths(TERRAIN, [np.full((5, 4), np.nan)], 0.1, workers=0, plan_fn=fake_plan)
    with pytest.raises(UsageError, match="timestep"):
        validate_paths(TERRAIN, [_guide(0.1)], -0.1, workers=0, plan_fn=fake_plan)
    with pytest.raises(UsageError, match="workers"):
        ValidationPool(TERRAIN, workers=-1, plan_fn=fake_plan)
    with pytest.raises(UsageError, match="start_method"):
        ValidationPool(TERRAIN, workers=1, plan_fn=fake_plan, start_method="fork")
    with pytest.raises(UsageError, match=r"address='ray://head:10001'.*Ray"):
        ValidationPool(TERRAIN, address="ray://head:10001", plan_fn=fake_plan)
    with pytest.raises(Exception, match="bounds"):
        ValidationPool(TERRAIN.replace("[4.0, 2.0]]", "[-4.0, 2.0]]"), workers=0, plan_fn=fake_plan)
    assert validate_paths(TERRAIN, [], 0.1, workers=2, plan_fn=fake_plan) == []


@pytest.mark.parametrize(
    "how, message",
    [
        ("import", "died during start-up"),  # the child cannot even unpickle its target
        ("terrain", "start-up failed: RuntimeError: crafted terrain failure"),  # PathRunner raised
    ],
)
def test_worker_startup_failure_fails_the_future_not_hangs(monkeypatch, how, message):
    monkeypatch.setenv("LEAS_TEST_BREAK_WORKER", how)  # read by this module in the workers
    pool = ValidationPool(TERRAIN, workers=1, plan_fn=fake_plan)
    try:
        future = pool.submit([_guide(0.1)], 0.1)
        with pytest.raises(ValidationPoolError, match=message):
            future.result(timeout=60)
        with pytest.raises(ValidationPoolError, match="broken"):
            pool.submit([_guide(0.1)], 0.1)
    finally:
        pool.close()


class _RecordingBackend:
    """A remote-backend stand-in registered through the address hook."""

    workers = 3
    created: list = []

    def __init__(self, address, spec, workers, options):
        from leas_jax.contacts.validation.pool import PathRunner

        self.runner = PathRunner(spec)
        _RecordingBackend.created.append((address, workers, options["max_attempts"]))

    def submit(self, guides, timestep, seeds):
        from concurrent.futures import Future

        future = Future()
        future.set_result([self.runner.run(i, g, timestep, s) for i, (g, s) in enumerate(zip(guides, seeds))])
        return future

    def close(self, cancel_pending=False):
        pass


def test_address_hook_routes_to_registered_backend():
    register_backend("recording", _RecordingBackend)
    with ValidationPool(TERRAIN, address="recording://cluster:1", workers=5, plan_fn=fake_plan) as pool:
        assert pool.workers == 3
        results = pool.map(_batch()[:3], 0.1)
    assert _RecordingBackend.created == [("recording://cluster:1", 5, 2)]
    local = validate_paths(TERRAIN, _batch()[:3], 0.1, workers=0, plan_fn=fake_plan)
    assert _summary(results) == _summary(local)


def test_path_seed_depends_on_index_only():
    assert path_seed(0, 3) == path_seed(0, 3)
    assert len({path_seed(0, i) for i in range(100)}) == 100
    assert path_seed(1, 3) != path_seed(0, 3)


# A user's script that calls validate_paths at import time (no __main__ guard).
_SCRIPT = """
import numpy as np
from leas_jax.contacts import validate_paths

TERRAIN = {terrain!r}
guide = np.zeros((3, 4))
guide[:, 0] = [1.0, 1.02, 1.04]
guide[:, 1] = 1.0
guide[:, 2] = 1.0
{body}
"""
_CALL = "results = validate_paths(TERRAIN, [guide], 0.1, workers=1)\nprint('planned', results[0].ok)"


@pytest.mark.parametrize("guarded", [False, True])
def test_a_script_without_the_main_guard_is_told_how_to_fix_it(tmp_path, guarded):
    """Spawned workers re-import the main script: unguarded, the error names the cause and the
    fix (the guarded script, same call, plans: the error is about the guard alone)."""
    body = "if __name__ == '__main__':\n    " + _CALL.replace("\n", "\n    ") if guarded else _CALL
    script = tmp_path / "validate_script.py"
    script.write_text(_SCRIPT.format(terrain=TERRAIN, body=body))
    root = Path(__file__).resolve().parents[1]
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(root), os.environ.get("PYTHONPATH")])),
    }
    done = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=env, cwd=tmp_path
    )
    if guarded:
        assert done.returncode == 0, done.stderr
        assert done.stdout.split() == ["planned", "True"]
        return
    assert done.returncode == 1 and "planned" not in done.stdout
    last = done.stderr.strip().splitlines()
    assert any(line.startswith("leas_jax.contacts.validation.runner.ValidationPoolError: ") for line in last)
    assert "imports the main script again" in done.stderr
    assert 'if __name__ == "__main__":' in done.stderr and str(script) in done.stderr
    assert "died during start-up" not in done.stderr  # the cause, not the symptom
