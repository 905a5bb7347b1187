"""The mesh ray cast (`MeshIndex.raster`, `MeshIndex.column_top`) stays within the heights of
what it hits: every multicontact scene of hpp-environments, rasterised alone, and fuzzed
triangles (vertical, nearly vertical, needles, repeated corners, float32 corners as STL
stores them). A vertical line within EDGE_TOL of a triangle seen nearly edge-on from above
once got heights far outside the triangle (36.6 m on a 0.19 m high scene)."""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

import numpy as np
import pytest

from leas_jax.terrain import TerrainError, loads_terrain
from leas_jax.terrain.mesh import MeshIndex, TerrainMesh
from leas_jax.terrain.model import raster_shape
from leas_jax.terrain.sources import PACKAGE_FOLDERS

RES = 0.02
TOL = 1e-9  # m: rounding of the weighted mean of the corner heights
MULTICONTACT = (
    Path(importlib.metadata.distribution("hpp-environments").locate_file(PACKAGE_FOLDERS["hpp-environments"]))
    / "multicontact"
)
SCENES = sorted(p.name for p in MULTICONTACT.glob("*.stl"))
# The scenes whose rasters held heights above their highest vertex.
GRAZED = (
    "box.stl",
    "box_rom.stl",
    "ground_table.stl",
    "ground_table2.stl",
    "ground_tablec.stl",
    "plateforme_surfaces.stl",
    "plateforme_surfaces_scale.stl",
    "plateformes_full.stl",
    "robot_box.stl",
)


def _scene(name: str) -> TerrainMesh:
    """The scene's mesh, world frame as stored; skips a scene the installed package lacks."""
    text = (
        'name = "scene"\nbounds = [[0.0, 0.0], [1.0, 1.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
        f'[[mesh]]\nfile = "hpp-environments:multicontact/{name}"\n'
    )
    try:
        return loads_terrain(text).meshes[0]
    except TerrainError as exc:
        pytest.skip(f"{name}: {exc}")


def _raster_alone(mesh: TerrainMesh) -> np.ndarray:
    """Raster of the mesh alone over its own xy bounds, RES apart, -inf where nothing is hit."""
    bounds = mesh.aabb()[:, :2]
    return MeshIndex([mesh]).raster(bounds, RES, raster_shape(bounds, RES))


def _within(heights: np.ndarray, low: float, high: float) -> np.ndarray:
    """The hit heights (finite) outside [low, high], beyond rounding."""
    hit = heights[np.isfinite(heights)]
    return hit[(hit > high + TOL) | (hit < low - TOL)]


def test_the_scenes_are_found():
    assert len(SCENES) > 90 and set(GRAZED) <= set(SCENES)


@pytest.mark.parametrize("name", SCENES)
def test_scene_rasters_stay_within_the_mesh_heights(name):
    mesh = _scene(name)
    (_, _, low), (_, _, high) = mesh.aabb()
    heights = _raster_alone(mesh)
    assert np.isfinite(heights).any()
    assert _within(heights, low, high).size == 0, (name, _within(heights, low, high).max())


@pytest.mark.parametrize("name", GRAZED)
def test_grazed_scene_heights_stay_within_the_mesh_heights_on_its_terrain_raster(name):
    """The terrain's own raster and ray cast (bounds beyond the mesh, float32 raster)."""
    mesh = _scene(name)
    (x0, y0, low), (x1, y1, high) = mesh.aabb()
    text = (
        f'name = "scene"\nbounds = [[{x0 - 0.3:.2f}, {y0 - 0.3:.2f}], [{x1 + 0.3:.2f}, {y1 + 0.3:.2f}]]\n'
        f'void_height = -2.0\nresolution = {RES}\n[[mesh]]\nfile = "hpp-environments:multicontact/{name}"\n'
    )
    terrain = loads_terrain(text)
    raster = terrain.raster()
    solid = raster[raster > terrain.void_height]
    assert solid.size and solid.max() <= np.float32(high) and solid.min() >= np.float32(low)
    i, j = np.meshgrid(*(np.arange(n) for n in terrain.shape), indexing="ij")
    xy = terrain.origin + np.stack([i, j], axis=-1).reshape(-1, 2) * RES
    heights = terrain.height_at(xy)
    assert _within(np.where(heights > terrain.void_height, heights, np.nan), low, high).size == 0


def test_the_plateformes_cell_that_read_36_m():
    mesh = _scene("plateforme_surfaces_scale.stl")
    top = MeshIndex([mesh]).column_top(np.array([[0.92, 0.50]]))[0]
    assert top <= mesh.aabb()[1, 2] + TOL


