"""The notice of mujoco.mjx's optional GPU backend, kept off the command line.

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
