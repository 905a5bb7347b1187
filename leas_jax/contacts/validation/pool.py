"""Parallel validation of guide paths by the contact generator (host-only).

The planner-in-the-loop trainer (docs/design.md §7) rolls out thousands of guide paths
in JAX and asks the contact generator how far along each one it can plan
contacts. Contact planning is slow, single-threaded host code (Pinocchio, coal,
hpp-centroidal-dynamics), so the paths are spread over worker processes:

    with ValidationPool(terrain, workers=7) as pool:
        job = pool.submit(guides_k, timestep)      # returns at once
        guides_k1 = rollout(...)                   # overlaps with validation of batch k
        results = job.result()                     # list[PathResult], one per guide

    results = validate_paths(terrain, guides, timestep, workers=4)  # one-shot

Design points (why):

* Processes are started with `spawn` (default) or `forkserver`, never `fork`:
  the parent usually holds JAX/XLA threads, which do not survive a fork.
* Each worker loads the terrain (sent once, as its TOML text) and builds the
  planner (Talos model, sample database) once, in its start-up phase, then
  plans any number of paths. A long-lived `ValidationPool` keeps its workers
  across training iterations, so the start-up cost is paid once.
* Results do not depend on the number of workers or on scheduling: every path
  is planned independently, from its guide, the terrain, the config and a seed
  derived from the path's index only (`path_seed`). Nothing random is shared.
* A worker that dies while planning a path (segfault, `os._exit`, SIGKILL by the
  OOM killer) is detected through its process sentinel; the path is retried
  once on a fresh worker, then reported as an error `PathResult` for that path.
  A path that runs longer than `task_timeout` gets its worker killed and is
  reported as an error (not retried: planning is deterministic, a rerun would
  time out again). Paths are never silently dropped and the caller never
  hangs on a dead worker.
* `workers=0` plans in the calling thread, synchronously inside `submit`: for
  debuggers and profilers. An exception in the planner is still turned into an
  error result, but a crash of the planner takes the caller down with it.
  `workers >= 1` always uses subprocesses (one worker still isolates crashes).
* `address=` runs the workers on a cluster (docs/design.md §7: "the same interface
  accepts a Ray cluster address"): `address="ray://head:10001"`, `"auto"` or
  `"local"` use the Ray backend of `leas_jax.contacts.validation.ray_backend` (optional
  extra `leas-jax[cluster]`; imported on first use). Other schemes look up a
  backend registered with `register_backend`. A backend receives a
  `WorkerSpec` and runs `PathRunner(spec).run(...)` on its remote workers, so
  planning semantics (seeding, error capture, result type) stay identical.

Test hook: `plan_fn=` replaces `plan_contacts` with any picklable module-level
function of the same signature `(terrain, guide, timestep, config) -> plan`,
where `plan` has `coverage` and `last_valid_index` attributes. The test suite
uses it to kill a worker from inside a path (`os._exit`, SIGKILL) and to raise
errors; production code leaves it at None.
"""

from __future__ import annotations

import collections
import dataclasses
import importlib
import itertools
import math
import multiprocessing
import os
import random
import signal
import threading
import time
import traceback as traceback_module
import weakref
from collections.abc import Callable, Sequence
from concurrent.futures import Future
from dataclasses import dataclass, field
from multiprocessing.connection import wait as wait_for_ready
from typing import Any, Protocol

import numpy as np

from leas_jax.errors import LeasError, UsageError

# Default cap on the wall time of one path. A 400-step guide subsampled every
# 5th pose is 80 contact-planning stages; the generator should take seconds, so
# ten minutes only catches a planner stuck in a loop.
DEFAULT_TASK_TIMEOUT = 600.0  # s
# A path is started at most this many times: once, plus one retry after its
# worker died (the brief of docs/design.md §7: retried once, then an error).
DEFAULT_MAX_ATTEMPTS = 2
# Workers that die before they report ready this many times in a row mean the
# start-up itself is broken (bad install, bad plan_fn): fail instead of
# respawning forever.
_MAX_STARTUP_DEATHS = 3
# How long close() waits for a worker to exit after asking it to, before SIGKILL.
_STOP_GRACE = 5.0  # s
# Upper bound of one wait in the dispatcher loop: bounds how late a task timeout
# is noticed when nothing else happens.
_POLL_INTERVAL = 0.5  # s


class ValidationPoolError(LeasError):
    """The pool cannot plan at all (worker start-up failed, pool closed, bad address)."""


