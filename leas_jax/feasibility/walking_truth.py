"""The contact generator's walking truth: what a label of the learned condition means, and the
key of everything such a label depends on. Host-only.

A pose is feasible when the contact generator covers the short straight guide that starts at
it along its yaw (`walking_guide`, planned at WALK_TIMESTEP). The learned condition's weights
(`leas feasibility condition`, `condition_build`) record the `dataset_key` of the labels they were fitted
on, the walkability model's (`leas feasibility walkability`) the `generator_key` of the generator
that labelled its families; `stale_weights` compares either with the key the current generator
gives, so that a run about to train or a search about to read weights fitted on another
generator's verdicts says so.
"""

from __future__ import annotations

import hashlib
import warnings
from pathlib import Path

import numpy as np

from leas_jax.feasibility.spawns import GENERATOR_SOURCES, generator_code_digest

WALK_POSES = 21  # guide poses 0.018 m apart (0.36 m in 2 s: two or three footsteps)
WALK_SPEED = 0.18  # m/s, the target speed (paper §IV)
WALK_TIMESTEP = 0.1  # s, paper Table I
RELABEL_COMMAND = "leas feasibility condition --workers 2"
REBUILD_WALKABILITY_COMMAND = "leas feasibility walkability --workers 2"
_REPO = Path(__file__).resolve().parents[2]


class StaleConditionWarning(UserWarning):
    """The learned condition's weights were fitted on labels the current generator would not give."""


def walking_guide(pose: np.ndarray) -> np.ndarray:
    """[WALK_POSES, 4] guide (x, y, z, yaw), world, from `pose` [4] straight ahead along its yaw
    at WALK_SPEED, same z and yaw."""
    steps = np.arange(WALK_POSES) * WALK_SPEED * WALK_TIMESTEP
    guide = np.repeat(np.asarray(pose, np.float64)[None], WALK_POSES, axis=0)
    guide[:, 0] += steps * np.cos(pose[3])
    guide[:, 1] += steps * np.sin(pose[3])
    return guide


def dataset_key(terrain_text: str, generator_config, sources_root: Path | None = None) -> str:
    """sha256 (hex) of what a walking-truth label depends on.

    Args:
        terrain_text: the terrain file's text.
        generator_config: the `GeneratorConfig` the labels are made with (its repr holds every field).
        sources_root: a folder whose .py files stand for the generator's code (None: the
            package's, `spawns.GENERATOR_SOURCES`: the generator and the terrain code).
    """
    digest = hashlib.sha256()
    digest.update(f"walking {WALK_POSES} {WALK_SPEED} {WALK_TIMESTEP}\n".encode())
    digest.update(repr(generator_config).encode())
    digest.update(terrain_text.encode())
    digest.update(
        generator_code_digest(GENERATOR_SOURCES if sources_root is None else (sources_root,)).encode()
    )
    return digest.hexdigest()


def generator_key(generator_config=None) -> str:
    """sha256 (hex) of the contact generator alone: its settings (None: `GeneratorConfig()`) and
    its code (`spawns.GENERATOR_SOURCES`). What every walking label depends on besides its terrain."""
    if generator_config is None:
        from leas_jax.contacts.planner.config import GeneratorConfig

        generator_config = GeneratorConfig()
    digest = hashlib.sha256(repr(generator_config).encode())
    digest.update(generator_code_digest(GENERATOR_SOURCES).encode())
    return digest.hexdigest()


def stale_weights(path: Path, metadata: dict, generator_config=None) -> str | None:
    """Why the weights in `path` no longer match the generator, or None where they do or cannot tell.

    Args:
        path: the weights file (for the message).
        metadata: its metadata (`learned_weights.load_params`): `data_key` and `terrain`, the
            labels' key and terrain file (relative to the repository root), as
            `leas feasibility condition` writes them; or `generator_key`, as
            `leas feasibility walkability` writes it. Weights without them (the planner
            phase's refits, hand-made weights, walkability models built before the key was
            recorded) cannot be checked: None.
        generator_config: the generator to compare with (None: `GeneratorConfig()`, the one
            the labels are made with).
    """
    recorded = metadata.get("generator_key")
    if recorded:
        now = generator_key(generator_config)
        if now == recorded:
            return None
        return (
            f"{path}: the walkability model was fitted on walking verdicts of another contact generator "
            f"(labels {recorded[:12]}, the current generator's {now[:12]}): it may disagree with the "
            f"generator; rebuild it with `{REBUILD_WALKABILITY_COMMAND}`"
        )
    key, terrain = metadata.get("data_key"), metadata.get("terrain")
    if not key or not terrain:
        return None
    terrain_path = Path(terrain) if Path(terrain).is_absolute() else _REPO / terrain
    if not terrain_path.is_file():
        return None
    if generator_config is None:
        from leas_jax.contacts.planner.config import GeneratorConfig

        generator_config = GeneratorConfig()
    now = dataset_key(terrain_path.read_text(), generator_config)
    if now == key:
        return None
    return (
        f"{path}: the learned condition was fitted on walking verdicts of another contact generator "
        f"or {terrain} (labels {key[:12]}, the current generator's {now[:12]}): it may disagree with "
        f"the generator; relabel and refit with `{RELABEL_COMMAND}` (about 20 min on 2 cores)"
    )


def warn_if_stale(path: Path, metadata: dict, generator_config=None) -> None:
    """`stale_weights`' message as a StaleConditionWarning, where there is one."""
    message = stale_weights(path, metadata, generator_config)
    if message:
        warnings.warn(message, StaleConditionWarning, stacklevel=3)
