"""Terrain data model: boxes and meshes over a void, their heightfield and support surfaces.

Host code (NumPy); nothing here can be jitted. The file format is docs/design.md §4 (terrain
format v1; v2 adds meshes and an elevation map, `leas_jax.terrain.sources`, whose geometry
is `leas_jax.terrain.mesh`); the interface is docs/architecture.md; `leas_jax.terrain.export`
writes a terrain as MJCF or a mesh. All coordinates are world frame, metres, z up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from leas_jax.errors import TerrainError
from leas_jax.terrain.mesh import MeshIndex, support_polygons

# Boxes are closed sets: a raster point exactly on a box edge belongs to it. Grid
# coordinates xmin + i*res carry rounding errors of ~1e-15 m, so the slab test
# accepts points 1e-7 m outside a face; far below the raster resolution.
_EDGE_TOL = 1e-7  # m
# Number of raster points evaluated at once per box (bounds the temporary arrays
# to a few tens of MB whatever the box size).
_CHUNK_POINTS = 1 << 20
# A face is buried if every probe point, this far above it along its normal, lies inside
# another box: a step covering the whole ground face. The probes are a grid of
# _BURIED_GRID x _BURIED_GRID points from 5 % to 95 % of the face's sides, so a pillar
# standing on the middle of a slab no longer hides the whole slab (the generator's
# `surfaces.uncovered` check keeps soles off the covered part of a face it keeps).
_BURIED_PROBE = 1e-3  # m
_BURIED_GRID = 5


def _frozen_array(value, shape: tuple[int, ...]) -> np.ndarray:
    """Copy `value` to a read-only float64 array of the given shape."""
    array = np.array(value, dtype=np.float64).reshape(shape)
    array.setflags(write=False)
    return array


def rotation_from_rpy(rpy) -> np.ndarray:
    """Rotation matrix of roll, pitch, yaw (rad) in the z-y-x convention.

    Args:
        rpy: [3] (roll, pitch, yaw), rad.

    Returns:
        [3, 3] world_R_box = Rz(yaw) @ Ry(pitch) @ Rx(roll).
    """
    roll, pitch, yaw = (float(a) for a in rpy)
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    return rz @ ry @ rx


def quaternion_wxyz_from_rpy(rpy) -> np.ndarray:
    """Unit quaternion (w, x, y, z), MuJoCo order, of the rotation `rotation_from_rpy(rpy)`.

    Args:
        rpy: [3] (roll, pitch, yaw), rad.

    Returns:
        [4] (w, x, y, z) with w >= 0.
    """
    roll, pitch, yaw = (0.5 * float(a) for a in rpy)
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    # q = qz(yaw) * qy(pitch) * qx(roll), expanded.
    q = np.array(
        [
            cy * cp * cr + sy * sp * sr,
            cy * cp * sr - sy * sp * cr,
            cy * sp * cr + sy * cp * sr,
            sy * cp * cr - cy * sp * sr,
        ]
    )
    return q if q[0] >= 0.0 else -q


@dataclass(frozen=True, eq=False)
class Box:
    """An oriented box of the terrain.

    Attributes:
        center: [3] centre, world frame, m.
        size: [3] full extents along the box axes, m (all > 0).
        rpy: [3] roll, pitch, yaw of the box axes, rad (world_R_box = Rz Ry Rx).
    """

    center: np.ndarray
    size: np.ndarray
    rpy: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self):
        object.__setattr__(self, "center", _frozen_array(self.center, (3,)))
        object.__setattr__(self, "size", _frozen_array(self.size, (3,)))
        object.__setattr__(self, "rpy", _frozen_array(self.rpy, (3,)))

    def __eq__(self, other):
        if not isinstance(other, Box):
            return NotImplemented
        return (
            np.array_equal(self.center, other.center)
            and np.array_equal(self.size, other.size)
            and np.array_equal(self.rpy, other.rpy)
        )

    def __hash__(self):
        return hash((self.center.tobytes(), self.size.tobytes(), self.rpy.tobytes()))

    @property
    def half(self) -> np.ndarray:
        """[3] half extents along the box axes, m."""
        return 0.5 * self.size

    @property
    def rotation(self) -> np.ndarray:
        """[3, 3] world_R_box = Rz(yaw) @ Ry(pitch) @ Rx(roll); columns are the box axes in world."""
        return rotation_from_rpy(self.rpy)

    @property
    def quaternion_wxyz(self) -> np.ndarray:
        """[4] orientation as a (w, x, y, z) quaternion (MuJoCo order)."""
        return quaternion_wxyz_from_rpy(self.rpy)

    def vertices(self) -> np.ndarray:
        """[8, 3] corners, world frame; corner k has signs (+/-) of bits (k>>2, k>>1, k) on x, y, z."""
        signs = np.array([[1 - 2 * ((k >> b) & 1) for b in (2, 1, 0)] for k in range(8)], dtype=np.float64)
        return self.center + (signs * self.half) @ self.rotation.T

    def aabb(self) -> np.ndarray:
        """[2, 3] axis-aligned bounds (min row, max row), world frame."""
        extent = np.abs(self.rotation) @ self.half
        return np.stack([self.center - extent, self.center + extent])

    def contains(self, points: np.ndarray, tol: float = 0.0) -> np.ndarray:
        """Whether points lie inside the box grown by `tol`.

        Args:
            points: [N, 3] world frame.
            tol: margin added to every half extent, m.

        Returns:
            [N] bool.
        """
        local = (np.asarray(points, dtype=np.float64) - self.center) @ self.rotation
        return np.all(np.abs(local) <= self.half + tol, axis=-1)

    def column_top(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Highest point of the box on vertical lines, by slab intersection.

        The vertical line through (x, y) is p(z) = (x, y, z). In the box frame it is
        o + z d with o = R^T ((x, y, 0) - c) and d = R^T e_z (the third row of R). It
        meets the box where |o_k + z d_k| <= h_k for the three axes k: each axis with
        d_k != 0 bounds z to [(-h_k - o_k)/d_k, (h_k - o_k)/d_k] (sorted); an axis with
        d_k = 0 (a vertical face) either holds for every z or for none.

        Args:
            x: [...] world x, m.
            y: [...] same shape, world y, m.

        Returns:
            [...] top z of the intersection, -inf where the line misses the box.
        """
        rot = self.rotation
        dx = np.asarray(x, dtype=np.float64) - self.center[0]
        dy = np.asarray(y, dtype=np.float64) - self.center[1]
        # The hit test uses the box grown by _EDGE_TOL (closed set, robust to rounding);
        # the returned height uses the true box so that it is exact.
        lower = np.full(dx.shape, -np.inf)
        upper = np.full(dx.shape, np.inf)
        top = np.full(dx.shape, np.inf)
        for k in range(3):
            d_k = rot[2, k]
            o_k = rot[0, k] * dx + rot[1, k] * dy - rot[2, k] * self.center[2]
            if abs(d_k) < 1e-12:
                upper = np.where(np.abs(o_k) > self.half[k] + _EDGE_TOL, -np.inf, upper)
                continue
            a = (-self.half[k] - _EDGE_TOL - o_k) / d_k
            b = (self.half[k] + _EDGE_TOL - o_k) / d_k
            lower = np.maximum(lower, np.minimum(a, b))
            upper = np.minimum(upper, np.maximum(a, b))
            top = np.minimum(top, (np.sign(d_k) * self.half[k] - o_k) / d_k)
        return np.where(lower <= upper, top, -np.inf)


