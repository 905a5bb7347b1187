"""Atomic checkpoints of training runs (host only).

Layout of a run directory:
    config.json                 the TrainConfig (written once, checked on resume)
    checkpoints/step_<N>.pkl    full TrainState (optimizer, normaliser, env states, key)
    policy.pkl                  what inference needs: normaliser + policy params + config
    metrics.jsonl, tb/          logs
Every file is written to a temporary name in the same directory and renamed,
so a crash never leaves a truncated checkpoint.
"""

from __future__ import annotations

import os
import pickle
import re
import tempfile
from pathlib import Path

import jax
import numpy as np

from leas_jax.errors import LeasError

_STEP_FILE = re.compile(r"step_(\d+)\.pkl$")


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write `data` to `path` through a temporary file and an atomic rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    atomic_write_bytes(path, text.encode())


def to_host(tree):
    """Device arrays -> NumPy arrays (pickle-friendly)."""
    return jax.tree.map(np.asarray, jax.device_get(tree))


def list_checkpoints(run_dir: Path) -> list[tuple[int, Path]]:
    """[(env_steps, path)] sorted by steps."""
    folder = Path(run_dir) / "checkpoints"
    if not folder.is_dir():
        return []
    found = [(int(m.group(1)), p) for p in folder.iterdir() if (m := _STEP_FILE.search(p.name))]
    return sorted(found)


def save_state(run_dir: Path, state, env_steps: int, keep: int) -> Path:
    """Pickle the full training state atomically; keep the `keep` newest files."""
    path = Path(run_dir) / "checkpoints" / f"step_{env_steps:012d}.pkl"
    atomic_write_bytes(path, pickle.dumps(to_host(state), protocol=pickle.HIGHEST_PROTOCOL))
    for _, old in list_checkpoints(run_dir)[:-keep]:
        old.unlink(missing_ok=True)
    return path


def load_state(path: Path):
    """Load a pickled training state (NumPy leaves)."""
    try:
        with open(path, "rb") as f:
            return pickle.load(f)
    except (OSError, pickle.UnpicklingError, EOFError) as exc:
        raise LeasError(f"{path}: cannot read checkpoint ({exc})") from exc


def save_policy(run_dir: Path, normalizer, policy_params, config_dict: dict, env_steps: int) -> Path:
    """Write `policy.pkl`: everything `load_policy` needs, nothing more."""
    payload = {
        "format": "leas-policy-v1",
        "config": config_dict,
        "env_steps": int(env_steps),
        "normalizer": to_host(normalizer),
        "policy_params": to_host(policy_params),
    }
    path = Path(run_dir) / "policy.pkl"
    atomic_write_bytes(path, pickle.dumps(payload, protocol=pickle.HIGHEST_PROTOCOL))
    return path