@dataclass(frozen=True)
class PathResult:
    """Outcome of the contact generator on one guide path.

    Equality compares `index`, `coverage`, `last_valid_index`, `error` and
    `attempts`; `plan`, `seconds` and `traceback` are excluded (arrays and
    timings: compare plans array by array).

    Attributes:
        index: position of the guide in the submitted list.
        coverage: arc-length fraction of the guide covered by the plan, in
            [0, 1]; 0.0 when `error` is set.
        last_valid_index: guide index of the last valid posture (docs/design.md §6);
            -1 when `error` is set (no part of the guide was validated).
        plan: the `ContactPlan`; None when `error` is set or the pool was made
            with `return_plans=False`.
        error: None on success, else one line "Type: message" (an exception
            raised by the planner, a worker death, a timeout).
        attempts: how many times the path was started (2 after a worker died
            once under it).
        seconds: wall time of the last attempt, s.
        traceback: the formatted traceback of a planner exception, else None.
    """

    index: int
    coverage: float
    last_valid_index: int
    plan: Any = field(compare=False, repr=False)
    error: str | None
    attempts: int
    seconds: float = field(default=0.0, compare=False)
    traceback: str | None = field(default=None, compare=False, repr=False)

    @property
    def ok(self) -> bool:
        """True when the generator returned a plan (which may still cover little of the guide)."""
        return self.error is None


@dataclass(frozen=True)
class WorkerSpec:
    """Everything a worker needs to build its planner; picklable, sent once per worker.

    Attributes:
        terrain_text: the terrain file text (TOML, docs/design.md §4).
        terrain_source: name used in terrain error messages (file path or "<...>").
        config: the generator config (`GeneratorConfig`), None for its defaults.
        plan_fn: None for `leas_jax.contacts.plan_contacts`, else a picklable
            module-level function `(terrain, guide [T, 4], timestep, config) -> plan`.
        return_plans: False to drop each plan in the worker and send back only
            coverage and last_valid_index (the trainer needs no more; a plan
            carries the terrain text, ~40 kB for the training arena).
    """

    terrain_text: str
    terrain_source: str = "<terrain>"
    config: Any = None
    plan_fn: Callable | None = None
    return_plans: bool = True


def path_seed(base_seed: int, index: int) -> int:
    """Seed of the path at `index`: a function of (base_seed, index) only.

    Uses NumPy's SeedSequence so neighbouring indices give unrelated streams.

    Returns:
        int in [0, 2**32).
    """
    return int(np.random.SeedSequence([int(base_seed) & 0xFFFFFFFF, int(index)]).generate_state(1)[0])


def _one_line(exc: BaseException) -> str:
    """'Type: first line of the message' of an exception."""
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0]}" if text else type(exc).__name__


