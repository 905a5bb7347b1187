"""Libraries' notices kept off the command line: mujoco.mjx's optional GPU backend, the LP's
debug line of hpp-centroidal-dynamics (`c_stdout_discarded`).

brax imports mujoco.mjx, whose optional backend `mujoco.mjx.warp` prints "Failed to import
warp: ..." and "Failed to import mujoco_warp: ..." on stdout where warp is not installed,
from whichever module imports brax first (training, the env, a benchmark, a notebook).
`import leas_jax` calls `silence_warp_notice`: that one module then runs with its stdout
discarded. Nothing is imported before brax is, and the backend is the same either way.
"""

from __future__ import annotations

import contextlib
import importlib.abc
import importlib.machinery
import io
import os
import sys

WARP_MODULE = "mujoco.mjx.warp"


class _QuietLoader(importlib.abc.Loader):
    """A module's own loader, run with stdout discarded."""

    def __init__(self, loader: importlib.abc.Loader):
        self.loader = loader

    def create_module(self, spec):
        """The wrapped loader's module (None: the default one)."""
        return self.loader.create_module(spec)

    def exec_module(self, module) -> None:
        """Run the module's code; what it prints on stdout goes nowhere."""
        with contextlib.redirect_stdout(io.StringIO()):
            self.loader.exec_module(module)


class QuietWarpFinder(importlib.abc.MetaPathFinder):
    """Finds `WARP_MODULE` as the path finder would, and gives it a `_QuietLoader`."""

    def find_spec(self, name, path, target=None):
        """The spec of `WARP_MODULE` with a quiet loader; None for every other module."""
        if name != WARP_MODULE:
            return None
        spec = importlib.machinery.PathFinder.find_spec(name, path, target)
        if spec is not None and spec.loader is not None:
            spec.loader = _QuietLoader(spec.loader)
        return spec


def silence_warp_notice() -> None:
    """Put a `QuietWarpFinder` first on `sys.meta_path` (once; later calls do nothing)."""
    if not any(isinstance(finder, QuietWarpFinder) for finder in sys.meta_path):
        sys.meta_path.insert(0, QuietWarpFinder())


_DEVNULL: list[int] = []  # the process's descriptor of os.devnull, opened on first use


@contextlib.contextmanager
def c_stdout_discarded():
    """Discard what compiled code writes on file descriptor 1 inside the block.

    hpp-centroidal-dynamics prints "[DEBUG centroidal_dynamics.cpp 269] Primal LP problem could
    not be solved: 4" on stdout (std::cout, not Python's sys.stdout) where qpOASES fails an LP
    that `HppEquilibrium` then solves with CLP; in a command's output it reads like an error.
    Planning (`contacts.validation.runner.PathRunner.run`) and `contacts.verify` run their LPs
    inside it. (Not in `HppEquilibrium` itself: the generator's code is in the key of its
    labels, `feasibility.spawns.GENERATOR_SOURCES`, and an edit there makes them stale.)
    What Python printed before the block is flushed first; what it prints inside stays in
    sys.stdout's buffer and reaches the descriptor after the block. About 4 us a block, 1-2 % of
    one LP."""
    if not _DEVNULL:
        _DEVNULL.append(os.open(os.devnull, os.O_WRONLY))
    sys.stdout.flush()  # what Python printed before the block reaches stdout, not the void
    saved = os.dup(1)
    try:
        os.dup2(_DEVNULL[0], 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