def _fuzzed_triangles(rng: np.random.Generator, count: int) -> np.ndarray:
    """[count, 3, 3] triangles in [0, 0.4]^2 x [-1, 1], float32 corners, of five kinds in
    turn: any, vertical on a raster line (two corners on raster points, the third on their
    line), nearly vertical (the third corner 1e-9 to 1e-6 m off the line), needles (one
    corner 1e-7 to 1e-4 m from another) and repeated corners."""
    corners = rng.uniform([0.0, 0.0, -1.0], [0.4, 0.4, 1.0], (count, 3, 3))
    kind = np.arange(count) % 5
    on_grid = np.round(corners[:, :2, :2] / RES) * RES
    along = rng.uniform(-0.5, 1.5, (count, 1))
    line = on_grid[:, 0] + along * (on_grid[:, 1] - on_grid[:, 0])
    direction = on_grid[:, 1] - on_grid[:, 0]
    normal = np.stack([-direction[:, 1], direction[:, 0]], axis=1)
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    offset = 10.0 ** rng.uniform(-9, -6, (count, 1)) * normal
    needle = corners[:, 0, :] + 10.0 ** rng.uniform(-7, -4, (count, 1)) * rng.normal(size=(count, 3))
    vertical = kind == 1
    near = kind == 2
    corners[vertical | near, :2, :2] = on_grid[vertical | near]
    corners[vertical, 2, :2] = line[vertical]
    corners[near, 2, :2] = line[near] + offset[near]
    corners[kind == 3, 2] = needle[kind == 3]
    corners[kind == 4, 1] = corners[kind == 4, 0]
    return corners.astype(np.float32).astype(np.float64)


def _single(triangle: np.ndarray) -> MeshIndex:
    return MeshIndex([TerrainMesh("mesh[0]", triangle, [[0, 1, 2]], "", "fuzz")])


def test_fuzzed_triangles_are_hit_within_their_corner_heights():
    rng = np.random.default_rng(20261206)
    bounds = np.array([[0.0, 0.0], [0.4, 0.4]])
    shape = raster_shape(bounds, RES)
    grazed = 0
    for triangle in _fuzzed_triangles(rng, 600):
        index = _single(triangle)
        low, high = triangle[:, 2].min(), triangle[:, 2].max()
        raster = index.raster(bounds, RES, shape)
        # lines through the corners and through points of the edges, 1e-6 m off
        t = rng.uniform(0.0, 1.0, (32, 1))
        edges = triangle[:, :2] + t[:, None] * (np.roll(triangle[:, :2], -1, axis=0) - triangle[:, :2])
        points = np.concatenate([triangle[:, :2], edges.reshape(-1, 2)])
        points = points + rng.normal(scale=1e-6, size=points.shape)
        column = index.column_top(points)
        assert _within(raster, low, high).size == 0, triangle
        assert _within(column, low, high).size == 0, triangle
        grazed += len(index) > 0 and np.isfinite(raster).any() and high - low > 0.1
    assert grazed > 100  # the fuzz reaches the triangles the ray cast keeps


def test_raster_heights_inside_triangles_are_their_planes():
    """Points well inside a triangle with an area seen from above: the plane's height
    (barycentric coordinates solved independently)."""
    rng = np.random.default_rng(7)
    bounds = np.array([[0.0, 0.0], [0.4, 0.4]])
    shape = raster_shape(bounds, RES)
    i, j = np.meshgrid(*(np.arange(n) for n in shape), indexing="ij")
    xy = bounds[0] + np.stack([i, j], axis=-1).reshape(-1, 2) * RES
    checked = 0
    for triangle in _fuzzed_triangles(rng, 200)[::5]:  # the kind "any"
        a, b, c = triangle
        matrix = np.array([[b[0] - a[0], c[0] - a[0]], [b[1] - a[1], c[1] - a[1]]])
        if abs(np.linalg.det(matrix)) < 1e-4:
            continue
        s, u = np.linalg.solve(matrix, (xy - a[:2]).T)
        inside = (s > 1e-6) & (u > 1e-6) & (s + u < 1.0 - 1e-6)
        expected = a[2] + s * (b[2] - a[2]) + u * (c[2] - a[2])
        raster = _single(triangle).raster(bounds, RES, shape).reshape(-1)
        np.testing.assert_allclose(raster[inside], expected[inside], atol=1e-9)
        checked += int(inside.sum())
    assert checked > 1000