class PathRunner:
    """Plans single paths; lives in a worker (or in the caller for workers=0). Host-only.

    Built once per worker from a `WorkerSpec`: loads the terrain and, for the
    default planner, one `ContactGenerator` (Talos model, sample database,
    terrain collision objects, support surfaces), reused for every path. A
    remote backend (see `register_backend`) instantiates it on its workers.

    The generator is deterministic given (terrain, guide, timestep, config);
    `GeneratorConfig` has no seed field, so the path seed only reaches the
    global NumPy and `random` generators. An injected `plan_fn` whose config
    has a `seed` field gets the path seed there too.

    Args:
        spec: terrain text, config and planner.
    """

    def __init__(self, spec: WorkerSpec):
        from leas_jax.terrain import loads_terrain

        self.terrain = loads_terrain(spec.terrain_text, source=spec.terrain_source)
        self.return_plans = spec.return_plans
        self._generator = None
        if spec.plan_fn is None:
            # Imported here, not at module level: leas_jax.contacts imports this
            # module lazily, and only workers need the generator.
            from leas_jax.contacts.planner.generator import ContactGenerator, GeneratorConfig

            self.config = spec.config if spec.config is not None else GeneratorConfig()
            self._generator = ContactGenerator(self.terrain, self.config)
            self.plan_fn = None
        else:
            self.config = spec.config
            self.plan_fn = spec.plan_fn

    def _config_for(self, seed: int):
        """The config with its `seed` field (if it has one) set to the path seed."""
        config = self.config
        if dataclasses.is_dataclass(config) and any(f.name == "seed" for f in dataclasses.fields(config)):
            config = dataclasses.replace(config, seed=seed)
        return config

    def _plan(self, guide: np.ndarray, timestep: float, seed: int):
        if self._generator is not None:
            return self._generator.plan(guide, timestep)
        return self.plan_fn(self.terrain, guide, timestep, self._config_for(seed))

    def run(self, index: int, guide: np.ndarray, timestep: float, seed: int, attempts: int = 1) -> PathResult:
        """Plan one path; planner exceptions become an error result.

        Args:
            index: position of the guide in its batch (copied to the result).
            guide: [T, 4] (x, y, z, yaw) root poses, world frame.
            timestep: s between guide poses.
            seed: path seed (`path_seed`); seeds the global NumPy and `random`
                generators and the config's `seed` field when it has one.
            attempts: attempt number, copied to the result.
        """
        # Global generators too: planner code that draws from them must not
        # depend on what this worker planned before.
        np.random.seed(seed)
        random.seed(seed)
        start = time.perf_counter()
        try:
            plan = self._plan(guide, timestep, seed)
            coverage = float(plan.coverage)
            last_valid = int(plan.last_valid_index)
        except Exception as exc:
            return PathResult(
                index=index,
                coverage=0.0,
                last_valid_index=-1,
                plan=None,
                error=_one_line(exc),
                attempts=attempts,
                seconds=time.perf_counter() - start,
                traceback=traceback_module.format_exc(),
            )
        return PathResult(
            index=index,
            coverage=coverage,
            last_valid_index=last_valid,
            plan=plan if self.return_plans else None,
            error=None,
            attempts=attempts,
            seconds=time.perf_counter() - start,
        )


def _worker_main(conn, spec: WorkerSpec) -> None:
    """Worker process: build a PathRunner, then answer tasks until told to stop.

    Protocol (parent -> worker): `(key, index, guide, timestep, seed, attempts)`
    per path, None to stop. Worker -> parent: `("ready", pid)` once,
    `("init_error", message, traceback)` if start-up failed, `("done", key,
    PathResult)` per path. The worker exits when the parent's end of the pipe
    closes, so an abandoned worker never outlives its parent's pool.
    """
    # Ctrl-C goes to the whole process group; the parent decides what to do
    # (close the pool), a worker dying on SIGINT would only look like a crash.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        runner = PathRunner(spec)
    except BaseException as exc:  # noqa: BLE001 - anything here is reported to the parent
        conn.send(("init_error", _one_line(exc), traceback_module.format_exc()))
        return
    conn.send(("ready", os.getpid()))
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        key, index, guide, timestep, seed, attempts = message
        result = runner.run(index, guide, timestep, seed, attempts)
        try:
            conn.send(("done", key, result))
        except (EOFError, OSError, BrokenPipeError):
            return
        except Exception as exc:  # the plan could not be pickled
            conn.send(
                (
                    "done",
                    key,
                    dataclasses.replace(
                        result,
                        plan=None,
                        coverage=0.0,
                        last_valid_index=-1,
                        error=f"result of path {index} could not be sent back: {_one_line(exc)}",
                    ),
                )
            )


# --------------------------------------------------------------------------- backends


class Backend(Protocol):
    """What `ValidationPool` needs from an executor (local processes, inline, remote).

    `submit` must not block on planning; each returned future resolves to one
    `PathResult` per guide, in order, with `PathResult.index == position`.
    """

    workers: int

    def submit(self, guides: list[np.ndarray], timestep: float, seeds: list[int]) -> Future: ...

    def close(self, cancel_pending: bool = False) -> None: ...


class _InlineBackend:
    """workers=0: plan in the calling thread, synchronously inside submit."""

    workers = 0

    def __init__(self, spec: WorkerSpec):
        self._runner = PathRunner(spec)
        self._closed = False

    def submit(self, guides, timestep, seeds):
        if self._closed:
            raise ValidationPoolError("submit() on a closed ValidationPool")
        future: Future = Future()
        future.set_running_or_notify_cancel()
        future.set_result(
            [self._runner.run(i, g, timestep, s) for i, (g, s) in enumerate(zip(guides, seeds))]
        )
        return future

    def close(self, cancel_pending=False):
        self._closed = True


@dataclass
class _Job:
    future: Future
    results: list
    remaining: int


@dataclass
class _Task:
    job: _Job
    index: int
    guide: np.ndarray
    timestep: float
    seed: int
    attempts: int = 0
    key: int = 0


