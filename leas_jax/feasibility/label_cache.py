"""A resumable on-disk cache of per-pose labels (the contact generator's verdicts).

Labelling poses with the generator costs milliseconds to seconds a pose, so labels are
computed chunk by chunk and the cache file is rewritten (atomically) after each chunk: an
interrupted build resumes after its last finished chunk. A file is reused only for the same
poses under the same key (a hash of everything the labels depend on, made by the caller),
else rebuilt. Host only. Used by the generator-verified spawns
(`leas_jax.feasibility.spawns`) and the data of the learned condition and of the walkability
model (`walkability.walking_labels`, `leas feasibility`).
"""

from __future__ import annotations

import io
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from leas_jax.files import atomic_write_bytes


def load_partial(path: Path, poses: np.ndarray, key: str) -> np.ndarray:
    """Labels cached in `path` for a prefix of `poses` [N, 4] under `key`: bool [k], k <= N
    (empty when the file is missing, damaged, holds other poses or another key)."""
    if not Path(path).is_file():
        return np.zeros(0, bool)
    try:
        with np.load(path) as data:
            if str(data["key"]) != key:
                return np.zeros(0, bool)
            if data["poses"].shape != poses.shape or not np.array_equal(data["poses"], poses):
                return np.zeros(0, bool)
            return np.asarray(data["labels"][: int(data["done"])], bool)
    except (OSError, ValueError, KeyError):  # a damaged file is rebuilt
        return np.zeros(0, bool)


def _save(path: Path, **arrays) -> None:
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    atomic_write_bytes(path, buffer.getvalue())


def cached_labels(
    poses: np.ndarray,
    key: str,
    path: Path,
    label_chunks: Callable[[list[np.ndarray]], Iterable[np.ndarray]],
    chunk: int,
    progress: Callable[[int, int], None] | None = None,
) -> np.ndarray:
    """Labels of poses [N, 4], from the cache where it has them, the rest computed and cached.

    Args:
        poses: [N, 4] (x, y, z, yaw), world.
        key: hash of what the labels depend on.
        path: the cache file.
        label_chunks: maps a list of pose chunks to an iterable of bool label arrays, in order
            (a pool's imap, a generator over a `ValidationPool`, a plain map in tests); it is
            not called when the cache holds every label.
        chunk: poses per chunk.
        progress: called with (labels done, N) after each computed chunk.

    Returns:
        bool [N]. The cache holds poses, labels, the number done and the key after every chunk.
    """
    poses = np.asarray(poses, np.float64)
    labels = np.zeros(len(poses), bool)
    done = len(known := load_partial(path, poses, key))
    labels[:done] = known
    if done < len(poses):
        starts = range(done, len(poses), chunk)
        for start, part in zip(starts, label_chunks([poses[s : s + chunk] for s in starts]), strict=True):
            labels[start : start + len(part)] = part
            done = start + len(part)
            _save(Path(path), poses=poses, labels=labels, done=done, key=np.array(key))
            if progress is not None:
                progress(done, len(poses))
    return labels
