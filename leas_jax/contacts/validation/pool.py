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
  the parent usually holds JAX/XLA threads, which do not survive a fork. A spawned
  worker imports the caller's main script again, so a script must start its pool
  under `if __name__ == "__main__":`; one that does not gets a `ValidationPoolError`
  saying so (`process.refuse_bootstrap_start`), not a bare start-up failure.
* Each worker loads the terrain (sent once, as its TOML text) and builds the
  planner (Talos model, sample database) once, in its start-up phase, then
  plans any number of paths. A long-lived `ValidationPool` keeps its workers
  across training iterations, so the start-up cost is paid once.
* Results do not depend on the number of workers or on scheduling: every path
  is planned independently, from its guide, the terrain, the config and a seed
  derived from the path's index only (`path_seed`). Nothing random is shared.
* A worker that dies while planning a path (segfault, `os._exit`, SIGKILL by the
  OOM killer) is detected through its process sentinel; the path is retried
  once on a fresh worker, then reported as an error `PathResult` for that path;
  each death is logged (a warning on the `leas_jax.contacts.validation.process`
  logger naming the worker's pid and the path).
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

Where things live: this module is the interface (`ValidationPool`, `validate_paths`);
`runner` plans one path in a worker (`PathRunner`, `PathResult`, `WorkerSpec`);
`backend` holds the executor protocol, the in-process backend and `register_backend`;
`process` the local worker processes; `ray_backend` the Ray actors.

Test hook: `plan_fn=` replaces `plan_contacts` with any picklable module-level
function of the same signature `(terrain, guide, timestep, config) -> plan`,
where `plan` has `coverage` and `last_valid_index` attributes. The test suite
uses it to kill a worker from inside a path (`os._exit`, SIGKILL) and to raise
errors; production code leaves it at None.
"""

from __future__ import annotations

import importlib
import math
import os
import weakref
from collections.abc import Callable, Sequence
from concurrent.futures import Future

import numpy as np

from leas_jax.contacts.validation.backend import (
    _BACKENDS,
    _BUILTIN_BACKENDS,
    Backend,
    _InlineBackend,
    register_backend,
)
from leas_jax.contacts.validation.process import _ProcessBackend
from leas_jax.contacts.validation.runner import (
    PathResult,
    PathRunner,
    ValidationPoolError,
    WorkerSpec,
    path_seed,
)
from leas_jax.errors import UsageError

# Default cap on the wall time of one path. A 400-step guide subsampled every
# 5th pose is 80 contact-planning stages; the generator should take seconds, so
# ten minutes only catches a planner stuck in a loop.
DEFAULT_TASK_TIMEOUT = 600.0  # s
# A path is started at most this many times: once, plus one retry after its
# worker died (the brief of docs/design.md §7: retried once, then an error).
DEFAULT_MAX_ATTEMPTS = 2


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


__all__ = [
    "DEFAULT_MAX_ATTEMPTS",
    "DEFAULT_TASK_TIMEOUT",
    "Backend",
    "PathResult",
    "PathRunner",
    "ValidationPool",
    "ValidationPoolError",
    "WorkerSpec",
    "available_cpus",
    "path_seed",
    "register_backend",
    "validate_paths",
]