@dataclass
class _Worker:
    process: Any
    conn: Any
    ready: bool = False
    pid: int | None = None
    task: _Task | None = None
    task_started: float = 0.0
    timed_out: bool = False
    tasks_done: int = 0
    retiring: bool = False
    eof: bool = False  # its pipe is closed: watch only the sentinel (no busy loop on EOF)


def _describe_exit(exitcode: int | None) -> str:
    """Human text for a process exit code (negative = killed by that signal)."""
    if exitcode is None:
        return "exit status unknown"
    if exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = f"signal {-exitcode}"
        return f"killed by {name}"
    return f"exited with code {exitcode}"


class _QueuedBackend:
    """Job bookkeeping shared by the process and Ray backends.

    `submit` queues one `_Task` per path of a `_Job`; the dispatcher thread
    (`_thread`) hands tasks to workers and reports answers with `_complete`;
    `_fail_jobs` fails every pending job. Subclasses create `_lock`, `_queue`,
    `_live_jobs`, `_broken`, `_closing`, `_cancel` and `_thread`, and define
    `_wake()` (interrupt the dispatcher's wait).
    """

    def submit(self, guides, timestep, seeds):
        future: Future = Future()
        future.set_running_or_notify_cancel()
        if not guides:
            future.set_result([])
            return future
        job = _Job(future=future, results=[None] * len(guides), remaining=len(guides))
        with self._lock:
            if self._broken is not None:
                raise ValidationPoolError(f"the validation pool is broken: {self._broken}")
            if self._closing:
                raise ValidationPoolError("submit() on a closed ValidationPool")
            self._live_jobs[id(job)] = job
            for index, (guide, seed) in enumerate(zip(guides, seeds)):
                self._queue.append(_Task(job=job, index=index, guide=guide, timestep=timestep, seed=seed))
        self._wake()
        return future

    def close(self, cancel_pending=False):
        with self._lock:
            self._closing = True
            self._cancel = self._cancel or cancel_pending
        self._wake()
        if threading.current_thread() is not self._thread:
            self._thread.join()

    def _complete(self, task: _Task, result: PathResult) -> None:
        """Record one path's result (the first answer wins); resolve the job when it is whole."""
        job = task.job
        if job.results[task.index] is not None:
            return
        job.results[task.index] = result
        job.remaining -= 1
        if job.remaining == 0:
            self._live_jobs.pop(id(job), None)
            job.future.set_result(job.results)

    def _fail_jobs(self, exc: BaseException) -> None:
        """Fail every pending job with `exc`; later submits raise (caller holds the lock)."""
        self._broken = exc
        self._queue.clear()
        for job in list(self._live_jobs.values()):
            if not job.future.done():
                job.future.set_exception(exc)
        self._live_jobs.clear()


