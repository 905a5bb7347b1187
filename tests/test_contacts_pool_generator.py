"""The worker pool with the real contact generator: same plans whatever the worker
count, the same as planning in-process, failures before a hole reported per path."""

from __future__ import annotations

import numpy as np
import pytest

from leas_jax.contacts import ContactPlan, PathResult, ValidationPool, plan_contacts, validate_paths, verify
from leas_jax.contacts.robot.model import NOMINAL_ROOT_HEIGHT as H
from leas_jax.terrain import loads_terrain

DT = 0.1  # s, paper Table I
SPEED = 0.18  # m/s, paper §IV
# Ground for x in [-1, 2] and [3, 7]; a 1 m hole between.
TERRAIN = loads_terrain("""
name = "pool_generator"
bounds = [[-1.0, -2.0], [7.0, 2.0]]
void_height = -2.0
resolution = 0.02

[[box]]
center = [0.5, 0.0, -0.1]
size = [3.0, 4.0, 0.2]

[[box]]
center = [5.0, 0.0, -0.1]
size = [4.0, 4.0, 0.2]
""")


def straight(x0, x1, y=0.0, yaw=0.0):
    """Guide along +x at SPEED, one pose per DT, root at the nominal height."""
    count = int(round(abs(x1 - x0) / (SPEED * DT))) + 1
    x = np.linspace(x0, x1, count)
    return np.stack([x, np.full(count, y), np.full(count, H), np.full(count, yaw)], axis=1)


def turning(rate=np.pi / 9, count=60):
    yaw = rate * DT * np.arange(count)
    x = 4.0 + np.cumsum(0.1 * DT * np.cos(yaw))
    y = np.cumsum(0.1 * DT * np.sin(yaw))
    return np.stack([x, y, np.full(count, H), yaw], axis=1)


GUIDES = [straight(-0.5, 1.5), straight(0.0, 3.5), turning(), straight(3.5, 5.5, y=0.3), straight(-0.5, 0.5)]


def _same_plans(a: list[PathResult], b: list[PathResult]):
    assert a == b
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x.plan.q, y.plan.q)
        np.testing.assert_array_equal(x.plan.feet, y.plan.feet)
        np.testing.assert_array_equal(x.plan.guide_index, y.plan.guide_index)


@pytest.fixture(scope="module")
def inline_results():
    return validate_paths(TERRAIN, GUIDES, DT, workers=0)


def test_in_process_matches_plan_contacts(inline_results):
    direct = [plan_contacts(TERRAIN, guide, DT) for guide in GUIDES]
    for result, plan in zip(inline_results, direct):
        assert isinstance(result.plan, ContactPlan) and result.ok and result.attempts == 1
        assert result.coverage == plan.coverage and result.last_valid_index == plan.last_valid_index
        np.testing.assert_array_equal(result.plan.q, plan.q)
    # Straight 2 m on ground and the slow turn pass; the guide into the hole stops before it.
    assert inline_results[0].coverage == 1.0 and inline_results[2].coverage == 1.0
    cut = inline_results[1]
    assert 0.0 < cut.coverage < 1.0 and 1.0 < GUIDES[1][cut.last_valid_index, 0] < 2.2


def test_one_and_two_workers_give_the_same_plans(inline_results):
    one = validate_paths(TERRAIN, GUIDES, DT, workers=1)
    _same_plans(one, inline_results)
    # Two workers, as the trainer uses them: batch k+1 submitted before batch k is done.
    with ValidationPool(TERRAIN, workers=2) as pool:
        first = pool.submit(GUIDES, DT)
        second = pool.submit(GUIDES[3:], DT)
        two, again = first.result(timeout=120), second.result(timeout=120)
    _same_plans(two, inline_results)
    # Indices restart per batch; planning does not depend on them.
    assert [r.index for r in again] == [0, 1]
    _same_plans(
        [r for r in again], [PathResult(**{**vars(r), "index": i}) for i, r in enumerate(inline_results[3:])]
    )
    assert verify(two[1].plan).ok  # a plan that came back through a pipe still verifies


def test_worker_killed_from_outside_mid_batch(inline_results):
    """SIGKILL (as the OOM killer would) a worker at an arbitrary moment: every path still
    gets the plan it gets in-process, the lost one after a retry on a fresh worker."""
    import os
    import signal
    import time

    guides = GUIDES * 4
    with ValidationPool(TERRAIN, workers=1) as pool:
        future = pool.submit(guides, DT)
        backend = pool._backend  # white-box: the pid of the running worker
        deadline = time.monotonic() + 60
        while not any(w.ready for w in backend._pool) and time.monotonic() < deadline:
            time.sleep(0.01)
        victim = next(w.pid for w in backend._pool if w.ready)
        time.sleep(0.3)  # a few paths in
        os.kill(victim, signal.SIGKILL)
        results = future.result(timeout=120)
        assert victim not in {w.pid for w in backend._pool}
    assert [r.index for r in results] == list(range(len(guides)))
    assert all(r.ok and r.attempts in (1, 2) for r in results)
    for got, want in zip(results, inline_results * 4):
        assert (got.coverage, got.last_valid_index) == (want.coverage, want.last_valid_index)
        np.testing.assert_array_equal(got.plan.q, want.plan.q)
