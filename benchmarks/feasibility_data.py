"""Training and validation data of the learned feasibility condition (`leas_jax.feasibility`).

A pose's label is the contact generator's *walking truth*
(benchmarks/reachability_calibration.py): the generator covers the 0.36 m straight guide
that starts at the pose along its yaw. Two pose sets:

* fresh poses: `reachability_calibration.sample_poses` on the arena (uniform and near
  obstacles, z over the generator's whole range);
* policy poses: poses on the guides a policy draws on the arena from the env's own random
  resets (`leas_jax.eval.geometric.arena_episodes`, deterministic policy): where the
  condition matters.

Labels are cached in .cache/feasibility_<set>_<key>.npz at the repository root, where
<key> hashes everything a label depends on (`walking_truth.dataset_key`): the terrain file's text,
the generator's settings (`GeneratorConfig`), the generator's sources
(leas_jax/contacts/**/*.py and leas_jax/terrain/**/*.py) and the walking truth's guide. A change to any of them gives
another key, so the labels are rebuilt. Labels are computed in chunks and the cache is
rewritten (atomically) after each one (`leas_jax.feasibility.label_cache`): an interrupted
build resumes where it stopped.
Host-only.
"""

from __future__ import annotations

import multiprocessing
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import reachability_calibration as rc  # noqa: E402

from leas_jax.feasibility.label_cache import cached_labels  # noqa: E402
from leas_jax.feasibility.walking_truth import WALK_TIMESTEP, dataset_key, walking_guide  # noqa: E402

REPO = rc.REPO
CACHE = REPO / ".cache"
CHUNK = 50  # poses per labelling task: a cache write every CHUNK * workers poses


def cache_file(name: str, key: str, cache: Path = CACHE) -> Path:
    """.cache/feasibility_<name>_<first 16 hex digits of key>.npz."""
    return cache / f"feasibility_{name}_{key[:16]}.npz"


class _Progress:
    """Prints labelling progress: poses done and the rate since the first computed chunk."""

    def __init__(self, path: Path):
        self.path, self.began = path, time.perf_counter()

    def __call__(self, done: int, total: int) -> None:
        elapsed = time.perf_counter() - self.began
        print(f"  {self.path.name}: {done} / {total} poses labelled ({elapsed:.0f} s)", flush=True)


_WORKER = {}


def _init_worker(terrain_text: str, generator_config) -> None:
    from leas_jax.contacts.planner.generator import ContactGenerator
    from leas_jax.terrain import loads_terrain

    _WORKER["generator"] = ContactGenerator(
        loads_terrain(terrain_text, source="<feasibility>"), generator_config
    )


def _walking_labels(poses: np.ndarray) -> np.ndarray:
    generator = _WORKER["generator"]
    return np.array(
        [generator.plan(walking_guide(p), WALK_TIMESTEP).coverage >= 1.0 for p in poses], dtype=bool
    )


def walking_labels(
    terrain, poses: np.ndarray, name: str, workers: int = 2, generator_config=None
) -> np.ndarray:
    """The generator's walking truth at poses [N, 4] (bool [N]), cached as `cache_file(name, key)`.

    Host-only: `workers` spawn processes (0 or 1: this process), one ContactGenerator each.
    """
    from leas_jax.contacts.planner.generator import GeneratorConfig

    generator_config = GeneratorConfig() if generator_config is None else generator_config
    key = dataset_key(terrain.text, generator_config)
    path = cache_file(name, key)
    if workers <= 1:
        _init_worker(terrain.text, generator_config)
        return cached_labels(
            poses, key, path, lambda chunks: map(_walking_labels, chunks), CHUNK, _Progress(path)
        )
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(workers, initializer=_init_worker, initargs=(terrain.text, generator_config)) as pool:
        return cached_labels(
            poses, key, path, lambda chunks: pool.imap(_walking_labels, chunks), CHUNK, _Progress(path)
        )


def fresh_poses(terrain, count: int, seed: int) -> np.ndarray:
    """[count, 4] fresh poses (`reachability_calibration.sample_poses`)."""
    return rc.sample_poses(terrain, count, seed)


def policy_poses(policy, terrain, count: int, seed: int, per_guide: int = 4, steps: int = 400) -> np.ndarray:
    """[count, 4] poses on a policy's own arena guides (deterministic policy, env resets, seeded).

    `count / per_guide` episodes (`arena_episodes`); `per_guide` poses drawn uniformly
    (seeded) among each guide's valid poses.
    """
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.eval.geometric import arena_episodes

    n = -(-count // per_guide)
    field = heightfield_from_terrain(terrain, policy.config.env)
    episodes = arena_episodes(policy, field, n=n, seed=seed, steps=steps)
    rng = np.random.default_rng(seed)
    picks = [episodes.poses[k, rng.integers(0, episodes.lengths[k], per_guide)] for k in range(n)]
    return np.concatenate(picks)[:count].astype(np.float64)
