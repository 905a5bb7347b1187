"""One guide path through the contact generator: what a validation worker runs (host-only).

`PathRunner` is built once per worker from a `WorkerSpec` (terrain text, config, planner)
and plans paths one at a time, turning planner exceptions into error `PathResult`s; the
local process backend (`process`) and the Ray backend (`ray_backend`) both run it, so
seeding, error capture and the result type are the same everywhere.
"""

from __future__ import annotations

import dataclasses
import random
import time
import traceback as traceback_module
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from leas_jax.errors import LeasError
from leas_jax.quiet import c_stdout_discarded


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

    @classmethod
    def failed(
        cls, index: int, error: str, attempts: int, seconds: float = 0.0, traceback: str | None = None
    ) -> PathResult:
        """The result of a path that produced no plan (planner exception, worker death, timeout)."""
        return cls(
            index=index,
            coverage=0.0,
            last_valid_index=-1,
            plan=None,
            error=error,
            attempts=attempts,
            seconds=seconds,
            traceback=traceback,
        )

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
            # hpp-centroidal-dynamics prints a debug line on stdout where qpOASES fails an LP
            # (CLP answers then): kept out of the command's output
            with c_stdout_discarded():
                plan = self._plan(guide, timestep, seed)
            coverage = float(plan.coverage)
            last_valid = int(plan.last_valid_index)
        except Exception as exc:
            return PathResult.failed(
                index,
                _one_line(exc),
                attempts,
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
