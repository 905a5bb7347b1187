"""The terrain as JAX data: heights and reachability rasters on a regular grid.

`Heightfield` is a pytree passed to the pure functions (never a constant baked
into a closure). Host code builds it once per terrain with
`heightfield_from_terrain`; everything else here is jittable.

Grid convention (same as `Terrain.raster()`): `heights[i, j]` is the terrain
height at world point `(x0 + i * res, y0 + j * res)`. Outside the grid the
terrain is `void_height` (the void the boxes stand over).
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import numpy as np
from flax import struct
from scipy import ndimage

from leas_jax.env.config import EnvConfig, ReachabilityConfig
from leas_jax.env.learned_weights import condition_params
from leas_jax.errors import TerrainError


@struct.dataclass
class Heightfield:
    """Terrain rasters, world frame.

    Attributes:
        heights: [nx, ny] terrain height (m).
        trunk_max: [nx, ny] highest terrain point within `trunk_radius` of the point.
        leg_max: [nx, ny] highest solid terrain point within `leg_radius` of the point
            (-inf where there is only void).
        leg_min: [nx, ny] lowest solid terrain point within `leg_radius` of the point
            (+inf where there is only void).
        foothold: [nx, ny] smallest height spread of a sole disk of radius `foothold_radius`
            centred within `foothold_search` of the point (+inf where every such disk touches
            the void); [1, 1] zeros when the foothold term is disabled (`foothold_spread` None).
        hand_max: [nx, ny] highest terrain point within `hand_radius` of the point; [1, 1]
            zeros when the hands term is disabled (`hand_radius` None).
        footing: [2, nx, ny] the share of ground within FOOTING_SHARE_RADIUS of the point a
            sole stands on in static equilibrium, and the share of solid ground there
            (`footing_rasters`; the walkability model reads both).
        origin: [2] world (x, y) of `heights[0, 0]`.
        resolution: [] cell size (m).
        void_height: [] height outside the grid.
        spawn_xy: [S, 2] world (x, y) of the reset positions: grid points where a root at
            nominal height is valid for every yaw (resets draw around them), or, where
            `spawn_yaw` is set, positions of verified start poses (resets use them as they are).
            S is 0 on a terrain with no such point (too small or too rough): the field then
            serves rollouts from given starts, not random resets (`LeasEnv.random_root`).
        spawn_yaw: [S] yaw (rad, world) of each verified start pose; NaN where any yaw is
            valid (`EnvConfig.spawns`: "condition" gives NaN everywhere, "generator" none).
        spawn_spacing: [] spacing of the spawn candidates (m); resets jitter within it.
        condition: the learned feasibility condition's parameters
            (`learned_feasibility.LearnedParams`) when `EnvConfig.condition` is "learned",
            else {} (no leaves).
        curriculum: on a curriculum arena (`with_curriculum`), its rows: "level_start" [L]
            int32, the index of each row's first spawn point (spawns are sorted by row) and
            "level_count" [L] int32, its number of spawn points; else {} (no leaves).
    """

    heights: jax.Array
    trunk_max: jax.Array
    leg_max: jax.Array
    leg_min: jax.Array
    foothold: jax.Array
    hand_max: jax.Array
    footing: jax.Array
    origin: jax.Array
    resolution: jax.Array
    void_height: jax.Array
    spawn_xy: jax.Array
    spawn_yaw: jax.Array
    spawn_spacing: jax.Array
    condition: dict = struct.field(default_factory=dict)
    curriculum: dict = struct.field(default_factory=dict)


def with_curriculum(field: Heightfield, curriculum, name: str = "the terrain") -> Heightfield:
    """The field with its spawn points sorted by curriculum row and the rows' index (host).

    Args:
        field: the heightfield of a curriculum arena.
        curriculum: its `leas_jax.terrain.model.Curriculum` layout (rows along x from the
            field's origin).
        name: the terrain, for the error.

    Raises:
        TerrainError: a row has no spawn point (training envs could not start on it).
    """
    xy = np.asarray(field.spawn_xy)
    x0 = float(np.asarray(field.origin)[0])
    level = np.clip(((xy[:, 0] - x0) // curriculum.tile[0]).astype(np.int64), 0, curriculum.levels - 1)
    order = np.argsort(level, kind="stable")
    count = np.bincount(level, minlength=curriculum.levels)
    if np.any(count == 0):
        empty = ", ".join(str(k) for k in np.flatnonzero(count == 0))
        raise TerrainError(f"{name}: curriculum rows {empty} have no spawn position for training episodes")
    start = np.concatenate([[0], np.cumsum(count)[:-1]])
    return field.replace(
        spawn_xy=field.spawn_xy[order],
        spawn_yaw=field.spawn_yaw[order],
        curriculum={
            "level_start": jnp.asarray(start, jnp.int32),
            "level_count": jnp.asarray(count, jnp.int32),
        },
    )


def _grid_index(field: Heightfield, x: jax.Array, y: jax.Array):
    """Continuous grid coordinates of world points. x, y: [...] -> ([...], [...])."""
    u = (x - field.origin[0]) / field.resolution
    v = (y - field.origin[1]) / field.resolution
    return u, v


def sample_nearest(field: Heightfield, raster: jax.Array, xy: jax.Array, outside=None) -> jax.Array:
    """Value of `raster` at the grid point nearest to each world point; `outside` (default: the
    void height) beyond the grid.

    Args:
        field: the heightfield (for origin, resolution, void height).
        raster: [nx, ny] one of the field's rasters.
        xy: [..., 2] world points.

    Returns:
        [...] raster values.
    """
    return sample_nearest_xy(field, raster, xy[..., 0], xy[..., 1], outside)


def sample_nearest_xy(field: Heightfield, raster: jax.Array, x: jax.Array, y: jax.Array, outside=None):
    """`sample_nearest` of the world points (x, y), x and y: [...] each -> [...] raster values.

    Many points per pose sample faster given as two arrays (`kinematics.world_xy`) than as
    one [..., 2] array.
    """
    nx, ny = raster.shape
    u, v = _grid_index(field, x, y)
    i = jnp.round(u).astype(jnp.int32)
    j = jnp.round(v).astype(jnp.int32)
    inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
    flat = raster.reshape(-1)[jnp.clip(i, 0, nx - 1) * ny + jnp.clip(j, 0, ny - 1)]
    return jnp.where(inside, flat, field.void_height if outside is None else outside)


def sample_bilinear(field: Heightfield, xy: jax.Array) -> jax.Array:
    """Terrain height at world points, bilinear between grid points; void outside.

    Bilinear interpolation is exact on planar faces (slopes) away from edges.

    Args:
        field: the heightfield.
        xy: [..., 2] world points.

    Returns:
        [...] heights (m).
    """
    return sample_bilinear_xy(field, xy[..., 0], xy[..., 1])


def sample_bilinear_xy(field: Heightfield, x: jax.Array, y: jax.Array) -> jax.Array:
    """`sample_bilinear` of the world points (x, y), x and y: [...] each -> [...] heights (m)."""
    heights = field.heights
    nx, ny = heights.shape
    u, v = _grid_index(field, x, y)
    inside = (u >= 0) & (u <= nx - 1) & (v >= 0) & (v <= ny - 1)
    i0 = jnp.clip(jnp.floor(u).astype(jnp.int32), 0, nx - 2)
    j0 = jnp.clip(jnp.floor(v).astype(jnp.int32), 0, ny - 2)
    fu = jnp.clip(u - i0, 0.0, 1.0)
    fv = jnp.clip(v - j0, 0.0, 1.0)
    flat = heights.reshape(-1)
    base = i0 * ny + j0
    h00 = flat[base]
    h01 = flat[base + 1]
    h10 = flat[base + ny]
    h11 = flat[base + ny + 1]
    h = h00 * (1 - fu) * (1 - fv) + h10 * fu * (1 - fv) + h01 * (1 - fu) * fv + h11 * fu * fv
    return jnp.where(inside, h, field.void_height)


def disk_filter(heights: np.ndarray, radius_cells: float, reduce: str, cval: float) -> np.ndarray:
    """Max or min of `heights` over a disk around every grid point (host, NumPy).

    A disk is a stack of rows; the 2-D filter is the max (min) over row offsets
    dy of a 1-D filter of half-width floor(sqrt(r^2 - dy^2)) shifted by dy,
    which costs O(r) 1-D passes instead of O(r^2) per point.

    Args:
        heights: [nx, ny] raster.
        radius_cells: disk radius in cells.
        reduce: "max" or "min".
        cval: value outside the raster (the void height).

    Returns:
        [nx, ny] filtered raster.
    """
    filt1d = ndimage.maximum_filter1d if reduce == "max" else ndimage.minimum_filter1d
    combine = np.maximum if reduce == "max" else np.minimum
    r = int(np.floor(radius_cells))
    padded = np.pad(heights, r, mode="constant", constant_values=cval)
    out = None
    for dy in range(-r, r + 1):
        half = int(np.floor(np.sqrt(max(radius_cells**2 - dy**2, 0.0))))
        rows = filt1d(padded, size=2 * half + 1, axis=0, mode="constant", cval=cval)
        shifted = rows[r : -r or None, r + dy : r + dy + heights.shape[1]]
        out = shifted if out is None else combine(out, shifted)
    return out


def _solid(heights: np.ndarray, void_height: float, fill: float) -> np.ndarray:
    """Heights with the void replaced by `fill`: the void is no floor a foot can touch."""
    return np.where(heights > void_height + 1e-6, heights, fill)


def foothold_raster(
    heights: np.ndarray, void_height: float, resolution: float, foothold_radius: float, foothold_search: float
) -> np.ndarray:
    """Flatness of the best sole place near every grid point (host, NumPy).

    spread[p] = max - min of the terrain heights over the disk of radius `foothold_radius`
    around p, +inf when that disk touches the void (or leaves the grid): a sole cannot
    stand over it. The raster is the min of spread over the disk of radius
    `foothold_search` around each point (the foot may land anywhere near its centre).

    Args:
        heights: [nx, ny] terrain heights (m), world grid.
        void_height: height of the void (m).
        resolution: cell size (m).
        foothold_radius: sole disk radius (m).
        foothold_search: search radius (m); below one cell, the point itself only.

    Returns:
        [nx, ny] float32 spreads (m), +inf where no sole disk nearby is over solid terrain.
    """
    solid_or_inf = _solid(heights, void_height, np.inf)
    highest = disk_filter(solid_or_inf, foothold_radius / resolution, "max", np.inf)
    lowest = disk_filter(heights, foothold_radius / resolution, "min", void_height)
    spread = highest - lowest  # inf - finite = inf
    return disk_filter(spread, foothold_search / resolution, "min", np.inf).astype(np.float32)


# The steepest ground a sole holds in static equilibrium: the contact generator's friction
# pyramid (`contacts.robot.equilibrium.friction_generators`: 4 edges inscribed in the mu = 0.5
# cone, oriented along world x and y as hpp-centroidal-dynamics' `Equilibrium` does) carries a
# tangential load up to mu / sqrt(2) of the normal load along x or y, so a plane z = b x + c y
# holds a sole when max(|b|, |c|) <= mu / sqrt(2) (19.5 deg along x or y). On the DARPA-style
# blocks family, terrains whose blocks tilt 19.3 deg or more leave 60-76 % of their poses
# unwalkable and those at 18.8 deg or less 2-20 % (docs/results/2026-12-07-walkability-footing).
# tests/test_footing.py checks it against the generator's pyramid.
FOOTING_SLOPE = 0.5 / math.sqrt(2.0)
FOOTING_SOLE_RADIUS = 0.06  # m, half-side of the square a sole's plane is fitted on
FOOTING_UNEVENNESS = 0.015  # m, largest height spread under that square beyond its plane's own
FOOTING_SHARE_RADIUS = 0.10  # m, the disk a share is taken over (a foot lands anywhere near its place)


def _disk_mean(raster: np.ndarray, radius_cells: float) -> np.ndarray:
    """Mean of `raster` over the disk around every grid point, zero beyond the grid (host)."""
    r = int(np.floor(radius_cells))
    k = np.arange(-r, r + 1)
    disk = (k[:, None] ** 2 + k[None, :] ** 2 <= radius_cells**2).astype(np.float64)
    return ndimage.correlate(raster.astype(np.float64), disk / disk.sum(), mode="constant", cval=0.0)


def footing_rasters(heights: np.ndarray, void_height: float, resolution: float) -> np.ndarray:
    """Where a sole could stand, as shares of the ground around every grid point (host, NumPy).

    A grid point is *footing* when the square of half-side FOOTING_SOLE_RADIUS around it is
    solid ground (no void), the least-squares plane z = b x + c y over it holds a sole in
    static equilibrium (max(|b|, |c|) <= FOOTING_SLOPE) and the heights stray from that plane
    by at most FOOTING_UNEVENNESS (no edge, step or crack under it).

    Args:
        heights: [nx, ny] terrain heights (m), world grid.
        void_height: height of the void (m).
        resolution: cell size (m).

    Returns:
        [2, nx, ny] float32: the share of footing points, and the share of solid points,
        within FOOTING_SHARE_RADIUS of each grid point (zero beyond the grid).
    """
    heights = np.asarray(heights, np.float64)
    solid = heights > void_height + 1e-6
    half = max(int(round(FOOTING_SOLE_RADIUS / resolution)), 1)
    size = 2 * half + 1
    offsets = np.arange(-half, half + 1) * resolution
    level = np.where(solid, heights, 0.0)
    # the plane's slopes are separable filters: sum(offset * h) / sum(offset^2) along one
    # axis, a mean along the other
    along = offsets / np.sum(offsets**2)
    b = ndimage.correlate1d(
        ndimage.uniform_filter1d(level, size, axis=1, mode="nearest"), along, axis=0, mode="nearest"
    )
    c = ndimage.correlate1d(
        ndimage.uniform_filter1d(level, size, axis=0, mode="nearest"), along, axis=1, mode="nearest"
    )
    spread = ndimage.maximum_filter(level, size, mode="nearest") - ndimage.minimum_filter(
        level, size, mode="nearest"
    )
    unevenness = spread - (np.abs(b) + np.abs(c)) * 2 * half * resolution
    square_solid = ndimage.minimum_filter(solid.astype(np.uint8), size, mode="constant", cval=0) > 0
    footing = (
        square_solid
        & (np.maximum(np.abs(b), np.abs(c)) <= FOOTING_SLOPE)
        & (unevenness <= FOOTING_UNEVENNESS)
    )
    radius = FOOTING_SHARE_RADIUS / resolution
    return np.stack([_disk_mean(footing, radius), _disk_mean(solid, radius)]).astype(np.float32)


def _spawn_points(
    heights: np.ndarray,
    trunk_max: np.ndarray,
    void_height: float,
    resolution: float,
    config: EnvConfig,
    spacing: float,
    foothold: np.ndarray | None = None,
) -> np.ndarray:
    """Grid indices [S, 2] where a root at nominal height is valid for every yaw.

    The leg cylinders turn with the yaw around the root, their centres `farthest` m
    from it (the lateral offset; with the lookahead legs, `leg_forward`, the farthest
    leg centre). A point is kept when it is solid ground, the trunk is free, and
      - legs wider than that distance (leg_radius > farthest + one cell): the small
        disk of radius leg_radius - farthest around the point, which lies inside
        every leg disk whatever the yaw, reaches solid ground within the leg band;
      - narrower legs (the calibrated 0.05 m at 0.085 m): every point within
        farthest + leg_radius + one cell, a disk that holds every leg disk whatever
        the yaw, is solid ground within the band.
    With the foothold term, the foothold raster must pass within `farthest` of the
    point (every yaw). With the hands term, the terrain within the hand disks' reach
    (centre distance + radius + one cell) stays below the hands. (Host, NumPy.)
    """
    reach = config.reachability
    stride = max(int(round(spacing / resolution)), 1)
    z = heights + config.nominal_root_height
    farthest = float(np.hypot(reach.leg_forward, reach.leg_lateral_offset))
    ok = (trunk_max < z + reach.trunk_bottom) & (heights > void_height + 1e-6)
    if reach.leg_radius > farthest + resolution:
        inner = (reach.leg_radius - farthest) / resolution
        highest = disk_filter(_solid(heights, void_height, -np.inf), inner, "max", -np.inf)
        lowest = disk_filter(_solid(heights, void_height, np.inf), inner, "min", np.inf)
        ok &= (highest >= z + reach.leg_bottom) & (lowest <= z + reach.leg_top)
    else:
        # + one cell: the condition reads each leg at the grid point nearest to its centre
        outer = (farthest + reach.leg_radius + resolution) / resolution
        lowest = disk_filter(_solid(heights, void_height, -np.inf), outer, "min", -np.inf)
        highest = disk_filter(heights, outer, "max", np.inf)
        ok &= (lowest >= z + reach.leg_bottom) & (highest <= z + reach.leg_top)
    if foothold is not None:
        ok &= disk_filter(foothold, farthest / resolution, "max", np.inf) <= reach.foothold_spread
    if reach.hand_radius is not None:
        hands = (
            float(np.hypot(reach.hand_forward, reach.hand_lateral)) + reach.hand_radius + resolution
        ) / resolution
        ok &= disk_filter(heights, hands, "max", void_height) < z + reach.hand_bottom
    # keep away from the grid border so that jittered resets stay inside
    ok[:stride, :] = ok[-stride:, :] = False
    ok[:, :stride] = ok[:, -stride:] = False
    sub = np.zeros_like(ok)
    sub[::stride, ::stride] = True
    return np.argwhere(ok & sub)


def heightfield_from_raster(
    heights: np.ndarray,
    origin,
    resolution: float,
    void_height: float,
    config: EnvConfig = EnvConfig(),
    spawn_spacing: float = 0.10,
    require_spawn: bool = True,
) -> Heightfield:
    """Build the JAX heightfield and its reachability rasters (host only, not jittable).

    Args:
        heights: [nx, ny] terrain heights, heights[i, j] at origin + (i, j) * resolution.
        origin: (x0, y0) world.
        resolution: cell size (m).
        void_height: height outside the grid (m).
        config: environment configuration (cylinder radii, nominal root height).
        spawn_spacing: spacing of reset candidates (m).
        require_spawn: raise ValueError when no point is valid for a reset; with
            False the field then has no spawn points (for fields used only for sampling
            and for rollouts from given starts).
    """
    heights = np.asarray(heights, dtype=np.float32)
    reach: ReachabilityConfig = config.reachability
    trunk_max = disk_filter(heights, reach.trunk_radius / resolution, "max", void_height)
    # legs touch solid terrain only: the void is ignored (-inf for the max, +inf for the min),
    # so a disk over the void alone never touches, whatever the root height
    leg_max = disk_filter(
        _solid(heights, void_height, -np.inf), reach.leg_radius / resolution, "max", -np.inf
    )
    leg_min = disk_filter(_solid(heights, void_height, np.inf), reach.leg_radius / resolution, "min", np.inf)
    if reach.foothold_spread is None:
        foothold = None
    else:
        foothold = foothold_raster(
            heights, void_height, resolution, reach.foothold_radius, reach.foothold_search
        )
    hand_max = (
        None
        if reach.hand_radius is None
        else disk_filter(heights, reach.hand_radius / resolution, "max", void_height)
    )
    spawn_ij = _spawn_points(heights, trunk_max, void_height, resolution, config, spawn_spacing, foothold)
    if len(spawn_ij) == 0 and require_spawn:
        raise ValueError("the terrain has no valid spawn position for the root at nominal height")
    spawn_xy = np.asarray(origin, dtype=np.float32) + spawn_ij.astype(np.float32) * resolution
    f32 = lambda a: jnp.asarray(a, dtype=jnp.float32)  # noqa: E731
    return Heightfield(
        heights=f32(heights),
        trunk_max=f32(trunk_max),
        leg_max=f32(leg_max),
        leg_min=f32(leg_min),
        foothold=f32(np.zeros((1, 1)) if foothold is None else foothold),
        hand_max=f32(np.zeros((1, 1)) if hand_max is None else hand_max),
        footing=f32(footing_rasters(heights, void_height, resolution)),
        origin=f32(origin),
        resolution=f32(resolution),
        void_height=f32(void_height),
        spawn_xy=f32(spawn_xy),
        spawn_yaw=f32(np.full(len(spawn_xy), np.nan)),
        spawn_spacing=f32(spawn_spacing),
        condition=condition_params(config),
    )


def heightfield_from_terrain(
    terrain, config: EnvConfig = EnvConfig(), spawn_spacing: float = 0.10, require_spawn: bool = False
) -> Heightfield:
    """Heightfield of a `leas_jax.terrain.Terrain` (host only, not jittable).

    Only random resets (training, `LeasEnv.reset`) start at spawn points; rollouts, the
    navigate search and the evaluations start where they are told. So by default a terrain
    with no spawn point (too small for a root valid at every yaw) gives a field without
    any, and `require_spawn` (the training arena, `feasibility.spawns.arena_field`) turns
    that into a TerrainError naming the terrain file.
    """
    field = heightfield_from_raster(
        terrain.raster(),
        terrain.bounds[0],
        terrain.resolution,
        terrain.void_height,
        config,
        spawn_spacing,
        require_spawn=False,
    )
    if require_spawn and field.spawn_xy.shape[0] == 0:
        raise TerrainError(
            f"{terrain.path or terrain.name}: no spawn position, a point where a root at nominal height "
            "is valid for every yaw, for training episodes to start at (the terrain is too small or too rough)"
        )
    if terrain.curriculum is not None and field.spawn_xy.shape[0] > 0:
        field = with_curriculum(field, terrain.curriculum, terrain.path or terrain.name)
    return field
