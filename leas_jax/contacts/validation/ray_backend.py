"""Ray backend of `ValidationPool`: contact planning on a Ray cluster (host-only).

Optional: needs the `cluster` extra (`pip install 'leas-jax[cluster]'`, Ray
2.60.0). Ray is imported only when a pool with one of these addresses is made;
`ValidationPool` imports this module (which registers it) on first use:

    ValidationPool(terrain, address="ray://head:10001")   # Ray client of a remote cluster
    ValidationPool(terrain, address="auto")                # the cluster running on this machine
                                                           # (`ray start --head`, or $RAY_ADDRESS)
    ValidationPool(terrain, address="local", workers=2)    # a new local Ray instance with 2 CPUs
    leas train --mode planner --ray-address ray://head:10001 ...

Accepted addresses: `ray://HOST:PORT` (Ray client; the head runs
`ray start --head`, whose client server listens on port 10001 by default; a
cluster with token authentication, Ray's default, also needs
`RAY_AUTH_MODE=token` and its token on the driver), `auto`
(join an existing cluster from one of its nodes) and `local` (start a Ray
instance in this process with `num_cpus=workers`, default all cores). A
process talks to one Ray cluster: if Ray is already initialised (by the caller
or an earlier pool), that connection is used whatever the address, and it stays
open after the pool closes (the next pool reuses it; Ray shuts it down at exit).
The cluster nodes need leas-jax installed with the same dependency set.

Same semantics as the local worker processes (`leas_jax.contacts.validation.pool`):

* `workers` Ray actors (default: the cluster's CPUs), one CPU each; every actor
  builds one `PathRunner(spec)` (Talos model, sample database, terrain) once
  and plans any number of paths with it. Each actor holds one path at a time,
  so the dispatcher knows which path a dead actor was planning.
* Results are the same `PathResult`s, in order, for any number of actors: each
  path is planned from its guide, the terrain, the config and its `path_seed`.
* An actor that dies under a path (`RayActorError`: crash, `ray.kill`, lost
  node) costs that path one retry on a fresh actor, then an error result for
  that path. A path over `task_timeout` gets its actor killed and an error
  result (not retried). An actor that cannot start three times in a row, or
  whose `PathRunner` raises, fails the pending futures with
  `ValidationPoolError` instead of hanging.
* Actors asked for beyond the cluster's free CPUs wait for resources (Ray's
  scheduling, an autoscaler may add nodes); paths go to the actors that run.
"""

from __future__ import annotations

import collections
import os
import socket
import threading
import time
import traceback as traceback_module
import warnings
from dataclasses import dataclass, field
from typing import Any

from leas_jax.contacts.validation.backend import (
    _MAX_STARTUP_DEATHS,
    _POLL_INTERVAL,
    _Job,
    _QueuedBackend,
    _Task,
    register_backend,
)
from leas_jax.contacts.validation.runner import (
    PathResult,
    PathRunner,
    ValidationPoolError,
    WorkerSpec,
    _one_line,
)
from leas_jax.errors import UsageError

SCHEMES = ("ray", "auto", "local")
_CONNECT_TIMEOUT = 10.0  # s, TCP check of a ray:// address before Ray's own (slow) retries
# Paths sent to an actor at once: the next one waits in the actor's queue, so the
# actor does not idle for a round trip between paths (short paths take ~10 ms).
_PIPELINE = 2


class RayAddressError(ValidationPoolError, UsageError):
    """Ray is not installed, or the address is malformed or unreachable (exit code 2 on the command line)."""


class _ActorWorker:
    """Body of one Ray actor: a PathRunner built once; start-up errors kept for `ready`."""

    def __init__(self, spec: WorkerSpec):
        self._runner, self._error = None, None
        try:
            self._runner = PathRunner(spec)
        except BaseException as exc:  # noqa: BLE001 - reported to the driver by ready()
            self._error = (_one_line(exc), traceback_module.format_exc())

    def ready(self):
        """(pid, None) once the planner is built, (pid, (message, traceback)) if it failed."""
        return os.getpid(), self._error

    def run(self, index, guide, timestep, seed, attempts) -> PathResult:
        return self._runner.run(index, guide, timestep, seed, attempts)


@dataclass(eq=False)
class _Actor:
    handle: Any
    ready_ref: Any
    ready: bool = False
    pid: int | None = None
    # (task, ref) sent to the actor, oldest first: it runs them in that order,
    # so the oldest is the one it is planning.
    tasks: collections.deque = field(default_factory=collections.deque)
    head_started: float = 0.0  # when the oldest one started (as seen from here)
    timed_out: bool = False
    tasks_done: int = 0


def _import_ray(address: str):
    try:
        import ray
    except ImportError:
        raise RayAddressError(
            f"address={address!r}: the Ray backend needs Ray, which is not installed: "
            "pip install 'leas-jax[cluster]'"
        ) from None
    return ray


