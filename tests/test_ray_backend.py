"""The Ray backend of the validation pool (`leas_jax.contacts.validation.ray_backend`).

The slow tests start one local Ray instance with 2 CPUs (`address="local"`,
`workers=2`) and need the `cluster` extra: `make test-cluster`. They reuse the
fault-injecting `fake_plan` of test_contacts_pool.py and the real-generator
guides of test_contacts_pool_generator.py; Ray's workers import those modules by
name (the fixture puts tests/ on the PYTHONPATH of the Ray instance it starts).
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np
import pytest
from test_contacts_pool import EXIT, KILL_ONCE, SLEEP, TERRAIN, _batch, _guide, _summary, fake_plan

from leas_jax.contacts.validation.pool import ValidationPool, ValidationPoolError, validate_paths
from leas_jax.errors import UsageError


def test_bad_addresses_give_clear_errors(monkeypatch):
    with pytest.raises(UsageError, match=r"address='tcp://head:1': no validation backend for scheme 'tcp'"):
        ValidationPool(TERRAIN, address="tcp://head:1", plan_fn=fake_plan)
    with monkeypatch.context() as patch:
        patch.setitem(sys.modules, "ray", None)  # as if Ray were not installed
        with pytest.raises(
            ValidationPoolError,
            match=r"needs Ray, which is not installed: "
            r"pip install 'leas-jax\[cluster\]'",
        ):
            ValidationPool(TERRAIN, address="ray://head:10001", plan_fn=fake_plan)
    pytest.importorskip("ray")
    import ray

    assert not ray.is_initialized()
    for address, message in (
        ("ray://head", "expected ray://HOST:PORT"),
        ("ray://127.0.0.1:1", "cannot reach the Ray client server at 127.0.0.1:1"),
    ):
        with pytest.raises(ValidationPoolError, match=message) as caught:
            ValidationPool(TERRAIN, address=address, plan_fn=fake_plan)
        assert isinstance(caught.value, UsageError)  # `leas` prints it on one line, exit code 2
    with pytest.raises(UsageError, match="at least one actor"):
        ValidationPool(TERRAIN, address="local", workers=0, plan_fn=fake_plan)
    assert not ray.is_initialized()


@pytest.fixture(scope="module")
def local_ray(tmp_path_factory):
    """A local Ray instance with 2 CPUs, started by the first pool (address="local", workers=2)."""
    ray = pytest.importorskip("ray")
    if ray.is_initialized():
        pytest.skip("Ray is already initialised in this process")
    # Ray's workers inherit the environment of the instance's start: fake_plan's marker
    # files, and tests/ on the path so that they can unpickle fake_plan.
    saved = {name: os.environ.get(name) for name in ("LEAS_TEST_MARKER_DIR", "PYTHONPATH")}
    os.environ["LEAS_TEST_MARKER_DIR"] = str(tmp_path_factory.mktemp("markers"))
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [os.path.dirname(__file__), saved["PYTHONPATH"]]))
    try:
        ValidationPool(TERRAIN, address="local", workers=2, plan_fn=fake_plan).close()
        assert ray.cluster_resources()["CPU"] == 2
        yield ray
    finally:
        ray.shutdown()
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


@pytest.mark.slow
def test_results_identical_to_local_workers(local_ray):
    guides = _batch()
    local = validate_paths(TERRAIN, guides, 0.1, workers=1, plan_fn=fake_plan)
    on_ray = validate_paths(TERRAIN, guides, 0.1, address="local", plan_fn=fake_plan)  # workers: cluster CPUs
    with ValidationPool(TERRAIN, address="local", workers=1, plan_fn=fake_plan) as pool:
        assert pool.workers == 1
        first, second = pool.submit(guides, 0.1), pool.submit(guides[:3], 0.1)  # both queued at once
        one_actor, again = first.result(timeout=120), second.result(timeout=120)
    assert _summary(on_ray) == _summary(local) == _summary(one_actor)
    assert on_ray == local == one_actor and _summary(again) == _summary(local[:3])
    assert all(r.ok and r.attempts == 1 for r in on_ray)
    pids = {r.plan.pid for r in on_ray}
    assert len(pids) <= 2 and os.getpid() not in pids  # two actors (the first ready may plan all), none here
    assert len({r.plan.pid for r in one_actor + again}) == 1  # one actor kept across batches


@pytest.mark.slow
def test_dead_actor_costs_a_retry_not_the_batch(local_ray):
    guides = [_guide(0.1), _guide(0.2, yaw=EXIT), _guide(0.3, yaw=KILL_ONCE), _guide(0.4), _guide(0.5)]
    start = time.monotonic()
    results = validate_paths(TERRAIN, guides, 0.1, address="local", workers=2, plan_fn=fake_plan)
    assert time.monotonic() - start < 120
    assert [r.index for r in results] == [0, 1, 2, 3, 4]
    for i in (0, 3, 4):
        assert results[i].ok and results[i].attempts == 1 and results[i].coverage == 1.0
    # Killed on its first attempt only: planned by a fresh actor, same answer as in-process.
    clean = validate_paths(
        TERRAIN, [_guide(0.1), _guide(0.2), _guide(0.3)], 0.1, workers=0, plan_fn=fake_plan
    )[2]
    assert results[2].ok and results[2].attempts == 2
    assert (results[2].coverage, results[2].last_valid_index, results[2].plan.noise) == (
        clean.coverage,
        clean.last_valid_index,
        clean.plan.noise,
    )
    # Killed on every attempt: retried once, then an error result for that path.
    dead = results[1]
    assert not dead.ok and dead.attempts == 2 and dead.plan is None and dead.last_valid_index == -1
    assert dead.error.startswith("WorkerDied: Ray actor") and "path 1, on each of 2 attempts" in dead.error


@pytest.mark.slow
def test_timeout_kills_the_actor_and_reports_the_path(local_ray):
    with ValidationPool(TERRAIN, address="local", workers=1, plan_fn=fake_plan, task_timeout=2.0) as pool:
        results = pool.map([_guide(0.1, yaw=SLEEP), _guide(0.2)], 0.1, timeout=120)
    assert (
        results[0].error.startswith("TimeoutError: path 0 took longer than 2 s") and results[0].attempts == 1
    )
    assert results[1].ok  # planned by the fresh actor


@pytest.mark.slow
def test_max_tasks_per_worker_recycles_actors(local_ray):
    with ValidationPool(
        TERRAIN, address="local", workers=1, plan_fn=fake_plan, max_tasks_per_worker=2
    ) as pool:
        results = pool.map(_batch()[:5], 0.1, timeout=120)
    assert all(r.ok and r.attempts == 1 for r in results)
    assert (
        len({r.plan.pid for r in results}) == 3 and max(r.plan.calls for r in results) == 2
    )  # 2 + 2 + 1 paths


@pytest.mark.slow
def test_real_generator_actor_killed_mid_batch(local_ray):
    """ray.kill one actor while it plans: every path still gets its in-process plan."""
    from test_contacts_pool_generator import DT, GUIDES
    from test_contacts_pool_generator import TERRAIN as GENERATOR_TERRAIN

    inline = validate_paths(GENERATOR_TERRAIN, GUIDES, DT, workers=0)
    guides = GUIDES * 6
    with ValidationPool(GENERATOR_TERRAIN, address="local", workers=2) as pool:
        future = pool.submit(guides, DT)
        backend = pool._backend  # white-box: the job's progress and the actor handles
        (job,) = backend._live_jobs.values()
        deadline = time.monotonic() + 120
        while job.remaining > len(guides) - 3 and time.monotonic() < deadline:  # a few paths in
            time.sleep(0.01)
        victim = next((a for a in list(backend._actors) if a.tasks), backend._actors[0])
        local_ray.kill(victim.handle, no_restart=True)
        results = future.result(timeout=300)
    assert [r.index for r in results] == list(range(len(guides)))
    # The path the victim held (or the next one given to it) ran twice.
    assert all(r.ok for r in results) and sorted(r.attempts for r in results) == [1] * (len(guides) - 1) + [2]
    for got, want in zip(results, inline * 6):
        assert (got.coverage, got.last_valid_index) == (want.coverage, want.last_valid_index)
        np.testing.assert_array_equal(got.plan.q, want.plan.q)
        np.testing.assert_array_equal(got.plan.feet, want.plan.feet)


@pytest.mark.slow
def test_planner_training_on_ray(local_ray, tmp_path):
    from leas_jax.training import preset, train

    config = preset(
        "smoke",
        mode="planner",
        terrain="terrains/eval_ground.toml",
        num_timesteps=300,
        num_envs=4,
        num_minibatches=2,
        num_epochs=1,
        checkpoint_every_s=0.0,
    )
    records = []
    result = train(config, tmp_path / "run", progress=False, address="local", on_log=records.append)
    assert result.env_steps >= 300 and records
    assert all(r["generator_errors"] == 0 for r in records)
    assert 0.0 < records[-1]["mean_coverage"] <= 1.0


_CLIENT_DRIVER = """
import json, sys
sys.path.insert(0, {tests!r})
from test_contacts_pool_generator import DT, GUIDES, TERRAIN
from leas_jax.contacts.validation.pool import validate_paths
local = validate_paths(TERRAIN, GUIDES[:3], DT, workers=0)
remote = validate_paths(TERRAIN, GUIDES[:3], DT, address={address!r})
print(json.dumps([remote == local, all((a.plan.q == b.plan.q).all() for a, b in zip(remote, local)),
                  [r.attempts for r in remote]]))
