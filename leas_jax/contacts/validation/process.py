"""Local worker processes for `ValidationPool` (host-only): spawn, dispatch, watch, respawn.

One dispatcher thread in the parent owns every pipe and process: it hands one path at a
time to each ready worker (so it always knows which path a dead worker was planning),
reads results, watches process sentinels for deaths and in-flight paths for timeouts,
respawns workers and completes futures. Workers run `_worker_main`: a `PathRunner`, then
paths until told to stop.
"""

from __future__ import annotations

import collections
import dataclasses
import itertools
import logging
import multiprocessing
import os
import signal
import sys
import threading
import time
import traceback as traceback_module
from dataclasses import dataclass
from multiprocessing.connection import wait as wait_for_ready
from typing import Any

from leas_jax.contacts.validation.backend import (
    _MAX_STARTUP_DEATHS,
    _POLL_INTERVAL,
    _Job,
    _QueuedBackend,
    _Task,
)
from leas_jax.contacts.validation.runner import (
    PathResult,
    PathRunner,
    ValidationPoolError,
    WorkerSpec,
    _one_line,
)

# How long close() waits for a worker to exit after asking it to, before SIGKILL.
_STOP_GRACE = 5.0  # s
# Exit status of a worker that found itself re-running the caller's script (see
# `refuse_bootstrap_start`): EX_CONFIG of sysexits.h, a usage mistake, not a crash.
SPAWN_GUARD_EXIT = 78

logger = logging.getLogger(__name__)

SPAWN_GUARD_MESSAGE = (
    "contact workers could not start: the script that started the validation pool runs it at "
    "import time. Workers are started with 'spawn' (JAX threads do not survive 'fork'), and a "
    "spawned worker imports the main script again, so each worker tried to start a pool of its own. "
    "Put the code that calls validate_paths / ValidationPool under\n"
    '    if __name__ == "__main__":\n'
    "in the script {script}, or pass workers=0 to plan in this process."
)


def refuse_bootstrap_start() -> None:
    """Stop a spawned worker that is re-running its parent's main script and reached a pool.

    A spawned child re-imports the parent's `__main__` (as `__mp_main__`) before it
    unpickles its target; a script that makes a pool at top level then makes one in
    every child, which multiprocessing refuses with a traceback the parent never sees.
    Called where a pool would start processes: in such a child (multiprocessing marks its
    bootstrapping phase with `current_process()._inheriting`, the flag its own check
    reads), print why to stderr and exit with `SPAWN_GUARD_EXIT`, which the parent
    turns into a `ValidationPoolError` that says how to fix the script.
    """
    if getattr(multiprocessing.current_process(), "_inheriting", False):
        main = sys.modules.get("__main__")
        script = getattr(main, "__file__", None) or "<main script>"
        print(SPAWN_GUARD_MESSAGE.format(script=script), file=sys.stderr, flush=True)
        raise SystemExit(SPAWN_GUARD_EXIT)


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
        refuse_bootstrap_start()
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
            if worker.process.exitcode == SPAWN_GUARD_EXIT:
                main = sys.modules.get("__main__")
                script = getattr(main, "__file__", None) or "<main script>"
                self._break(ValidationPoolError(SPAWN_GUARD_MESSAGE.format(script=script)))
            elif self._startup_deaths >= _MAX_STARTUP_DEATHS:
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
            logger.warning(
                "contact worker pid %s killed: path %d ran past the task timeout of %g s",
                pid,
                task.index,
                self._task_timeout,
            )
            self._complete(
                task,
                PathResult.failed(
                    task.index,
                    f"TimeoutError: path {task.index} took longer than {self._task_timeout:g} s "
                    f"(worker pid {pid} killed)",
                    task.attempts,
                    seconds=time.monotonic() - worker.task_started,
                ),
            )
            return
        how = _describe_exit(worker.process.exitcode)
        if task.attempts < self._max_attempts:
            logger.warning(
                "contact worker pid %s %s while planning path %d (attempt %d of %d); "
                "retrying the path on a fresh worker",
                pid,
                how,
                task.index,
                task.attempts,
                self._max_attempts,
            )
            # Front of the queue: the retry should not wait behind later batches.
            self._queue.appendleft(task)
        else:
            logger.warning(
                "contact worker pid %s %s while planning path %d, on each of %d attempts; "
                "the path is reported as an error",
                pid,
                how,
                task.index,
                task.attempts,
            )
            self._complete(
                task,
                PathResult.failed(
                    task.index,
                    f"WorkerDied: contact worker (pid {pid}) {how} while planning path "
                    f"{task.index}, on each of {task.attempts} attempts",
                    task.attempts,
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
