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
  - where the weights hold "footing" points (the walkability model's), the footing shares
    at each (`field.footing_rasters`: ground a sole stands on in static equilibrium, and
    solid ground, around each footstep place of the walking guide): the friction limit is
    the same on every terrain, where the patch's shapes are those of the fitting families
    (docs/results/2026-12-07-walkability-footing);

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
    feature_count,
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
FOOTING_X = (0.04, 0.20, 0.36)  # m, root frame: footstep places along the walking truth's 0.36 m guide


def patch_grid(x_range=PATCH_X, y_range=PATCH_Y, step: float = PATCH_STEP) -> np.ndarray:
    """Root-frame points of the patch, x-major (x slow). Returns [nx * ny, 2] float32 (m)."""
    gx = np.arange(x_range[0], x_range[1] + 1e-9, step)
    gy = np.arange(y_range[0], y_range[1] + 1e-9, step)
    px, py = np.meshgrid(gx, gy, indexing="ij")
    return np.stack([px.ravel(), py.ravel()], axis=-1).astype(np.float32)


def footing_points(reach: ReachabilityConfig = ReachabilityConfig()) -> np.ndarray:
    """Root-frame footstep places the footing shares are read at: FOOTING_X on the left leg's
    line (y = +leg_lateral_offset), then on the right's. Returns [2 * len(FOOTING_X), 2] float32 (m)."""
    x = np.asarray(FOOTING_X, np.float32)
    y = np.full_like(x, reach.leg_lateral_offset)
    return np.concatenate([np.stack([x, y], -1), np.stack([x, -y], -1)]).astype(np.float32)


def mirror_index(grid: np.ndarray) -> np.ndarray:
    """[P] index of each grid point's mirror image across the root's x axis (y -> -y).

    Raises ValueError when the grid is not symmetric in y.
    """
    key = {(round(float(x), 4), round(float(y), 4)): k for k, (x, y) in enumerate(grid)}
    try:
        return np.array([key[(round(float(x), 4), round(float(-y), 4))] for x, y in grid])
    except KeyError:
        raise ValueError("the patch grid is not symmetric in y") from None


def feature_mirror_index(
    grid: np.ndarray, reach: ReachabilityConfig = ReachabilityConfig(), footing: np.ndarray | None = None
) -> np.ndarray:
    """[F] index of each feature in the features of the pose's mirror image (terrain reflected
    across the root's x axis): patch points mirrored, left and right legs and hands swapped,
    footing places (`footing` [K, 2], None: no footing features) mirrored."""
    p = len(grid)
    legs = 2 if reach.leg_forward == 0.0 else 4
    swap = np.arange(legs) ^ 1  # left <-> right, ahead pairs likewise
    groups = 2 + (reach.foothold_spread is not None)  # leg_max, leg_min (, foothold): one value per leg each
    base = p + 2
    margin = [p + 1] + [base + g * legs + k for g in range(groups) for k in swap]
    if reach.hand_radius is not None:
        margin += [base + groups * legs + 1, base + groups * legs]
    index = [mirror_index(grid), [p], margin]
    if footing is not None:
        start = base + margin_count(reach) - 1
        places = mirror_index(np.asarray(footing))
        index += [start + places, start + len(places) + places]
    return np.concatenate(index).astype(np.int64)


def raw_features(
    field: Heightfield,
    pose: jax.Array,
    grid: jax.Array,
    ground: jax.Array,
    clip: jax.Array,
    reach: ReachabilityConfig = ReachabilityConfig(),
    footing: jax.Array | None = None,
) -> jax.Array:
    """Unstandardised features of one pose.

    Args:
        field: the terrain, with the rasters of `reach`.
        pose: [4] (x, y, z, yaw), world.
        grid: [P, 2] root-frame patch points (m).
        ground: [G] int, the grid points within GROUND_RADIUS of the root (`ground_index`).
        clip: [2] (lo, hi) of the relative heights (m).
        reach: the cylinders whose margins are read.
        footing: [K, 2] root-frame footstep places (`footing_points`), or None.

    Returns:
        [P + 1 + M (+ 2 K)]: terrain height minus z at the patch points (clipped), z minus the
        local ground (clipped to HEIGHT_CLIP), the M `reachability.margins` (and the footing
        share, then the solid share, at each footstep place; zero off the raster).
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
    parts = [
        jnp.clip(relative, clip[0], clip[1]),
        jnp.clip(above_ground, *HEIGHT_CLIP)[None],
        reachability.margins(field, pose, reach),
    ]
    if footing is not None:
        place_x, place_y = world_xy(pose, footing)
        parts += [sample_nearest_xy(field, share, place_x, place_y, outside=0.0) for share in field.footing]
    return jnp.concatenate(parts)


def features(
    params: LearnedParams,
    field: Heightfield,
    pose: jax.Array,
    reach: ReachabilityConfig = ReachabilityConfig(),
) -> jax.Array:
    """[F] raw features of one pose [4] on the params' grid, clip and footing places (if any)."""
    return raw_features(
        field, pose, params["grid"], params["ground_index"], params["clip"], reach, params.get("footing")
    )


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
    footing: np.ndarray | None = None,
) -> LearnedParams:
    """Random parameters (Glorot-uniform weights, zero biases, identity standardisation, threshold 0).

    Keys and shapes: grid [P, 2], ground_index [G] (derived from the grid), clip [2], mean and
    std [F] (F = P + 1 + M (+ 2 K), M = `margin_count(reach)`), w0 [F, H0], b0 [H0], w1 [H0,
    H1], b1 [H1], w2 [H1, 1], b2 [1], threshold []; with `footing` [K, 2] (root-frame footstep
    places, `footing_points`), "footing" too.
    """
    grid = patch_grid() if grid is None else np.asarray(grid, np.float32)
    sizes = (feature_count(grid, reach, footing), *hidden, 1)
    params = {
        "grid": jnp.asarray(grid),
        "clip": jnp.asarray(clip, jnp.float32),
        "mean": jnp.zeros(sizes[0]),
        "std": jnp.ones(sizes[0]),
        "threshold": jnp.zeros(()),
    }
    if footing is not None:
        params["footing"] = jnp.asarray(footing, jnp.float32)
    for layer, (k, (n_in, n_out)) in enumerate(
        zip(jax.random.split(key, 3), zip(sizes[:-1], sizes[1:], strict=True), strict=True)
    ):
        limit = np.sqrt(6.0 / (n_in + n_out))
        params[f"w{layer}"] = jax.random.uniform(k, (n_in, n_out), minval=-limit, maxval=limit)
        params[f"b{layer}"] = jnp.zeros(n_out)
    return with_ground_index(params)
