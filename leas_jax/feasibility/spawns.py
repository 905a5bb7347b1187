"""Start poses the contact generator can stand on: the resets of `EnvConfig(spawns="generator")`.

The env's own spawn points (`leas_jax.env.field`) are grid points where the reachability
cylinders hold for every yaw. The contact generator disagrees at some of them: on the
training arena 8 % of them, at a random yaw, are poses where Talos cannot stand in double
support (feet on faces, leg IK, collisions, equilibrium), so guides starting there fail at
their first pose whatever the policy does. `verified_spawns` draws `EnvConfig.spawn_yaws`
random yaws at every spawn point, asks the generator (`ContactGenerator.double_support`, as
the first pose of a one-pose guide through `ValidationPool`), and keeps the poses it accepts
as the field's (spawn_xy, spawn_yaw) table; resets then start exactly at one of them.

Host only (the generator is not jittable). Verdicts are cached in `cache_dir()` under a key
of everything they depend on (the poses, terrain text, generator settings and code), written
chunk by chunk (`label_cache`): an interrupted build resumes where it stopped.
"""

from __future__ import annotations

import dataclasses
import hashlib
from pathlib import Path

import numpy as np

from leas_jax.feasibility.label_cache import cached_labels

SPAWN_MODES = ("condition", "generator")
CHUNK = 2000  # poses per pool batch: a cache write and a progress-bar update each
_FORMAT = "leas-verified-spawns-v1"
_PACKAGE = Path(__file__).resolve().parent.parent
# the code a generator verdict depends on: the generator and the robot model, and the terrain's
# loading, rasters and support faces; not the viewer, the worker pools, nor the terrain
# generators and commands, whose edits change no verdict
GENERATOR_SOURCES = (
    _PACKAGE / "contacts" / "planner",
    _PACKAGE / "contacts" / "robot",
    *(_PACKAGE / "terrain" / f"{name}.py" for name in ("loader", "mesh", "model", "sources")),
)


def generator_code_digest(roots=GENERATOR_SOURCES) -> str:
    """sha256 (hex) of every .py file below `roots` (folders, or .py files themselves; relative
    name and bytes), in order."""
    digest = hashlib.sha256()
    for root in map(Path, roots):
        base = root.parent if root.is_file() else root
        for path in [root] if root.is_file() else sorted(root.rglob("*.py")):
            digest.update(f"{base.name}/{path.relative_to(base)}".encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def root_poses(field, xy: np.ndarray, yaw: np.ndarray, nominal_root_height: float) -> np.ndarray:
    """[N, 4] poses (x, y, z, yaw), world, of roots at world points xy [N, 2] with yaws [N]:
    z the terrain under the point + the nominal root height (the reset's z rule,
    `LeasEnv.random_root`)."""
    import jax.numpy as jnp

    from leas_jax.env.field import sample_bilinear

    z = np.asarray(sample_bilinear(field, jnp.asarray(xy, dtype=jnp.float32)), dtype=np.float64)
    return np.column_stack([np.asarray(xy, np.float64), z + nominal_root_height, yaw])


def candidate_poses(field, config, seed: int = 0) -> np.ndarray:
    """[S * spawn_yaws, 4] `root_poses`: `config.spawn_yaws` seeded random yaws at each of the
    field's spawn points."""
    xy = np.repeat(np.asarray(field.spawn_xy, dtype=np.float64), config.spawn_yaws, axis=0)
    yaw = np.random.default_rng(seed).uniform(-np.pi, np.pi, len(xy))
    return root_poses(field, xy, yaw, config.nominal_root_height)


def spawn_key(terrain_text: str, poses: np.ndarray, generator_config) -> str:
    """sha256 (hex) of what the verdicts depend on: the poses, the terrain, the generator's
    settings and code (`generator_code_digest`)."""
    digest = hashlib.sha256(_FORMAT.encode())
    digest.update(np.ascontiguousarray(poses, dtype=np.float64).tobytes())
    digest.update(terrain_text.encode())
    digest.update(repr(generator_config).encode())
    digest.update(generator_code_digest().encode())
    return digest.hexdigest()


def standing_verdicts(
    terrain, poses: np.ndarray, generator_config=None, workers: int | None = None, progress: bool = True
) -> np.ndarray:
    """bool [N]: whether the contact generator stands in double support at each pose [N, 4].

    Host only. Cached in `cache_dir()` (`label_cache.cached_labels`, under `spawn_key`);
    `workers` as `ValidationPool`'s.
    """
    from leas_jax.contacts.planner.config import GeneratorConfig
    from leas_jax.contacts.robot.database import cache_dir
    from leas_jax.contacts.validation.pool import ValidationPool

    config = GeneratorConfig() if generator_config is None else generator_config
    key = spawn_key(terrain.text, poses, config)

    def label_chunks(chunks):
        with ValidationPool(terrain, workers=workers, config=config, return_plans=False) as pool:
            for chunk in chunks:
                results = pool.map([pose[None] for pose in chunk], 1.0)  # one-pose guides
                errors = [r.error for r in results if r.error is not None]
                if errors:
                    raise RuntimeError(f"the contact generator failed on a spawn pose: {errors[0]}")
                yield np.array([r.last_valid_index == 0 for r in results])

    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(poses), desc="spawn poses", unit="pose")
    try:
        return cached_labels(
            poses,
            key,
            cache_dir() / f"spawns_{key[:24]}.npz",
            label_chunks,
            CHUNK,
            None if bar is None else lambda done, _: bar.update(done - bar.n),
        )
    finally:
        if bar is not None:
            bar.close()