class _ProcessBackend(_QueuedBackend):
    """Local worker processes driven by one dispatcher thread in the parent.

    The dispatcher owns all pipes and processes: it hands one task at a time to
    each ready worker (so it always knows which path a dead worker was
    planning), reads results, watches process sentinels for deaths and
    in-flight tasks for timeouts, respawns workers and completes futures.
    """

    def __init__(
        self,
        spec: WorkerSpec,
        workers: int,
        *,
        task_timeout: float | None,
        max_attempts: int,
        max_tasks_per_worker: int | None,
        start_method: str,
    ):
        self.workers = workers
        self._spec = spec
        self._context = multiprocessing.get_context(start_method)
        self._task_timeout = task_timeout
        self._max_attempts = max_attempts
        self._max_tasks = max_tasks_per_worker
        # Re-entrant: a done-callback of a future runs in the dispatcher thread
        # with the lock held and may call submit().
        self._lock = threading.RLock()
        self._queue: collections.deque[_Task] = collections.deque()
        self._keys = itertools.count()
        self._live_jobs: dict[int, _Job] = {}
        self._pool: list[_Worker] = []
        self._closing = False
        self._cancel = False
        self._broken: BaseException | None = None
        self._startup_deaths = 0
        # Self-pipe: submit/close wake the dispatcher out of its wait().
        self._wake_reader, self._wake_writer = multiprocessing.Pipe(duplex=False)
        with self._lock:
            self._spawn_missing()
        self._thread = threading.Thread(target=self._run, name="leas-validation-pool", daemon=True)
        self._thread.start()

    # ---------------------------------------------------------------- dispatcher
    def _wake(self) -> None:
        try:
            self._wake_writer.send_bytes(b"w")
        except OSError:
            pass

    def _spawn_missing(self) -> None:
        """Start workers until `self.workers` are alive (caller holds the lock)."""
        alive = sum(1 for w in self._pool if not w.retiring)
        for _ in range(self.workers - alive):
            parent_conn, child_conn = self._context.Pipe(duplex=True)
            process = self._context.Process(
                target=_worker_main, args=(child_conn, self._spec), name="leas-contact-worker", daemon=True
            )
            process.start()
            # Only the child keeps its end: then the parent sees EOF when it dies.
            child_conn.close()
            self._pool.append(_Worker(process=process, conn=parent_conn))

    def _assign(self) -> None:
        """Give queued tasks to idle ready workers (caller holds the lock)."""
        for worker in self._pool:
            if not self._queue:
                return
            if not worker.ready or worker.task is not None or worker.retiring:
                continue
            task = self._queue.popleft()
            task.attempts += 1
            task.key = next(self._keys)
            worker.task, worker.task_started, worker.timed_out = task, time.monotonic(), False
            try:
                worker.conn.send((task.key, task.index, task.guide, task.timestep, task.seed, task.attempts))
            except (OSError, BrokenPipeError):
                # The worker died between its last message and now; its
                # sentinel fires on the next wait and _on_death handles the task.
                pass

    def _on_message(self, worker: _Worker, message) -> None:
        kind = message[0]
        if kind == "ready":
            worker.ready, worker.pid = True, message[1]
            self._startup_deaths = 0
        elif kind == "init_error":
            self._break(ValidationPoolError(f"contact worker start-up failed: {message[1]}\n{message[2]}"))
        elif kind == "done":
            _, key, result = message
            task = worker.task
            if task is None or task.key != key:
                return  # stale answer of a task already timed out
            worker.task = None
            worker.tasks_done += 1
            self._complete(task, result)
            if self._max_tasks is not None and worker.tasks_done >= self._max_tasks:
                # Recycle: bounds memory growth of long-lived C++ planners.
                worker.retiring = True
                try:
                    worker.conn.send(None)
                except OSError:
                    pass

    def _on_death(self, worker: _Worker) -> None:
        worker.process.join(timeout=1.0)
        self._pool.remove(worker)
        worker.conn.close()
        task = worker.task
        if not worker.ready and not worker.retiring:
            self._startup_deaths += 1
            if self._startup_deaths >= _MAX_STARTUP_DEATHS:
                self._break(
                    ValidationPoolError(
                        f"{self._startup_deaths} contact workers died during start-up "
                        f"(last {_describe_exit(worker.process.exitcode)})"
                    )
                )
        if task is None:
            return
        pid = worker.pid if worker.pid is not None else worker.process.pid
        if worker.timed_out:
            self._complete(
                task,
                PathResult(
                    index=task.index,
                    coverage=0.0,
                    last_valid_index=-1,
                    plan=None,
                    error=f"TimeoutError: path {task.index} took longer than {self._task_timeout:g} s "
                    f"(worker pid {pid} killed)",
                    attempts=task.attempts,
                    seconds=time.monotonic() - worker.task_started,
                ),
            )
            return
        how = _describe_exit(worker.process.exitcode)
        if task.attempts < self._max_attempts:
            # Front of the queue: the retry should not wait behind later batches.
            self._queue.appendleft(task)
        else:
            self._complete(
                task,
                PathResult(
                    index=task.index,
                    coverage=0.0,
                    last_valid_index=-1,
                    plan=None,
                    error=f"WorkerDied: contact worker (pid {pid}) {how} while planning path "
                    f"{task.index}, on each of {task.attempts} attempts",
                    attempts=task.attempts,
                    seconds=time.monotonic() - worker.task_started,
                ),
            )

    def _check_timeouts(self) -> float:
        """Kill workers over the task timeout; return seconds until the next deadline."""
        if self._task_timeout is None:
            return _POLL_INTERVAL
        now, next_deadline = time.monotonic(), _POLL_INTERVAL
        for worker in self._pool:
            if worker.task is None or worker.timed_out:
                continue
            left = worker.task_started + self._task_timeout - now
            if left <= 0:
                worker.timed_out = True
                worker.process.kill()
            else:
                next_deadline = min(next_deadline, left)
        return max(next_deadline, 0.01)

    def _break(self, exc: BaseException) -> None:
        """Fail every pending job with `exc`; later submits raise (caller holds the lock)."""
        self._fail_jobs(exc)
        for worker in self._pool:
            worker.task = None

    def _idle(self) -> bool:
        return not self._queue and all(w.task is None for w in self._pool)

    def _run(self) -> None:
        try:
            while True:
                with self._lock:
                    if self._closing and (self._cancel or self._broken is not None or self._idle()):
                        break
                    if self._broken is None:
                        self._spawn_missing()
                        self._assign()
                    timeout = self._check_timeouts()
                    watched = {self._wake_reader: None}
                    for worker in self._pool:
                        if not worker.eof:
                            watched[worker.conn] = worker
                        watched[worker.process.sentinel] = worker
                for ready in wait_for_ready(list(watched), timeout=timeout):
                    if ready is self._wake_reader:
                        while self._wake_reader.poll():
                            self._wake_reader.recv_bytes()
                        continue
                    worker = watched[ready]
                    with self._lock:
                        if worker not in self._pool:
                            continue
                        # Drain answers first: a worker may send its result and die.
                        try:
                            while not worker.eof and worker.conn.poll():
                                self._on_message(worker, worker.conn.recv())
                        except (EOFError, OSError):
                            worker.eof = True
                        if not worker.process.is_alive():
                            self._on_death(worker)
        except BaseException as exc:  # noqa: BLE001 - a dispatcher bug must not hang callers
            with self._lock:
                self._break(ValidationPoolError(f"validation dispatcher failed: {_one_line(exc)}"))
        finally:
            with self._lock:
                if self._live_jobs:
                    self._break(ValidationPoolError("ValidationPool closed with paths pending"))
                workers = list(self._pool)
                self._pool.clear()
            _stop_workers(workers)
            self._wake_reader.close()
            self._wake_writer.close()


