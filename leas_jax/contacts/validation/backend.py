"""What `ValidationPool` needs from an executor, and the job bookkeeping its backends share.

`Backend` is the protocol (`submit` a batch, `close`); `_InlineBackend` plans in the
calling thread (workers=0); `_QueuedBackend` queues one `_Task` per path of a `_Job` for a
dispatcher thread (the local processes of `process`, the actors of `ray_backend`);
`register_backend` adds an executor for an address scheme.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from leas_jax.contacts.validation.runner import PathResult, PathRunner, ValidationPoolError, WorkerSpec

# Workers that die before they report ready this many times in a row mean the
# start-up itself is broken (bad install, bad plan_fn): fail instead of
# respawning forever.
_MAX_STARTUP_DEATHS = 3
# Upper bound of one wait in the dispatcher loop: bounds how late a task timeout
# is noticed when nothing else happens.
_POLL_INTERVAL = 0.5  # s


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