def verified_spawns(field, terrain, config, generator_config=None, workers=None, progress=True, seed=0):
    """The field with its spawns replaced by verified start poses (`spawn_xy`, `spawn_yaw`).

    Args:
        field: the terrain's `Heightfield` (its condition spawn points are the candidates).
        terrain: the `Terrain` it was built from.
        config: the `EnvConfig` (`spawn_yaws`, `nominal_root_height`).
        generator_config: `GeneratorConfig` of the verdicts (None: defaults).
        workers, progress: generator processes, progress bar.
        seed: seed of the candidate yaws.

    Returns:
        Heightfield whose spawn table holds the candidates the generator stands on.

    Raises:
        UsageError: the generator stands on none of them.
    """
    import jax.numpy as jnp

    from leas_jax.errors import UsageError

    poses = candidate_poses(field, config, seed)
    stands = standing_verdicts(terrain, poses, generator_config, workers, progress)
    if not stands.any():
        raise UsageError(
            f"terrain {terrain.name!r}: the contact generator stands at none of the "
            f"{len(poses)} spawn poses; use EnvConfig(spawns='condition')"
        )
    kept = poses[stands]
    return dataclasses.replace(
        field,
        spawn_xy=jnp.asarray(kept[:, :2], dtype=jnp.float32),
        spawn_yaw=jnp.asarray(kept[:, 3], dtype=jnp.float32),
    )


def arena_field(terrain, config, workers=None, progress=True):
    """The `Heightfield` random resets start on: the terrain's, with verified spawns when
    `config.spawns` is "generator" (host only; see `verified_spawns`). Raises TerrainError,
    naming the terrain file, when the terrain has no spawn point."""
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.errors import UsageError

    if config.spawns not in SPAWN_MODES:
        raise UsageError(f"EnvConfig.spawns must be one of {', '.join(SPAWN_MODES)}, got {config.spawns!r}")
    if not (isinstance(config.spawn_yaws, int) and config.spawn_yaws >= 1):
        raise UsageError(f"EnvConfig.spawn_yaws must be an integer >= 1, got {config.spawn_yaws!r}")
    field = heightfield_from_terrain(terrain, config, require_spawn=True)
    if config.spawns == "generator":
        field = verified_spawns(field, terrain, config, workers=workers, progress=progress)
        if terrain.curriculum is not None:
            from leas_jax.env.field import with_curriculum

            field = with_curriculum(field, terrain.curriculum, terrain.path or terrain.name)
    return field