"""


@pytest.mark.slow
def test_ray_client_address():
    """address="ray://HOST:PORT" against a head started with `ray start --head` (a driver in a subprocess:
    a process connects to one Ray cluster)."""
    import json
    import shutil
    import signal
    import socket
    import subprocess
    import tempfile

    pytest.importorskip("ray")
    ports = []
    for _ in range(2):
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            ports.append(probe.getsockname()[1])
    ray_cli = os.path.join(os.path.dirname(sys.executable), "ray")
    env = {**os.environ, "RAY_AUTH_MODE": "token"}
    temp_dir = tempfile.mkdtemp(prefix="leas-ray-")  # short: Ray's socket paths must fit in 107 bytes
    # Its own process group (start_new_session): the head's daemons share its process group, killed as one at the end.
    head = subprocess.Popen(
        [
            ray_cli,
            "start",
            "--head",
            "--block",
            "--num-cpus=1",
            f"--port={ports[0]}",
            f"--ray-client-server-port={ports[1]}",
            "--include-dashboard=false",
            "--disable-usage-stats",
            f"--temp-dir={temp_dir}",
        ],
        env=env,
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            try:
                socket.create_connection(("127.0.0.1", ports[1]), timeout=1.0).close()
                break
            except OSError:
                assert head.poll() is None, "ray start --head exited"
                time.sleep(0.5)
        driver = _CLIENT_DRIVER.format(tests=os.path.dirname(__file__), address=f"ray://127.0.0.1:{ports[1]}")
        done = subprocess.run(
            [sys.executable, "-c", driver], env=env, capture_output=True, text=True, timeout=300
        )
        assert done.returncode == 0, done.stderr[-3000:]
        same, same_q, attempts = json.loads(done.stdout.strip().splitlines()[-1])
        assert same and same_q and attempts == [1, 1, 1]
    finally:
        # The process group of the head we started (its daemons): ask, then force.
        for sig, wait in ((signal.SIGTERM, 30.0), (signal.SIGKILL, 10.0)):
            try:
                os.killpg(head.pid, sig)
            except ProcessLookupError:
                break  # the whole group is gone
            try:
                head.wait(timeout=wait)
            except subprocess.TimeoutExpired:
                pass
            time.sleep(2.0)  # daemons that outlive the CLI get SIGKILL next
        shutil.rmtree(temp_dir, ignore_errors=True)