@dataclass(frozen=True, eq=False)
class Scenario:
    """Evaluation scenario of a terrain (docs/design.md §4 `[scenario]`).

    Attributes:
        target: [2] goal (x, y), world frame, m; z comes from the terrain.
        start_region: [2, 2] [[xmin, ymin], [xmax, ymax]] of the start positions, m.
        start_yaw_deg: [2] range of the initial yaw relative to the direction to the
            target (or to the first waypoint), deg.
        start_speed: [2] range of the initial speed along the heading, m/s.
        n_starts: number of start configurations to draw.
        seed: seed of the start draw.
        waypoints: [W, 2] points to follow in order before the target, or None.
    """

    target: np.ndarray
    start_region: np.ndarray
    start_yaw_deg: np.ndarray
    start_speed: np.ndarray
    n_starts: int
    seed: int
    waypoints: np.ndarray | None = None

    def __post_init__(self):
        object.__setattr__(self, "target", _frozen_array(self.target, (2,)))
        object.__setattr__(self, "start_region", _frozen_array(self.start_region, (2, 2)))
        object.__setattr__(self, "start_yaw_deg", _frozen_array(self.start_yaw_deg, (2,)))
        object.__setattr__(self, "start_speed", _frozen_array(self.start_speed, (2,)))
        if self.waypoints is not None:
            object.__setattr__(self, "waypoints", _frozen_array(self.waypoints, (-1, 2)))