def _connect(ray, address: str, workers: int | None) -> None:
    """ray.init for one of the accepted address forms, unless Ray is already initialised."""
    if ray.is_initialized():
        return
    if address == "local":
        with warnings.catch_warnings():
            # Ray starts its daemons with subprocess (fork and exec at once); JAX's fork hook warns anyway.
            warnings.filterwarnings("ignore", message=r"os\.fork\(\) was called", category=RuntimeWarning)
            ray.init(address="local", num_cpus=workers, include_dashboard=False)
        return
    if address.startswith("ray://"):
        host, _, port = address[len("ray://") :].rpartition(":")
        if not host or not port.isdigit():
            raise RayAddressError(
                f"address={address!r}: expected ray://HOST:PORT (Ray client server, port 10001 by default)"
            )
        try:
            socket.create_connection((host.strip("[]"), int(port)), timeout=_CONNECT_TIMEOUT).close()
        except OSError as exc:
            raise RayAddressError(
                f"address={address!r}: cannot reach the Ray client server at {host}:{port} ({_one_line(exc)})"
            ) from None
    elif address != "auto":
        raise RayAddressError(f"address={address!r}: expected ray://HOST:PORT, auto or local")
    try:
        ray.init(address=address)
    except (ConnectionError, RuntimeError, ValueError) as exc:
        hint = (
            " (a cluster with token authentication also needs RAY_AUTH_MODE=token and its token here, "
            "in RAY_AUTH_TOKEN or ~/.ray/auth_token)"
            if address.startswith("ray://")
            else ""
        )
        raise RayAddressError(f"address={address!r}: cannot connect to Ray: {_one_line(exc)}{hint}") from None


