"""The learned feasibility condition: a small network on the terrain around the root. Pure, jittable.

It stands in for the reachability cylinders (`reachability.valid`) as the environment's
termination condition when `EnvConfig.condition` is "learned" (`leas_jax.env.condition`).
It reads

  - a root-frame height patch: the terrain height minus the root's z at the points of a
    regular grid turning with the yaw (`patch_grid`; nearest raster cell, the void height
    off the raster), clipped to `clip`;
  - the root's height above the local ground: z minus the highest terrain point of the
    patch within `GROUND_RADIUS` of the root (studies/reachability_calibration.py draws
    its poses relative to that ground);
  - the cylinders' own margins (`reachability.margins` with the env's ReachabilityConfig,
    the calibrated one by default): the network refines the calibrated condition's
    boundary instead of learning the whole geometry from a few thousand verdicts (on
    3 200 fresh poses, the patch alone reached 99.0 / 64.7 % on fresh poses where the
    calibrated cylinders give 96.0 / 91.5 %: docs/results/2026-12-01-feasibility);

standardises them and runs a tanh MLP to one logit. The pose is feasible when the logit
is at least the stored threshold. Everything, grid included, is data in one dict of
arrays (`LearnedParams`), saved as an .npz file (`save_params`, `load_params`): the
heightfield carries it (`Heightfield.condition`) like its rasters, so jitted code that
takes a field takes the condition with it. leas_jax.feasibility trains it on the contact
generator's walking verdicts.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from leas_jax.env import reachability
from leas_jax.env.config import ReachabilityConfig
from leas_jax.env.field import Heightfield, sample_nearest_xy
from leas_jax.env.kinematics import world_xy
from leas_jax.env.learned_weights import (  # noqa: F401 (the weights' file API, re-exported)
    GROUND_RADIUS,
    LAYER_KEYS,
    LearnedParams,
    load_params,
    margin_count,
    save_params,
    with_ground_index,
)

# m, the grid: behind the heels to past the next footsteps (the walking truth's guide is
# 0.36 m), across past the half-sitting grippers (0.55 m beside the root)
PATCH_X = (-0.40, 0.64)
PATCH_Y = (-0.64, 0.64)
PATCH_STEP = 0.08  # m; half the 0.04 m of the gradient-boosted reference: 238 points instead of 858
CLIP = (-1.6, 0.4)  # m, relative heights (the arena's void is 2 m below its ground)
HEIGHT_CLIP = (0.0, 2.0)  # m, height above the local ground


def patch_grid(x_range=PATCH_X, y_range=PATCH_Y, step: float = PATCH_STEP) -> np.ndarray:
    """Root-frame points of the patch, x-major (x slow). Returns [nx * ny, 2] float32 (m)."""
    gx = np.arange(x_range[0], x_range[1] + 1e-9, step)
    gy = np.arange(y_range[0], y_range[1] + 1e-9, step)
    px, py = np.meshgrid(gx, gy, indexing="ij")
    return np.stack([px.ravel(), py.ravel()], axis=-1).astype(np.float32)


def mirror_index(grid: np.ndarray) -> np.ndarray:
    """[P] index of each grid point's mirror image across the root's x axis (y -> -y).

    Raises ValueError when the grid is not symmetric in y.
    """
    key = {(round(float(x), 4), round(float(y), 4)): k for k, (x, y) in enumerate(grid)}
    try:
        return np.array([key[(round(float(x), 4), round(float(-y), 4))] for x, y in grid])
    except KeyError:
        raise ValueError("the patch grid is not symmetric in y") from None


def feature_mirror_index(grid: np.ndarray, reach: ReachabilityConfig = ReachabilityConfig()) -> np.ndarray:
    """[F] index of each feature in the features of the pose's mirror image (terrain reflected
    across the root's x axis): patch points mirrored, left and right legs and hands swapped."""
    p = len(grid)
    legs = 2 if reach.leg_forward == 0.0 else 4
    swap = np.arange(legs) ^ 1  # left <-> right, ahead pairs likewise
    groups = 2 + (reach.foothold_spread is not None)  # leg_max, leg_min (, foothold): one value per leg each
    base = p + 2
    margin = [p + 1] + [base + g * legs + k for g in range(groups) for k in swap]
    if reach.hand_radius is not None:
        margin += [base + groups * legs + 1, base + groups * legs]
    return np.concatenate([mirror_index(grid), [p], margin]).astype(np.int64)