def _stop_workers(workers: list[_Worker]) -> None:
    """Ask workers to exit, then SIGKILL those still alive after a grace period."""
    for worker in workers:
        try:
            worker.conn.send(None)
        except OSError:
            pass
    deadline = time.monotonic() + _STOP_GRACE
    for worker in workers:
        worker.process.join(timeout=max(0.0, deadline - time.monotonic()))
        if worker.process.is_alive():
            worker.process.kill()
            worker.process.join(timeout=1.0)
        worker.conn.close()


# A remote backend factory: (address, spec, workers, options) -> Backend.
BackendFactory = Callable[[str, WorkerSpec, "int | None", dict], Backend]
_BACKENDS: dict[str, BackendFactory] = {}
# Backends shipped with leas-jax: the module registers itself when imported, on first use.
_BUILTIN_BACKENDS = {
    "ray": "leas_jax.contacts.validation.ray_backend",
    "auto": "leas_jax.contacts.validation.ray_backend",
    "local": "leas_jax.contacts.validation.ray_backend",
}


def register_backend(scheme: str, factory: BackendFactory) -> None:
    """Register the executor used for `ValidationPool(address="<scheme>://...")`.

    The Ray backend (`leas_jax.contacts.validation.ray_backend`, schemes "ray", "auto"
    and "local") is registered this way when first used; it is the example to
    follow for another executor.

    Args:
        scheme: the part of the address before "://" (or the whole address,
            e.g. "auto"), case-sensitive.
        factory: called as `factory(address, spec, workers, options)` where
            `options` holds task_timeout, max_attempts, max_tasks_per_worker;
            returns an object with the `Backend` protocol.
    """
    _BACKENDS[scheme] = factory


