"""Parity of the terrain heights with MuJoCo's own ray casting on the exported MJCF.

For every committed terrain: 10 000 random points away from box edges; vertical rays
from above with `mujoco.mj_ray` and with `mujoco.mjx.ray` (jitted, vmapped over the
points) against the raster sampled by bilinear interpolation and `Terrain.height_at`,
within 1 mm. A ray that hits nothing is void.
"""

from pathlib import Path

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
import pytest

from leas_jax.terrain import Terrain, load_terrain
from leas_jax.terrain.export import terrain_to_mjcf

TERRAINS = Path(__file__).resolve().parents[1] / "terrains"
NAMES = sorted(p.stem for p in TERRAINS.glob("*.toml"))
N_POINTS = 10_000
TOLERANCE = 1e-3  # m
EDGE_CELLS = 2  # skip points within this many raster cells of a box edge's projection


def bilinear(heights: np.ndarray, origin, resolution: float, xy: np.ndarray) -> np.ndarray:
    """Bilinear interpolation of a raster.

    Args:
        heights: [nx, ny], heights[i, j] at origin + (i, j) * resolution.
        origin: [2] world position of heights[0, 0].
        resolution: m.
        xy: [N, 2] world points inside the raster.

    Returns:
        [N] interpolated heights.
    """
    nx, ny = heights.shape
    grid = (np.asarray(xy, dtype=np.float64) - origin) / resolution
    i0 = np.clip(np.floor(grid[:, 0]).astype(int), 0, nx - 2)
    j0 = np.clip(np.floor(grid[:, 1]).astype(int), 0, ny - 2)
    fx, fy = grid[:, 0] - i0, grid[:, 1] - j0
    h = heights.astype(np.float64)
    return (
        (1 - fx) * (1 - fy) * h[i0, j0]
        + fx * (1 - fy) * h[i0 + 1, j0]
        + (1 - fx) * fy * h[i0, j0 + 1]
        + fx * fy * h[i0 + 1, j0 + 1]
    )


def test_bilinear_is_exact_on_a_plane():
    # h = 1 + 2x - 3y sampled at 0.5 m; bilinear reproduces a plane exactly
    xs, ys = np.meshgrid(np.arange(5) * 0.5, np.arange(4) * 0.5, indexing="ij")
    heights = 1 + 2 * xs - 3 * ys
    xy = np.array([[0.3, 0.2], [1.9, 1.4], [2.0, 1.5]])
    np.testing.assert_allclose(bilinear(heights, (0.0, 0.0), 0.5, xy), 1 + 2 * xy[:, 0] - 3 * xy[:, 1])


def _segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """[N] distance from points [N, 2] to the segment a-b ([2] each)."""
    ab = b - a
    length2 = float(ab @ ab)
    t = np.zeros(len(points)) if length2 == 0.0 else np.clip((points - a) @ ab / length2, 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


# the 12 edges of a box as pairs of Box.vertices() indices (corners differ in one bit)
_EDGES = [(k, k | bit) for k in range(8) for bit in (1, 2, 4) if not k & bit]


def away_from_edges(terrain: Terrain, xy: np.ndarray, margin: float) -> np.ndarray:
    """[N] bool: points farther than `margin` from the vertical projection of every box edge.

    Heights jump or kink only above projected box edges, so the raster is bilinear-exact
    (a plane per cell) away from them.
    """
    keep = np.ones(len(xy), dtype=bool)
    for box in terrain.boxes:
        lo, hi = box.aabb()[:, :2]
        near = np.all((xy >= lo - margin) & (xy <= hi + margin), axis=1)
        if not np.any(near):
            continue
        corners = box.vertices()[:, :2]
        candidates = xy[near]
        distance = np.min([_segment_distance(candidates, corners[a], corners[b]) for a, b in _EDGES], axis=0)
        keep[np.flatnonzero(near)[distance <= margin]] = False
    return keep


def sample_points(terrain: Terrain, seed: int = 0) -> np.ndarray:
    """[N_POINTS, 2] uniform points of the terrain bounds away from box edges."""
    rng = np.random.default_rng(seed)
    margin = EDGE_CELLS * terrain.resolution
    lo, hi = terrain.bounds
    points = np.empty((0, 2))
    while len(points) < N_POINTS:
        draw = rng.uniform(lo + margin, hi - margin, size=(2 * N_POINTS, 2))
        points = np.concatenate([points, draw[away_from_edges(terrain, draw, margin)]])
    return points[:N_POINTS]


def mujoco_scene(terrain: Terrain):
    model = mujoco.MjModel.from_xml_string(terrain_to_mjcf(terrain))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def ray_start_height(terrain: Terrain) -> float:
    """A height above every box, m."""
    return max(float(box.aabb()[1, 2]) for box in terrain.boxes) + 1.0


@pytest.fixture(scope="module", params=NAMES)
def case(request):
    terrain = load_terrain(TERRAINS / f"{request.param}.toml")
    xy = sample_points(terrain)
    reference = terrain.height_at(xy)
    return terrain, xy, reference


def test_raster_bilinear_matches_height_at(case):
    terrain, xy, reference = case
    interpolated = bilinear(terrain.raster(), terrain.origin, terrain.resolution, xy)
    np.testing.assert_allclose(interpolated, reference, atol=TOLERANCE, rtol=0)


def test_mj_ray_matches(case):
    terrain, xy, reference = case
    model, data = mujoco_scene(terrain)
    z0 = ray_start_height(terrain)
    down = np.array([0.0, 0.0, -1.0])
    geom = np.zeros(1, dtype=np.int32)
    heights = np.empty(len(xy))
    for k, (x, y) in enumerate(xy):
        distance = mujoco.mj_ray(model, data, np.array([x, y, z0]), down, None, 1, -1, geom)
        heights[k] = z0 - distance if distance >= 0 else terrain.void_height
    np.testing.assert_allclose(heights, reference, atol=TOLERANCE, rtol=0)
    raster = bilinear(terrain.raster(), terrain.origin, terrain.resolution, xy)
    np.testing.assert_allclose(heights, raster, atol=TOLERANCE, rtol=0)
    # the sample covers the terrain's features, not only flat ground
    if terrain.name.startswith("training_arena"):
        assert np.mean(heights == terrain.void_height) > 0.02 and np.mean(heights > 0.05) > 0.05


def test_mjx_ray_matches(case):
    from mujoco import mjx

    terrain, xy, reference = case
    model, data = mujoco_scene(terrain)
    z0 = ray_start_height(terrain)
    mx, dx = mjx.put_model(model), mjx.put_data(model, data)
    down = jnp.array([0.0, 0.0, -1.0])
    cast = jax.jit(jax.vmap(lambda p: mjx.ray(mx, dx, p, down)))
    points = np.concatenate([xy, np.full((len(xy), 1), z0)], axis=1)
    distance, _ = cast(jnp.asarray(points, dtype=jnp.float32))
    distance = np.asarray(distance, dtype=np.float64)
    heights = np.where(distance >= 0, z0 - distance, terrain.void_height)
    np.testing.assert_allclose(heights, reference, atol=TOLERANCE, rtol=0)
    raster = bilinear(terrain.raster(), terrain.origin, terrain.resolution, xy)
    np.testing.assert_allclose(heights, raster, atol=TOLERANCE, rtol=0)