def raw_features(
    field: Heightfield,
    pose: jax.Array,
    grid: jax.Array,
    ground: jax.Array,
    clip: jax.Array,
    reach: ReachabilityConfig = ReachabilityConfig(),
) -> jax.Array:
    """Unstandardised features of one pose.

    Args:
        field: the terrain, with the rasters of `reach`.
        pose: [4] (x, y, z, yaw), world.
        grid: [P, 2] root-frame patch points (m).
        ground: [G] int, the grid points within GROUND_RADIUS of the root (`ground_index`).
        clip: [2] (lo, hi) of the relative heights (m).
        reach: the cylinders whose margins are read.

    Returns:
        [P + 1 + M]: terrain height minus z at the patch points (clipped), z minus the
        local ground (clipped to HEIGHT_CLIP), the M `reachability.margins`.
    """
    x, y = world_xy(pose, grid)
    relative = sample_nearest_xy(field, field.heights, x, y) - pose[2]
    # The ground's points are sampled again rather than read from `relative`: the same values,
    # but XLA's CPU backend does not fuse a gather read both by the patch and by a reduction,
    # which made `quick` training with this condition about 1.1 x slower on 2 cores
    # (`benchmarks/train_throughput.py`, docs/results/2026-12-05-condition-ground-gather).
    ground_x, ground_y = world_xy(pose, grid[ground])
    above_ground = pose[2] - jnp.max(
        sample_nearest_xy(field, field.heights, ground_x, ground_y), initial=-jnp.inf
    )
    return jnp.concatenate(
        [
            jnp.clip(relative, clip[0], clip[1]),
            jnp.clip(above_ground, *HEIGHT_CLIP)[None],
            reachability.margins(field, pose, reach),
        ]
    )


def features(
    params: LearnedParams,
    field: Heightfield,
    pose: jax.Array,
    reach: ReachabilityConfig = ReachabilityConfig(),
) -> jax.Array:
    """[P + 1 + M] raw features of one pose [4] on the params' grid and clip."""
    return raw_features(field, pose, params["grid"], params["ground_index"], params["clip"], reach)


def logit_of_features(params: LearnedParams, x: jax.Array) -> jax.Array:
    """Logit of feasibility from raw features [..., F] -> [...] (tanh MLP, standardised inputs)."""
    h = (x - params["mean"]) / params["std"]
    h = jnp.tanh(h @ params["w0"] + params["b0"])
    h = jnp.tanh(h @ params["w1"] + params["b1"])
    return (h @ params["w2"] + params["b2"])[..., 0]


def logit(
    params: LearnedParams,
    field: Heightfield,
    pose: jax.Array,
    reach: ReachabilityConfig = ReachabilityConfig(),
) -> jax.Array:
    """Logit of feasibility of one pose [4] (x, y, z, yaw), world -> []."""
    return logit_of_features(params, features(params, field, pose, reach))


def valid(
    params: LearnedParams,
    field: Heightfield,
    pose: jax.Array,
    reach: ReachabilityConfig = ReachabilityConfig(),
) -> jax.Array:
    """True when the learned condition accepts the pose. pose: [4] (x, y, z, yaw), world -> bool[].
    `reach` must be the ReachabilityConfig the weights were fitted with (and the field built with)."""
    return logit(params, field, pose, reach) >= params["threshold"]


def init_params(
    key: jax.Array,
    hidden=(64, 32),
    grid: np.ndarray | None = None,
    clip=CLIP,
    reach: ReachabilityConfig = ReachabilityConfig(),
) -> LearnedParams:
    """Random parameters (Glorot-uniform weights, zero biases, identity standardisation, threshold 0).

    Keys and shapes: grid [P, 2], ground_index [G] (derived from the grid), clip [2], mean and
    std [F] (F = P + 1 + M, M = `margin_count(reach)`), w0 [F, H0], b0 [H0], w1 [H0, H1], b1
    [H1], w2 [H1, 1], b2 [1], threshold [].
    """
    grid = patch_grid() if grid is None else np.asarray(grid, np.float32)
    sizes = (len(grid) + 1 + margin_count(reach), *hidden, 1)
    params = {
        "grid": jnp.asarray(grid),
        "clip": jnp.asarray(clip, jnp.float32),
        "mean": jnp.zeros(sizes[0]),
        "std": jnp.ones(sizes[0]),
        "threshold": jnp.zeros(()),
    }
    for layer, (k, (n_in, n_out)) in enumerate(
        zip(jax.random.split(key, 3), zip(sizes[:-1], sizes[1:], strict=True), strict=True)
    ):
        limit = np.sqrt(6.0 / (n_in + n_out))
        params[f"w{layer}"] = jax.random.uniform(k, (n_in, n_out), minval=-limit, maxval=limit)
        params[f"b{layer}"] = jnp.zeros(n_out)
    return with_ground_index(params)