def available_cpus() -> int:
    """CPUs this process may use (its affinity mask where the OS has one)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def _default_workers() -> int:
    """One worker per CPU this process may use, leaving one for the trainer."""
    return max(1, available_cpus() - 1)


def _terrain_spec(terrain, config, plan_fn, return_plans: bool) -> WorkerSpec:
    """Check the terrain in the parent (clear error now, not in a worker) and pack the spec."""
    from leas_jax.terrain import Terrain, loads_terrain

    if isinstance(terrain, Terrain):
        text, source = terrain.text, terrain.path or f"<terrain {terrain.name}>"
    elif isinstance(terrain, str):
        text, source = terrain, "<terrain text>"
        loads_terrain(text, source=source)
    else:
        raise UsageError(
            f"terrain: expected a Terrain or the terrain file text, got {type(terrain).__name__}"
        )
    if plan_fn is not None and not callable(plan_fn):
        raise UsageError(f"plan_fn: expected a function, got {type(plan_fn).__name__}")
    return WorkerSpec(
        terrain_text=text,
        terrain_source=source,
        config=config,
        plan_fn=plan_fn,
        return_plans=bool(return_plans),
    )


def _check_guides(guides, timestep) -> list[np.ndarray]:
    """Validate the batch in the parent; returns contiguous float64 [T, 4] copies."""
    if isinstance(guides, np.ndarray) and guides.ndim == 3:
        guides = list(guides)
    if isinstance(guides, (str, bytes)) or not isinstance(guides, Sequence):
        raise UsageError(f"guides: expected a list of [T, 4] arrays, got {type(guides).__name__}")
    if not (
        isinstance(timestep, (int, float, np.floating, np.integer))
        and math.isfinite(float(timestep))
        and float(timestep) > 0
    ):
        raise UsageError(f"timestep: expected a positive number of seconds, got {timestep!r}")
    checked = []
    for i, guide in enumerate(guides):
        array = np.ascontiguousarray(guide, dtype=np.float64)
        if array.ndim != 2 or array.shape[1] != 4 or array.shape[0] < 1:
            raise UsageError(f"guides[{i}]: expected shape [T, 4] (x, y, z, yaw), got {list(array.shape)}")
        if not np.isfinite(array).all():
            raise UsageError(f"guides[{i}]: contains NaN or inf")
        checked.append(array)
    return checked


class ValidationPool:
    """Long-lived pool of contact-generator workers for one terrain (host-only).

    Create once, submit batches of guide paths for many training iterations,
    close at the end (or use as a context manager). Thread-safe: `submit` may
    be called from any thread.

    Args:
        terrain: a `Terrain`, or the terrain file text (TOML). Sent to every
            worker once, as text. For another terrain, make another pool.
        workers: number of worker processes; None for one per available CPU
            minus one; 0 to plan in the calling thread (debugging; see module
            docstring).
        config: `GeneratorConfig` for every path (None: its defaults). If it
            has a `seed` field, each path gets `path_seed(config.seed, index)`.
        plan_fn: None for `plan_contacts`; tests inject a picklable module-level
            function with the same signature (see module docstring).
        address: None for local processes; "ray://HOST:PORT", "auto" or
            "local" for Ray actors (`leas_jax.contacts.validation.ray_backend`); another
            "scheme://..." for a backend registered with `register_backend`.
        task_timeout: s; a path running longer has its worker killed and is
            reported as an error. None: no limit.
        max_attempts: times a path is started when its worker dies under it.
        max_tasks_per_worker: recycle a worker after this many paths (bounds
            leaks in native code); None: never.
        start_method: "spawn" or "forkserver" ("fork" is refused: JAX threads
            in the parent do not survive it).
        return_plans: False to get results without their `plan` (only
            coverage and last_valid_index travel back: what the trainer uses).
    """

    def __init__(
        self,
        terrain,
        *,
        workers: int | None = None,
        config=None,
        plan_fn: Callable | None = None,
        address: str | None = None,
        task_timeout: float | None = DEFAULT_TASK_TIMEOUT,
        max_attempts: int = DEFAULT_MAX_ATTEMPTS,
        max_tasks_per_worker: int | None = None,
        start_method: str = "spawn",
        return_plans: bool = True,
    ):
        if workers is not None and (
            not isinstance(workers, (int, np.integer)) or isinstance(workers, bool) or workers < 0
        ):
            raise UsageError(f"workers: expected an integer >= 0, got {workers!r}")
        if start_method not in ("spawn", "forkserver"):
            raise UsageError(
                f"start_method: expected 'spawn' or 'forkserver', got {start_method!r} "
                "(fork is unsafe once JAX has started threads)"
            )
        if not isinstance(max_attempts, int) or max_attempts < 1:
            raise UsageError(f"max_attempts: expected an integer >= 1, got {max_attempts!r}")
        if task_timeout is not None and not task_timeout > 0:
            raise UsageError(
                f"task_timeout: expected a positive number of seconds or None, got {task_timeout!r}"
            )
        spec = _terrain_spec(terrain, config, plan_fn, return_plans)
        self._base_seed = int(getattr(config, "seed", 0) or 0)
        self._backend: Backend
        if address is not None:
            scheme = address.split("://", 1)[0] if "://" in address else address
            if scheme not in _BACKENDS and scheme in _BUILTIN_BACKENDS:
                importlib.import_module(_BUILTIN_BACKENDS[scheme])
            factory = _BACKENDS.get(scheme)
            if factory is None:
                raise UsageError(
                    f"address={address!r}: no validation backend for scheme {scheme!r} (Ray: "
                    "ray://HOST:PORT, auto or local); see leas_jax.contacts.validation.pool.register_backend"
                )
            options = dict(
                task_timeout=task_timeout,
                max_attempts=max_attempts,
                max_tasks_per_worker=max_tasks_per_worker,
            )
            self._backend = factory(address, spec, workers, options)
        elif workers == 0:
            self._backend = _InlineBackend(spec)
        else:
            self._backend = _ProcessBackend(
                spec,
                _default_workers() if workers is None else int(workers),
                task_timeout=task_timeout,
                max_attempts=max_attempts,
                max_tasks_per_worker=max_tasks_per_worker,
                start_method=start_method,
            )
        # Workers must not outlive an unclosed pool at interpreter exit.
        self._finalizer = weakref.finalize(self, self._backend.close, True)

    @property
    def workers(self) -> int:
        """Number of workers (0: in-process)."""
        return self._backend.workers

    def submit(self, guides: Sequence[np.ndarray], timestep: float) -> Future:
        """Queue a batch of guide paths; returns at once (except with workers=0).

        Args:
            guides: list of [T_i, 4] (x, y, z, yaw) root poses, world frame
                (lengths may differ), or one [B, T, 4] array.
            timestep: s between consecutive guide poses.

        Returns:
            A `concurrent.futures.Future` resolving to `list[PathResult]`, one
            per guide, in order. It raises `ValidationPoolError` only if the
            pool itself broke (workers cannot start); per-path failures are
            error results. Batches are planned in submission order.
        """
        checked = _check_guides(guides, timestep)
        seeds = [path_seed(self._base_seed, i) for i in range(len(checked))]
        return self._backend.submit(checked, float(timestep), seeds)

    def map(
        self, guides: Sequence[np.ndarray], timestep: float, timeout: float | None = None
    ) -> list[PathResult]:
        """Plan a batch and wait: `submit(guides, timestep).result(timeout)`."""
        return self.submit(guides, timestep).result(timeout)

    def close(self, cancel_pending: bool = False) -> None:
        """Stop the workers. Waits for submitted batches unless `cancel_pending`
        (their futures then raise `ValidationPoolError`). Idempotent."""
        self._finalizer.detach()
        self._backend.close(cancel_pending)

    def __enter__(self) -> ValidationPool:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        # On an exception (Ctrl-C included) do not wait for queued batches.
        self.close(cancel_pending=exc_type is not None)


def validate_paths(
    terrain,
    guides: Sequence[np.ndarray],
    timestep: float,
    workers: int | None = None,
    config=None,
    *,
    plan_fn: Callable | None = None,
    address: str | None = None,
    task_timeout: float | None = DEFAULT_TASK_TIMEOUT,
    max_attempts: int = DEFAULT_MAX_ATTEMPTS,
    return_plans: bool = True,
) -> list[PathResult]:
    """Run the contact generator on every guide path, in parallel (host-only).

    One-shot form of `ValidationPool`: starts at most `len(guides)` workers,
    plans, stops them. Results are identical for any `workers` value.

    Args:
        terrain: `Terrain` or terrain file text.
        guides: list of [T_i, 4] (x, y, z, yaw) root poses, world frame.
        timestep: s between guide poses.
        workers: processes (None: CPUs - 1; 0: in the calling thread).
        config: `GeneratorConfig` (None: defaults).
        plan_fn, address, task_timeout, max_attempts, return_plans: see `ValidationPool`.

    Returns:
        list[PathResult], `results[i].index == i`; a path whose planner raised,
        whose worker died twice or that timed out has `error` set.
    """
    checked = _check_guides(guides, timestep)
    if not checked:
        return []
    if workers is None and address is None:
        workers = min(_default_workers(), len(checked))
    elif workers and address is None:
        workers = min(int(workers), len(checked))
    with ValidationPool(
        terrain,
        workers=workers,
        config=config,
        plan_fn=plan_fn,
        address=address,
        task_timeout=task_timeout,
        max_attempts=max_attempts,
        return_plans=return_plans,
    ) as pool:
        return pool.map(checked, timestep)