class RayBackend(_QueuedBackend):
    """`Backend` on Ray actors, driven by one dispatcher thread (after start-up, all Ray calls happen there).

    Args:
        address: `ray://HOST:PORT`, `auto` or `local` (module docstring).
        spec: what every actor builds its `PathRunner` from.
        workers: actors; None for the cluster's CPU count.
        task_timeout, max_attempts, max_tasks_per_worker: as `ValidationPool`.
    """

    def __init__(
        self,
        address: str,
        spec: WorkerSpec,
        workers: int | None,
        *,
        task_timeout: float | None,
        max_attempts: int,
        max_tasks_per_worker: int | None,
    ):
        if workers is not None and workers < 1:
            raise UsageError(
                f"workers={workers}: a Ray pool needs at least one actor (workers=0 plans in "
                "this process: give no address)"
            )
        ray = _import_ray(address)
        _connect(ray, address, workers)
        self._ray = ray
        self.workers = (
            int(workers) if workers is not None else max(1, int(ray.cluster_resources().get("CPU", 1)))
        )
        self._actor_class = ray.remote(_ActorWorker).options(num_cpus=1, max_restarts=0, max_task_retries=0)
        self._spec_ref = ray.put(spec)  # sent to the cluster once, shared by every actor
        self._task_timeout = task_timeout
        self._max_attempts = max_attempts
        self._max_tasks = max_tasks_per_worker
        self._lock = threading.RLock()  # re-entrant: a future's callback may call submit()
        self._wake_event = threading.Event()
        self._queue: collections.deque[_Task] = collections.deque()
        self._live_jobs: dict[int, _Job] = {}
        self._actors: list[_Actor] = []
        self._closing = self._cancel = False
        self._broken: BaseException | None = None
        self._startup_deaths = 0
        self._thread = threading.Thread(target=self._run, name="leas-ray-validation", daemon=True)
        self._thread.start()

    # ---------------------------------------------------------------- public
    # ---------------------------------------------------------------- dispatcher
    def _wake(self) -> None:
        self._wake_event.set()

    def _kill(self, actor: _Actor) -> None:
        try:
            self._ray.kill(actor.handle, no_restart=True)
        except Exception:  # noqa: BLE001 - already dead, or the connection is gone
            pass

    def _spawn_missing(self) -> None:
        for _ in range(self.workers - len(self._actors)):
            handle = self._actor_class.remote(self._spec_ref)
            self._actors.append(_Actor(handle=handle, ready_ref=handle.ready.remote()))

    def _assign(self) -> None:
        for depth in range(1, _PIPELINE + 1):  # first one path per actor, then the pipeline
            for actor in self._actors:
                if not self._queue:
                    return
                room = depth if self._max_tasks is None else min(depth, self._max_tasks - actor.tasks_done)
                if actor.ready and not actor.timed_out and len(actor.tasks) < room:
                    task = self._queue.popleft()
                    task.attempts += 1
                    if not actor.tasks:
                        actor.head_started = time.monotonic()
                    actor.tasks.append(
                        (
                            task,
                            actor.handle.run.remote(
                                task.index, task.guide, task.timestep, task.seed, task.attempts
                            ),
                        )
                    )

    def _error(self, task: _Task, started: float, error: str) -> None:
        self._complete(
            task,
            PathResult.failed(
                task.index,
                error,
                task.attempts,
                seconds=time.monotonic() - started,
            ),
        )

    def _break(self, exc: BaseException) -> None:
        self._fail_jobs(exc)
        for actor in self._actors:
            self._kill(actor)
        self._actors.clear()

    def _idle(self) -> bool:
        return not self._queue and not any(actor.tasks for actor in self._actors)

    def _on_ready(self, actor: _Actor) -> None:
        try:
            actor.pid, error = self._ray.get(actor.ready_ref)
        except self._ray.exceptions.RayActorError as exc:
            self._actors.remove(actor)
            self._startup_deaths += 1
            if self._startup_deaths >= _MAX_STARTUP_DEATHS:
                self._break(
                    ValidationPoolError(
                        f"{self._startup_deaths} Ray actors died during start-up; "
                        f"the last one:\n{str(exc)[-2000:]}"
                    )
                )
            return
        if error is not None:
            self._break(ValidationPoolError(f"contact worker start-up failed: {error[0]}\n{error[1]}"))
            return
        actor.ready, self._startup_deaths = True, 0

    def _retire(self, actor: _Actor) -> None:
        """Kill `actor` and requeue the paths waiting behind its current one (they never started)."""
        self._actors.remove(actor)
        self._kill(actor)
        for queued, _ in reversed(actor.tasks):
            queued.attempts -= 1
            self._queue.appendleft(queued)
        actor.tasks.clear()

    def _on_task(self, actor: _Actor) -> None:
        """The oldest path of `actor` is done (or the actor died)."""
        (task, ref), started = actor.tasks.popleft(), actor.head_started
        actor.head_started = time.monotonic()
        try:
            result = self._ray.get(ref)
        except self._ray.exceptions.RayActorError as exc:
            self._retire(actor)
            where = f"Ray actor (pid {actor.pid})"
            if actor.timed_out:
                self._error(
                    task,
                    started,
                    f"TimeoutError: path {task.index} took longer than "
                    f"{self._task_timeout:g} s ({where} killed)",
                )
            elif task.attempts < self._max_attempts:
                self._queue.appendleft(task)  # retries go before later batches
            else:
                self._error(
                    task,
                    started,
                    f"WorkerDied: {where} died while planning path {task.index}, on "
                    f"each of {task.attempts} attempts ({_one_line(exc)})",
                )
            return
        except Exception as exc:  # noqa: BLE001 - e.g. the result could not be sent back
            result = PathResult.failed(
                task.index,
                f"path {task.index}: {_one_line(exc)}",
                task.attempts,
                seconds=time.monotonic() - started,
            )
        actor.tasks_done += 1
        self._complete(task, result)
        # Recycle (bounds memory growth of native planners); or it finished just as it was killed for a timeout.
        if actor.timed_out or (self._max_tasks is not None and actor.tasks_done >= self._max_tasks):
            self._retire(actor)

    def _check_timeouts(self) -> None:
        if self._task_timeout is None:
            return
        now = time.monotonic()
        for actor in self._actors:
            if actor.tasks and not actor.timed_out and now - actor.head_started > self._task_timeout:
                actor.timed_out = True
                self._kill(actor)  # its task ref then raises RayActorError: reported in _on_task

    def _run(self) -> None:
        ray = self._ray
        try:
            while True:
                with self._lock:
                    if self._closing and (self._cancel or self._broken is not None or self._idle()):
                        break
                    if self._broken is None:
                        self._spawn_missing()
                        self._assign()
                    self._check_timeouts()
                    watched = {}  # ref -> (actor, True for its ready() call)
                    for actor in self._actors:
                        if not actor.ready:
                            watched[actor.ready_ref] = (actor, True)
                        elif actor.tasks:
                            watched[actor.tasks[0][1]] = (actor, False)
                if not watched:
                    self._wake_event.wait(_POLL_INTERVAL)
                    self._wake_event.clear()
                    continue
                # Short waits: a submit() must reach idle actors quickly (ray.wait cannot be woken).
                done, _ = ray.wait(list(watched), num_returns=1, timeout=0.05)
                if done:
                    done, _ = ray.wait(list(watched), num_returns=len(watched), timeout=0)
                with self._lock:
                    for ref in done:
                        actor, is_ready_call = watched[ref]
                        if actor not in self._actors:
                            continue  # removed meanwhile (pool broken)
                        if is_ready_call:
                            self._on_ready(actor)
                        elif actor.tasks and actor.tasks[0][1] == ref:
                            self._on_task(actor)
        except BaseException as exc:  # noqa: BLE001 - a dispatcher bug must not hang callers
            with self._lock:
                self._break(ValidationPoolError(f"Ray validation dispatcher failed: {_one_line(exc)}"))
        finally:
            with self._lock:
                if self._live_jobs:
                    self._break(ValidationPoolError("ValidationPool closed with paths pending"))
                actors = list(self._actors)
                self._actors.clear()
            for actor in actors:
                self._kill(actor)


def _factory(address: str, spec: WorkerSpec, workers: int | None, options: dict) -> RayBackend:
    return RayBackend(
        address,
        spec,
        workers,
        task_timeout=options["task_timeout"],
        max_attempts=options["max_attempts"],
        max_tasks_per_worker=options["max_tasks_per_worker"],
    )


for _scheme in SCHEMES:
    register_backend(_scheme, _factory)