@dataclass(frozen=True)
class Curriculum:
    """Layout of a curriculum arena (`[curriculum]`): tiles in rows of difficulty along x and
    columns of terrain families along y, from the terrain's lower bounds corner.

    Attributes:
        levels: number of rows; row k (x in [x0 + k * tile[0], x0 + (k + 1) * tile[0]]) is
            difficulty k / (levels - 1).
        tile: (length along x, width along y) of a tile, m.
        families: the family of each column, in order along y.
    """

    levels: int
    tile: tuple[float, float]
    families: tuple[str, ...]


@dataclass(frozen=True, eq=False)
class SupportSurface:
    """A convex planar face where a foot may rest.

    Attributes:
        vertices: [N, 3] polygon, world frame, counter-clockwise seen along -normal
            (i.e. looking at the face from outside, from above).
        normal: [3] outward unit normal, world frame.
        box_index: index of the box in `Terrain.boxes` the face belongs to, -1 for a mesh's.
        mesh_index: index of the mesh in `Terrain.meshes` the polygon is cut from, -1 for a box's.
    """

    vertices: np.ndarray
    normal: np.ndarray
    box_index: int
    mesh_index: int = -1

    @property
    def origin(self) -> str:
        """'box k' or 'mesh k', for messages."""
        return f"box {self.box_index}" if self.mesh_index < 0 else f"mesh {self.mesh_index}"

    def __post_init__(self):
        object.__setattr__(self, "vertices", _frozen_array(self.vertices, (-1, 3)))
        object.__setattr__(self, "normal", _frozen_array(self.normal, (3,)))


def _face_probes(corners: np.ndarray) -> np.ndarray:
    """[_BURIED_GRID ** 2, 3] points of a rectangular face with corners [4, 3] (`face_polygon`'s
    order), from 5 % to 95 % of its sides."""
    s, t = np.meshgrid(*(np.linspace(0.05, 0.95, _BURIED_GRID),) * 2, indexing="ij")
    s, t = s.reshape(-1, 1), t.reshape(-1, 1)
    return corners[2] + s * (corners[3] - corners[2]) + t * (corners[1] - corners[2])


