"""The learned feasibility condition's weights: file format, location and the env's check.

Host code (NumPy, files), apart from `learned_feasibility` (the jitted condition) so that
the heightfield builder (`field.heightfield_from_terrain`) can load the weights without
importing the condition, which reads the field.
"""

from __future__ import annotations

import dataclasses
import json
import os
from pathlib import Path

import jax.numpy as jnp
import numpy as np

from leas_jax.env.config import EnvConfig, ReachabilityConfig
from leas_jax.files import resolve_data_path

LAYER_KEYS = ("w0", "b0", "w1", "b1", "w2", "b2")
# m, the local ground is the highest terrain point within this radius of the root (the pose
# sampler's reference ground uses 0.15 m; grid points within it at a 0.08 m spacing: 13)
GROUND_RADIUS = 0.17

LearnedParams = dict  # str -> jax.Array (see `learned_feasibility.init_params` for the keys and shapes)


def margin_count(reach: ReachabilityConfig) -> int:
    """M, the number of `reachability.margins` of a config."""
    legs = 2 if reach.leg_forward == 0.0 else 4
    return (
        1
        + 2 * legs
        + (legs if reach.foothold_spread is not None else 0)
        + (2 if reach.hand_radius is not None else 0)
    )


def feature_count(grid, reach: ReachabilityConfig, footing=None) -> int:
    """F, the number of features the condition reads: patch [P, 2], height above the ground,
    margins, and two shares per footing place [K, 2] (None: none)."""
    return len(grid) + 1 + margin_count(reach) + (0 if footing is None else 2 * len(footing))


def ground_index(grid) -> np.ndarray:
    """[G] int32, the points of a patch grid [P, 2] (root frame, m) within GROUND_RADIUS of the root."""
    grid = np.asarray(grid)
    return np.flatnonzero(np.sum(grid**2, axis=-1) <= GROUND_RADIUS**2).astype(np.int32)


def with_ground_index(params: LearnedParams) -> LearnedParams:
    """params with "ground_index" = `ground_index(params["grid"])`, derived on the host: in jitted
    code the grid is traced, and the index's static shape lets the condition sample the ground's
    few points on their own (`learned_feasibility.raw_features`)."""
    return {**params, "ground_index": jnp.asarray(ground_index(params["grid"]))}


def save_params(path: str | Path, params: LearnedParams, **metadata) -> Path:
    """Write params (and string metadata, e.g. the data key) to an .npz file, atomically. The
    derived "ground_index" is not written (`load_params` derives it again)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + f".tmp{os.getpid()}.npz")
    arrays = {k: np.asarray(v) for k, v in params.items() if k != "ground_index"}
    np.savez(tmp, **arrays, **{f"meta_{k}": np.asarray(str(v)) for k, v in metadata.items()})
    os.replace(tmp, path)
    return path


def load_params(path: str | Path) -> tuple[LearnedParams, dict]:
    """(params, metadata) of an .npz written by `save_params`.

    Raises ValueError naming the file when it cannot be read or lacks a key.
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
    except (OSError, ValueError) as error:
        raise ValueError(f"{path}: cannot read the learned condition's weights ({error})") from None
    needed = ("grid", "clip", "mean", "std", "threshold", *LAYER_KEYS)
    missing = [k for k in needed if k not in arrays]
    if missing:
        raise ValueError(f"{path}: not a learned condition's weights (missing {', '.join(missing)})")
    optional = [k for k in ("footing",) if k in arrays]
    params = {k: jnp.asarray(arrays[k], jnp.float32) for k in (*needed, *optional)}
    metadata = {k[len("meta_") :]: str(v) for k, v in arrays.items() if k.startswith("meta_")}
    return with_ground_index(params), metadata


def condition_params(config: EnvConfig) -> dict:
    """The network's parameters when `config.condition` is "learned" or "walkability" (both read
    `config.learned_weights`; the threshold `config.condition_threshold` where it is set), else
    {} (host)."""
    if config.condition == "cylinders":
        return {}
    if config.condition not in ("learned", "walkability"):
        raise ValueError(
            f"EnvConfig.condition must be 'cylinders', 'learned' or 'walkability', got {config.condition!r}"
        )
    path = resolve_data_path(config.learned_weights)
    params, metadata = load_params(path)
    features = feature_count(params["grid"], config.reachability, params.get("footing"))
    if params["mean"].shape != (features,):
        raise ValueError(
            f"{path}: the learned condition reads {params['mean'].shape[0]} features, but its patch and "
            f"the margins of EnvConfig.reachability give {features}: build the env with the "
            "ReachabilityConfig it was fitted with"
        )
    fitted = metadata.get("reachability")
    if fitted is not None and json.loads(fitted) != dataclasses.asdict(config.reachability):
        raise ValueError(
            f"{path}: the learned condition was fitted on the margins of another ReachabilityConfig "
            f"({fitted}); build the env with that EnvConfig.reachability"
        )
    if config.condition_threshold is not None:
        params = {**params, "threshold": jnp.asarray(config.condition_threshold, jnp.float32)}
    return params