def face_polygon(box: Box, axis: int, sign: int) -> tuple[np.ndarray, np.ndarray]:
    """Corners and outward normal of one face of a box.

    Args:
        box: the box.
        axis: 0, 1 or 2, the box axis the face is normal to.
        sign: +1 or -1, which of the two faces.

    Returns:
        ([4, 3] corners, world frame, counter-clockwise about the normal;
         [3] outward unit normal, world frame).
    """
    rot = box.rotation
    normal = sign * rot[:, axis]
    # Tangent axes u, v with u x v = normal: then (+,+), (-,+), (-,-), (+,-) in (u, v)
    # turns counter-clockwise seen from the tip of the normal.
    i, j = (axis + 1) % 3, (axis + 2) % 3
    u, v = rot[:, i], sign * rot[:, j]
    hu, hv = box.half[i], box.half[j]
    centre = box.center + normal * box.half[axis]
    corners = np.array(
        [centre + su * hu * u + sv * hv * v for su, sv in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    )
    return corners, normal


@dataclass(frozen=True, eq=False)
class Terrain:
    """A terrain: a union of boxes and triangle meshes over a void (docs/design.md §4).

    Attributes:
        name: terrain name.
        bounds: [2, 2] [[xmin, ymin], [xmax, ymax]] of the heightfield, world frame, m.
        void_height: height where no box or mesh covers a point, m.
        resolution: heightfield cell size, m.
        boxes: the boxes.
        scenario: the evaluation scenario, or None (training terrains).
        text: TOML source of the terrain (with its `[resolved]` table for v2 sources).
        path: file the terrain was read from, or None.
        meshes: the `[[mesh]]` entries then the `[elevation]` map, as TerrainMesh (world frame).
        curriculum: the layout of a curriculum arena's difficulty rows, or None.
    """

    name: str
    bounds: np.ndarray
    void_height: float
    resolution: float
    boxes: tuple[Box, ...]
    scenario: Scenario | None = None
    text: str = ""
    path: str | None = None
    meshes: tuple = ()
    curriculum: Curriculum | None = None
    _cache: dict = field(default_factory=dict, init=False, repr=False)

    def __post_init__(self):
        object.__setattr__(self, "bounds", _frozen_array(self.bounds, (2, 2)))
        object.__setattr__(self, "boxes", tuple(self.boxes))
        object.__setattr__(self, "meshes", tuple(self.meshes))
        object.__setattr__(self, "void_height", float(self.void_height))
        object.__setattr__(self, "resolution", float(self.resolution))

    @property
    def shape(self) -> tuple[int, int]:
        """(nx, ny) raster points: (round((xmax - xmin)/res) + 1, round((ymax - ymin)/res) + 1)."""
        return raster_shape(self.bounds, self.resolution)

    @property
    def origin(self) -> np.ndarray:
        """[2] (xmin, ymin), world position of raster point [0, 0], m."""
        return self.bounds[0].copy()

    def grid_axes(self) -> tuple[np.ndarray, np.ndarray]:
        """Raster coordinates: ([nx] x = xmin + i*res, [ny] y = ymin + j*res), world, m."""
        nx, ny = self.shape
        return (
            self.bounds[0, 0] + np.arange(nx) * self.resolution,
            self.bounds[0, 1] + np.arange(ny) * self.resolution,
        )

    def raster(self) -> np.ndarray:
        """Heightfield of the terrain (cached, read-only).

        Returns:
            [nx, ny] float32: heights[i, j] is the highest point of the union of boxes
            and meshes on the vertical line through (xmin + i*res, ymin + j*res),
            void_height where nothing meets that line.
        """
        if "raster" not in self._cache:
            heights = rasterize(self.boxes, self.bounds, self.resolution, self.void_height, self.mesh_index())
            heights.setflags(write=False)
            self._cache["raster"] = heights
        return self._cache["raster"]

    def mesh_index(self) -> MeshIndex:
        """The triangles of all meshes, for vertical ray casts (cached)."""
        if "mesh_index" not in self._cache:
            self._cache["mesh_index"] = MeshIndex(self.meshes)
        return self._cache["mesh_index"]

    def height_at(self, xy) -> np.ndarray:
        """Exact terrain heights by vertical ray cast on the boxes and the meshes' triangles.

        Args:
            xy: [..., 2] world positions, m (e.g. [N, 2] or [2]).

        Returns:
            [...] float64 heights, void_height where nothing is hit.

        Raises:
            TerrainError: xy not of shape [..., 2] or not finite.
        """
        points = np.asarray(xy, dtype=np.float64)
        if points.shape[-1:] != (2,):
            raise TerrainError(f"height_at: xy of shape {points.shape}: the last axis must hold (x, y)")
        flat = points.reshape(-1, 2)
        if not np.all(np.isfinite(flat)):
            raise TerrainError("height_at: xy holds nan or inf")
        top = np.full(len(flat), -np.inf)
        tiles = _PointTiles(flat)
        for box in self.boxes:
            lo, hi = box.aabb()[:, :2]
            candidates = tiles.within(lo - _EDGE_TOL, hi + _EDGE_TOL)
            if len(candidates):
                sel = flat[candidates]
                top[candidates] = np.maximum(top[candidates], box.column_top(sel[:, 0], sel[:, 1]))
        if self.meshes:
            top = np.maximum(top, self.mesh_index().column_top(flat))
        heights = np.where(np.isfinite(top), top, self.void_height)
        return heights.reshape(points.shape[:-1])

    def support_surfaces(self, mu: float = 0.5) -> list[SupportSurface]:
        """Faces a foot may rest on: outward normal within the friction cone.

        A box face qualifies when the angle between its outward normal and +z is at most
        atan(mu). Faces covered by other boxes (a 5 x 5 grid of points 1 mm above the
        face, `_face_probes`, all inside them) are left out; partly covered faces are
        returned whole.
        Meshes give convex polygons of adjacent coplanar triangles within the cone
        (`leas_jax.terrain.mesh.support_polygons`).

        Args:
            mu: friction coefficient (> 0).

        Returns:
            list of SupportSurface, the boxes' in box order, then the meshes'.
        """
        if not mu > 0.0:
            raise TerrainError(f"support_surfaces: mu = {mu!r}: must be > 0")
        min_nz = math.cos(math.atan(mu))
        meshes = [
            SupportSurface(p.vertices, p.normal, -1, p.mesh_index)
            for p in support_polygons(self.meshes, mu, self.height_at)
        ]
        faces = []  # (box index, corners [4, 3], normal [3])
        for index, box in enumerate(self.boxes):
            for axis in range(3):
                for sign in (1, -1):
                    corners, normal = face_polygon(box, axis, sign)
                    if normal[2] >= min_nz - 1e-12:
                        faces.append((index, corners, normal))
        if not faces:
            return meshes
        owner = np.array([f[0] for f in faces])
        buried = self._covered_by_others(
            owner, np.array([f[1].mean(axis=0) + _BURIED_PROBE * f[2] for f in faces])
        )
        # a face free at its centre is not buried whole; the others are probed all over
        maybe = np.flatnonzero(buried)
        if len(maybe):
            probes = np.stack(
                [_face_probes(faces[i][1]) + _BURIED_PROBE * faces[i][2] for i in maybe]
            )  # [M, P, 3]
            grid = probes.shape[1]
            covered = self._covered_by_others(np.repeat(owner[maybe], grid), probes.reshape(-1, 3))
            buried[maybe] = covered.reshape(len(maybe), grid).all(axis=1)
        surfaces = [
            SupportSurface(corners, normal, index)
            for (index, corners, normal), hidden in zip(faces, buried)
            if not hidden
        ]
        return surfaces + meshes

    def _covered_by_others(self, owner: np.ndarray, points: np.ndarray) -> np.ndarray:
        """[N] bool: each point [N, 3] lies inside a box other than its owner's (index [N])."""
        covered = np.zeros(len(points), dtype=bool)
        for index, box in enumerate(self.boxes):
            covered |= box.contains(points) & (owner != index)
        return covered


class _PointTiles:
    """Points sorted by square tile, to find those inside an axis-aligned rectangle
    without scanning them all (height_at on many points and many boxes)."""

    TILE = 0.5  # m, about a quarter of a typical box footprint

    def __init__(self, xy: np.ndarray):
        """xy: [N, 2] world points."""
        self.xy = xy
        self.origin = xy.min(axis=0) if len(xy) else np.zeros(2)
        cells = np.floor((xy - self.origin) / self.TILE).astype(np.int64)
        self.width = int(cells[:, 0].max()) + 1 if len(xy) else 1
        self.height = int(cells[:, 1].max()) + 1 if len(xy) else 1
        ids = cells[:, 1] * self.width + cells[:, 0]
        self.order = np.argsort(ids, kind="stable")
        self.ids = ids[self.order]

    def within(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Indices of the points with lo <= xy <= hi (lo, hi: [2] world corners)."""
        c0 = np.floor((lo - self.origin) / self.TILE).astype(np.int64)
        c1 = np.floor((hi - self.origin) / self.TILE).astype(np.int64)
        c0 = np.maximum(c0, 0)
        c1 = np.minimum(c1, [self.width - 1, self.height - 1])
        if np.any(c0 > c1):
            return np.zeros(0, dtype=np.int64)
        rows = np.arange(c0[1], c1[1] + 1) * self.width
        starts = np.searchsorted(self.ids, rows + c0[0], side="left")
        ends = np.searchsorted(self.ids, rows + c1[0], side="right")
        candidates = np.concatenate([self.order[a:b] for a, b in zip(starts, ends)])
        inside = np.all((self.xy[candidates] >= lo) & (self.xy[candidates] <= hi), axis=1)
        return candidates[inside]


def raster_shape(bounds, resolution: float) -> tuple[int, int]:
    """(nx, ny) raster points of bounds [2, 2] at `resolution` m: round(extent/res) + 1 per axis."""
    extent = np.asarray(bounds, dtype=np.float64)[1] - np.asarray(bounds, dtype=np.float64)[0]
    return int(round(extent[0] / resolution)) + 1, int(round(extent[1] / resolution)) + 1


def rasterize(
    boxes, bounds, resolution: float, void_height: float, meshes: MeshIndex | None = None
) -> np.ndarray:
    """Highest box or mesh point above every raster point.

    Each box only touches the raster window of its axis-aligned bounding box, which is
    evaluated in chunks of at most _CHUNK_POINTS points; triangles likewise
    (`MeshIndex.raster`).

    Args:
        boxes: sequence of Box.
        bounds: [2, 2] [[xmin, ymin], [xmax, ymax]], world, m.
        resolution: cell size, m.
        void_height: height where nothing is met, m.
        meshes: the terrain's triangles, or None.

    Returns:
        [nx, ny] float32 heights at (xmin + i*res, ymin + j*res).
    """
    bounds = np.asarray(bounds, dtype=np.float64)
    nx, ny = raster_shape(bounds, resolution)
    top = np.full((nx, ny), -np.inf)
    for box in boxes:
        lo, hi = box.aabb()[:, :2]
        # Window of raster indices whose points may lie in the box footprint.
        i0, j0 = np.maximum(np.floor((lo - bounds[0]) / resolution - 1e-6).astype(int), 0)
        i1, j1 = np.minimum(np.ceil((hi - bounds[0]) / resolution + 1e-6).astype(int), [nx - 1, ny - 1])
        if i0 > i1 or j0 > j1:
            continue
        ys = bounds[0, 1] + np.arange(j0, j1 + 1) * resolution
        rows = max(1, _CHUNK_POINTS // len(ys))
        for a in range(i0, i1 + 1, rows):
            b = min(a + rows, i1 + 1)
            xs = bounds[0, 0] + np.arange(a, b) * resolution
            column = box.column_top(xs[:, None], ys[None, :])
            np.maximum(top[a:b, j0 : j1 + 1], column, out=top[a:b, j0 : j1 + 1])
    if meshes is not None and len(meshes):
        np.maximum(top, meshes.raster(bounds, resolution, (nx, ny)), out=top)
    return np.where(np.isfinite(top), top, void_height).astype(np.float32)
