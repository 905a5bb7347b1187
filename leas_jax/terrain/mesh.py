"""Triangle-mesh terrain geometry: vertical ray casts and support surfaces (terrain format v2).

Host code (NumPy), not jittable. A terrain's `[[mesh]]` entries and its `[elevation]`
map (`leas_jax.terrain.sources`) become `TerrainMesh` objects: world-frame triangles,
metres, z up. `MeshIndex` gathers the triangles of all of a terrain's meshes and answers
what the boxes answer with `Box.column_top`: the highest point of the terrain on
vertical lines (the heightfield raster and `Terrain.height_at`).

The ray cast ignores the triangles' orientation and takes the maximum over every
triangle a vertical line meets, so meshes with inverted or inconsistent normals, open
edges (no inside needed) and duplicate faces (the maximum is idempotent) give the same
heights as clean ones. Vertical triangles (no area seen from above) are skipped: the
line through a wall meets the wall's top edge, which belongs to the triangle above it.
A wall stored in float32 keeps a sliver of projected area and is kept; a line that
meets a triangle only within EDGE_TOL of its edges gets a height of the triangle (see
`_heights_on`), so no line gets a height beyond the heights of the corners it meets.

Support surfaces follow HPP's affordance extraction (hpp-affordance: the triangles whose
normal passes the support requirement, grown through shared edges into surfaces of one
plane): triangles within the friction cone (normals turned upwards first), not covered
by the terrain above their centroid, grouped by shared edges and one plane, and each
group cut into convex polygons by merging its triangles across shared edges while the
union stays convex (Hertel-Mehlhorn), which the sole placement tests need
(`leas_jax.contacts.planner.surfaces`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

# A vertical line exactly on a triangle edge meets the triangle (closed sets, as boxes):
# edge functions may be this far (m) negative; far below the raster resolution.
EDGE_TOL = 1e-5  # m (float32 STL vertices at 20 m are 2e-6 m apart)
# Triangles whose projected area is below this are vertical (skipped by the ray cast).
MIN_PROJECTED_AREA = 1e-12  # m^2
# Pairs (raster point, triangle) evaluated at once: bounds the temporaries to ~100 MB.
_CHUNK_PAIRS = 1 << 21
# Cell of the triangle index used by `MeshIndex.column_top` on arbitrary points: the
# median triangle extent (so that a cell holds a few triangles), within these bounds,
# doubled until the index holds at most INDEX_MAX_ENTRIES (triangle, cell) entries.
INDEX_CELL_BOUNDS = (0.02, 1.0)  # m
INDEX_MAX_ENTRIES = 1 << 24
# Coplanar test for the grouping of mesh triangles: STL stores float32 vertices (1e-6 m
# at 20 m), so the faces of one plane differ by more than the boxes' 1e-6 tolerances.
COPLANAR_ANGLE = 2e-3  # rad between two adjacent triangles' normals
# A group's corners must lie this close to its plane (a gently curved surface, whose
# neighbours all pass COPLANAR_ANGLE, does not): farther triangles stay alone.
COPLANAR_OFFSET = 1e-3  # m
# A triangle is covered when the terrain rises more than this above its centroid.
COVERED_TOL = 1e-3  # m
# Vertices closer than this are one vertex for the grouping (shared edges).
MERGE_DIGITS = 6  # rounding of world coordinates, m (1 um)


@dataclass(frozen=True, eq=False)
class TerrainMesh:
    """One mesh of a terrain, in the world frame.

    Attributes:
        key: the terrain-file key it comes from ("mesh[0]", "elevation").
        vertices: [V, 3] float64 world positions, m.
        faces: [F, 3] int64 vertex indices (any orientation).
        sha256: hex digest of the source file's bytes.
        source: the file as the terrain file names it.
    """

    key: str
    vertices: np.ndarray
    faces: np.ndarray
    sha256: str
    source: str

    def __post_init__(self):
        vertices = np.array(self.vertices, dtype=np.float64).reshape(-1, 3)
        faces = np.array(self.faces, dtype=np.int64).reshape(-1, 3)
        vertices.setflags(write=False)
        faces.setflags(write=False)
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "faces", faces)

    @property
    def triangles(self) -> np.ndarray:
        """[F, 3, 3] corner positions, world, m."""
        return self.vertices[self.faces]

    def aabb(self) -> np.ndarray:
        """[2, 3] axis-aligned bounds (min row, max row), world (as `Box.aabb`)."""
        return np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    def column_top(self, x, y) -> np.ndarray:
        """Highest point of this mesh on vertical lines through (x, y) [...] (as `Box.column_top`):
        [...] z, -inf where the line misses it. Builds a `MeshIndex` of this mesh alone."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64))
        top = MeshIndex([self]).column_top(np.stack([x.reshape(-1), y.reshape(-1)], axis=1))
        return top.reshape(x.shape)


def _edge_setup(tri: np.ndarray):
    """Per triangle, the planar edge functions of its xy projection.

    For p in the plane, w_k(p) = (b - a) x (p - a) over the edge a -> b opposite corner
    k, divided by the edge length: the signed distance (m) of p to that edge's line,
    positive inside for a counter-clockwise projection. Clockwise projections are
    handled by the sign of the doubled area.

    Args:
        tri: [F, 3, 3] triangles.

    Returns:
        (keep [F] bool (projected area above MIN_PROJECTED_AREA), coefficients [F', 3, 3]
         (per edge: ex, ey, c with w = ex x + ey y + c, sign-corrected), z [F', 3] the
         corner heights).
    """
    a, b, c = tri[:, 0, :2], tri[:, 1, :2], tri[:, 2, :2]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    keep = np.abs(area2) > 2.0 * MIN_PROJECTED_AREA
    a, b, c, area2 = a[keep], b[keep], c[keep], area2[keep]
    sign = np.sign(area2)
    coeffs = []
    # Edge opposite corner 0 is b -> c, opposite 1 is c -> a, opposite 2 is a -> b.
    for p, q in ((b, c), (c, a), (a, b)):
        d = q - p
        length = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)
        # w(x) = d x (x - p) = d0 (y - p1) - d1 (x - p0)
        ex = -d[:, 1] * sign / length
        ey = d[:, 0] * sign / length
        c0 = (d[:, 1] * p[:, 0] - d[:, 0] * p[:, 1]) * sign / length
        coeffs.append(np.stack([ex, ey, c0], axis=1))
    return keep, np.stack(coeffs, axis=1), tri[keep][:, :, 2]


def _heights_on(coeffs, z, lengths_tri, x, y, t):
    """Heights of triangles t at points (x, y), nan where the point is outside.

    Barycentric weights are the edge functions times the opposite edge's length over
    the doubled area (their sum), so z = sum_k w_k len_k z_k / sum_k w_k len_k. A point
    up to EDGE_TOL outside a triangle counts as on it: its negative edge functions are
    taken as 0, which moves it onto the triangle, and its height is a weighted mean of
    the corner heights, within their range. (The weights then sum to more than the
    doubled area, itself above 2 MIN_PROJECTED_AREA.) Extrapolated instead, the height
    grows with len / area, without bound for a triangle seen nearly edge-on from above:
    a vertical face stored in float32 keeps a projected area of 1e-9 m^2, and points
    beside such faces got heights of 68 m on a scene 0.18 m high.
    """
    w = coeffs[t, :, 0] * x[:, None] + coeffs[t, :, 1] * y[:, None] + coeffs[t, :, 2]  # [P, 3]
    inside = np.all(w >= -EDGE_TOL, axis=1)
    weights = np.maximum(w, 0.0) * lengths_tri[t]
    height = np.einsum("pk,pk->p", weights, z[t]) / weights.sum(axis=1)
    return np.where(inside, height, np.nan)


class MeshIndex:
    """All triangles of a terrain's meshes, for vertical ray casts.

    Built once per terrain (`Terrain.mesh_index`). Triangles seen edge-on from above are
    left out (see the module docstring).

    Attributes:
        triangles: [F, 3, 3] every triangle, world.
    """

    def __init__(self, meshes):
        meshes = tuple(meshes)
        tri = [m.triangles for m in meshes]
        self.triangles = np.concatenate(tri) if tri else np.zeros((0, 3, 3))
        keep, self._coeffs, self._z = _edge_setup(self.triangles)
        flat = self.triangles[keep]
        # Opposite-edge lengths of the projection, per corner (barycentric weights).
        a, b, c = flat[:, 0, :2], flat[:, 1, :2], flat[:, 2, :2]
        self._lengths = np.stack(
            [np.linalg.norm(c - b, axis=1), np.linalg.norm(a - c, axis=1), np.linalg.norm(b - a, axis=1)],
            axis=1,
        )
        # xy bounds grown by the edge tolerance: every point a triangle may hold.
        self._lo = flat[:, :, :2].min(axis=1) - 2 * EDGE_TOL if len(flat) else np.zeros((0, 2))
        self._hi = flat[:, :, :2].max(axis=1) + 2 * EDGE_TOL if len(flat) else np.zeros((0, 2))
        self._top = flat[:, :, 2].max(axis=1) if len(flat) else np.zeros(0)

    def __len__(self) -> int:
        return len(self._top)

    def raster(self, bounds, resolution: float, shape: tuple[int, int]) -> np.ndarray:
        """Highest triangle point above every raster point.

        Every triangle enumerates the raster points of its xy bounding box; the pairs
        are tested and reduced by maximum in chunks of _CHUNK_PAIRS.

        Args:
            bounds: [2, 2] raster bounds; raster point [i, j] is (xmin + i res, ymin + j res).
            resolution: cell size, m.
            shape: (nx, ny).

        Returns:
            [nx, ny] float64, -inf where no triangle is met.
        """
        bounds = np.asarray(bounds, dtype=np.float64)
        nx, ny = shape
        top = np.full(nx * ny, -np.inf)
        if len(self) == 0:
            return top.reshape(nx, ny)
        lo = (self._lo - bounds[0]) / resolution
        hi = (self._hi - bounds[0]) / resolution
        i0, j0 = np.maximum(np.ceil(lo), 0).astype(np.int64).T
        i1 = np.minimum(np.floor(hi[:, 0]), nx - 1).astype(np.int64)
        j1 = np.minimum(np.floor(hi[:, 1]), ny - 1).astype(np.int64)
        width = np.maximum(j1 - j0 + 1, 0)
        counts = np.maximum(i1 - i0 + 1, 0) * width
        ends = np.cumsum(counts)
        starts = ends - counts
        total = int(ends[-1])
        for a in range(0, total, _CHUNK_PAIRS):
            pair = np.arange(a, min(a + _CHUNK_PAIRS, total), dtype=np.int64)
            t = np.searchsorted(ends, pair, side="right")
            local = pair - starts[t]
            i = i0[t] + local // width[t]
            j = j0[t] + local % width[t]
            x = bounds[0, 0] + i * resolution
            y = bounds[0, 1] + j * resolution
            height = _heights_on(self._coeffs, self._z, self._lengths, x, y, t)
            hit = ~np.isnan(height)
            np.maximum.at(top, (i * ny + j)[hit], height[hit])
        return top.reshape(nx, ny)

    @functools.cached_property
    def _cells(self):
        """Triangle index on a grid of square cells: (origin [2], cell side, (cx, cy), CSR
        starts [cx*cy + 1], triangle ids, per-cell maximum triangle height [cx*cy])."""
        origin = self._lo.min(axis=0) if len(self) else np.zeros(2)
        extent = np.max(self._hi - self._lo, axis=1) if len(self) else np.ones(1)
        side = float(np.clip(np.median(extent), *INDEX_CELL_BOUNDS))
        while True:
            c0 = np.floor((self._lo - origin) / side).astype(np.int64)
            c1 = np.floor((self._hi - origin) / side).astype(np.int64)
            entries = int(np.sum((c1[:, 0] - c0[:, 0] + 1) * (c1[:, 1] - c0[:, 1] + 1)))
            size = (int(c1[:, 0].max(initial=0)) + 1, int(c1[:, 1].max(initial=0)) + 1)
            if entries <= INDEX_MAX_ENTRIES and size[0] * size[1] <= INDEX_MAX_ENTRIES:
                break
            side *= 2.0
        span_y = c1[:, 1] - c0[:, 1] + 1
        counts = (c1[:, 0] - c0[:, 0] + 1) * span_y
        t = np.repeat(np.arange(len(self)), counts)
        local = np.arange(len(t)) - np.repeat(np.cumsum(counts) - counts, counts)
        cell = (c0[t, 0] + local // span_y[t]) * size[1] + c0[t, 1] + local % span_y[t]
        order = np.argsort(cell, kind="stable")
        cell, t = cell[order], t[order]
        starts = np.searchsorted(cell, np.arange(size[0] * size[1] + 1))
        cell_top = np.full(size[0] * size[1], -np.inf)
        np.maximum.at(cell_top, cell, self._top[t])
        return origin, side, size, starts, t, cell_top

    def _cell_of(self, xy: np.ndarray) -> np.ndarray:
        """[N] flat index cell of points xy [N, 2], -1 outside the index."""
        origin, side, size, *_ = self._cells
        c = np.floor((xy - origin) / side).astype(np.int64)
        inside = (c[:, 0] >= 0) & (c[:, 0] < size[0]) & (c[:, 1] >= 0) & (c[:, 1] < size[1])
        return np.where(inside, c[:, 0] * size[1] + c[:, 1], -1)

    def column_top(self, xy) -> np.ndarray:
        """Highest triangle point on vertical lines through points xy [N, 2] (world, m): [N], -inf if none."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        top = np.full(len(xy), -np.inf)
        if len(self) == 0 or len(xy) == 0:
            return top
        _, _, _, starts, tri_ids, _ = self._cells
        cell = self._cell_of(xy)
        valid = np.flatnonzero(cell >= 0)
        counts = starts[cell[valid] + 1] - starts[cell[valid]]
        point = np.repeat(valid, counts)
        offset = np.arange(len(point)) - np.repeat(np.cumsum(counts) - counts, counts)
        t = tri_ids[np.repeat(starts[cell[valid]], counts) + offset]
        height = _heights_on(self._coeffs, self._z, self._lengths, xy[point, 0], xy[point, 1], t)
        hit = ~np.isnan(height)
        np.maximum.at(top, point[hit], height[hit])
        return top

    def top_bound(self, xy) -> np.ndarray:
        """[N] upper bound of `column_top(xy)`: the highest triangle registered in each point's cell."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        if len(self) == 0:
            return np.full(len(xy), -np.inf)
        cell = self._cell_of(xy)
        cell_top = self._cells[5]
        return np.where(cell >= 0, cell_top[np.maximum(cell, 0)], -np.inf)


@dataclass(frozen=True, eq=False)
class MeshSurface:
    """A convex support polygon cut from a mesh (`support_polygons`).

    Attributes:
        vertices: [N, 3] world, counter-clockwise seen from above (about `normal`).
        normal: [3] unit upward normal of the polygon's plane.
        mesh_index: index of the mesh in `Terrain.meshes`.
    """

    vertices: np.ndarray
    normal: np.ndarray
    mesh_index: int


def support_polygons(meshes, mu: float, height_at) -> list[MeshSurface]:
    """Support surfaces of triangle meshes: convex polygons of coplanar adjacent triangles.

    1. Triangles are oriented so that their normal points up (inverted normals do not
       matter); those at most atan(mu) from +z, with an area, are candidates.
    2. Duplicate triangles (same corners) are kept once; a triangle over which the
       terrain rises more than COVERED_TOL (`height_at`) at its centroid and near its
       three corners is covered (a box's bottom face turned up, a face inside another
       solid) and left out; a partly covered one is kept whole, as a box face is
       (`Terrain.support_surfaces`); the generator tests each sole for cover anyway.
    3. Candidates sharing an edge and a plane (COPLANAR_ANGLE, COPLANAR_OFFSET) form a
       group; each group gets its area-weighted normal and the plane through its
       area-weighted centroid, and is cut into convex polygons (`_convex_pieces`).

    Args:
        meshes: the terrain's TerrainMesh objects.
        mu: friction coefficient (> 0).
        height_at: callable [N, 2] -> [N] terrain height (all of the terrain: boxes too).

    Returns:
        list of MeshSurface, by mesh, then by group.
    """
    min_nz = math.cos(math.atan(mu))
    out = []
    for index, mesh in enumerate(meshes):
        tri = mesh.triangles
        if len(tri) == 0:
            continue
        normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        area2 = np.linalg.norm(normal, axis=1)
        flip = normal[:, 2] < 0.0
        faces = mesh.faces.copy()
        faces[flip] = faces[flip][:, [0, 2, 1]]
        normal[flip] *= -1.0
        with np.errstate(invalid="ignore", divide="ignore"):
            unit = normal / area2[:, None]
        candidate = (area2 > 2e-12) & (unit[:, 2] >= min_nz - 1e-12)
        ids = np.flatnonzero(candidate)
        if len(ids) == 0:
            continue
        # One vertex id per position (1 um), so that shared edges are found.
        rounded = np.round(mesh.vertices, MERGE_DIGITS)
        _, vertex_id = np.unique(rounded, axis=0, return_inverse=True)
        vertex_id = vertex_id.reshape(-1)
        corners = vertex_id[faces[ids]]
        # Duplicates: same three corners in any order.
        _, first = np.unique(np.sort(corners, axis=1), axis=0, return_index=True)
        ids, corners = ids[np.sort(first)], corners[np.sort(first)]
        # Samples: the centroid and a point near each corner (a tenth of the way in).
        corner_pts = tri[ids]
        samples = np.concatenate(
            [
                corner_pts.mean(axis=1, keepdims=True),
                0.9 * corner_pts + 0.1 * corner_pts.mean(axis=1, keepdims=True),
            ],
            axis=1,
        )
        flat = samples.reshape(-1, 3)
        free = (height_at(flat[:, :2]) <= flat[:, 2] + COVERED_TOL).reshape(-1, 4)
        exposed = free.any(axis=1)
        ids, corners = ids[exposed], corners[exposed]
        if len(ids) == 0:
            continue
        positions = np.zeros((int(vertex_id.max()) + 1, 3))
        positions[vertex_id] = mesh.vertices
        groups = _coplanar_groups(corners, unit[ids], positions)
        for members in groups:
            if len(members) == 1:  # most triangles of a curved surface: no merging to do
                t = members[0]
                out.append(MeshSurface(positions[corners[t]], unit[ids[t]], index))
                continue
            for polygon, plane_normal in _convex_pieces(
                corners[members], unit[ids[members]], area2[ids[members]], positions
            ):
                out.append(MeshSurface(polygon, plane_normal, index))
    return out


def _coplanar_groups(corners: np.ndarray, normals: np.ndarray, positions: np.ndarray) -> list[np.ndarray]:
    """Connected components of triangles through shared edges between coplanar neighbours.

    Args:
        corners: [T, 3] vertex ids of the (upward) triangles.
        normals: [T, 3] their unit normals.
        positions: [V, 3] vertex positions.

    Returns:
        list of index arrays into the T triangles, in order of their first triangle.
    """
    count = len(corners)
    # Undirected edges: sort each pair, then group equal pairs.
    edges = np.concatenate([corners[:, [0, 1]], corners[:, [1, 2]], corners[:, [2, 0]]])
    owner = np.tile(np.arange(count), 3)
    edges = np.sort(edges, axis=1)
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    edges, owner = edges[order], owner[order]
    same = np.all(edges[1:] == edges[:-1], axis=1)
    a, b = owner[:-1][same], owner[1:][same]
    from scipy.sparse import coo_matrix  # here: `leas --help` must not load SciPy
    from scipy.sparse.csgraph import connected_components

    # Neighbours share an edge, so their planes meet there: the angle decides.
    ok = np.einsum("ni,ni->n", normals[a], normals[b]) >= math.cos(COPLANAR_ANGLE)
    graph = coo_matrix((np.ones(int(ok.sum())), (a[ok], b[ok])), shape=(count, count))
    _, label = connected_components(graph, directed=False)
    # Components numbered in order of their first triangle.
    _, first = np.unique(label, return_index=True)
    label = np.argsort(np.argsort(first))[label]
    order = np.argsort(label, kind="stable")
    splits = np.flatnonzero(np.diff(label[order])) + 1
    return np.split(order, splits)


def _convex_pieces(corners, normals, area2, positions):
    """Convex polygons covering one coplanar group of triangles.

    The group's plane has the area-weighted mean normal n and passes through the
    area-weighted centroid; triangles with a corner farther than COPLANAR_OFFSET from it
    stay alone (their own plane); the others' corners are projected onto it. Triangles
    are merged across their shared edges, longest edge first, whenever the merged
    polygon stays convex (Hertel-Mehlhorn); collinear corners are then dropped.

    Args:
        corners: [T, 3] vertex ids (counter-clockwise about the upward normal).
        normals: [T, 3] unit normals; area2: [T] doubled areas.
        positions: [V, 3] vertex positions.

    Returns:
        list of ([N, 3] polygon corners, world, counter-clockwise about n; [3] n).
    """
    n = (normals * area2[:, None]).sum(axis=0)
    n /= np.linalg.norm(n)
    centre = (positions[corners].mean(axis=1) * area2[:, None]).sum(axis=0) / area2.sum()
    far = np.abs((positions[corners] - centre) @ n).max(axis=1) > COPLANAR_OFFSET
    out = [(positions[c], normal) for c, normal in zip(corners[far], normals[far])]
    corners = corners[~far]
    if len(corners) == 0:
        return out
    u = np.cross([0.0, 1.0, 0.0], n) if abs(n[1]) < 0.9 else np.cross([1.0, 0.0, 0.0], n)
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    used = np.unique(corners)
    rel = positions[used] - centre
    flat = dict(zip(used.tolist(), map(tuple, np.stack([rel @ u, rel @ v], axis=1).tolist())))
    world = {k: centre + p[0] * u + p[1] * v for k, p in flat.items()}
    polygons = {t: list(map(int, c)) for t, c in enumerate(corners)}
    parent = list(range(len(corners)))

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    shared = {}
    for t, c in enumerate(corners.tolist()):
        for k in range(3):
            shared.setdefault(frozenset((c[k], c[(k + 1) % 3])), []).append(t)
    interior = [(e, ts) for e, ts in shared.items() if len(ts) == 2]
    interior.sort(key=lambda item: -math.dist(*(flat[k] for k in item[0])))
    for edge, (ta, tb) in interior:
        ra, rb = root(ta), root(tb)
        if ra == rb:
            continue
        merged = _merge(polygons[ra], polygons[rb], tuple(edge), flat)
        if merged is not None:
            parent[rb] = ra
            polygons[ra] = merged
            del polygons[rb]
    for polygon in polygons.values():
        polygon = _drop_collinear(polygon, flat)
        out.append((np.array([world[k] for k in polygon]), n))
    return out


def _cross(o, a, b) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _merge(p: list, q: list, edge: tuple, flat: dict):
    """Polygon p + q glued along their shared edge, or None if not convex or not simple.

    p runs u -> v along the edge and q runs v -> u (both counter-clockwise).
    """
    x, y = edge
    for u, w in ((x, y), (y, x)):
        if u in p and w in p and p[(p.index(u) + 1) % len(p)] == w:
            break
    else:
        return None
    if u not in q or q[(q.index(w) + 1) % len(q)] != u:
        return None
    iu = p.index(u)
    p_from_w = p[iu + 1 :] + p[: iu + 1]  # w, ..., u
    iq = q.index(u)
    q_from_u = q[iq:] + q[:iq]  # u, ..., w
    merged = p_from_w + q_from_u[1:-1]
    if len(set(merged)) != len(merged):
        return None
    count = len(merged)
    for k in (merged.index(u), merged.index(w)):
        if not _convex_turn(flat[merged[k - 1]], flat[merged[k]], flat[merged[(k + 1) % count]]):
            return None
    return merged


def _convex_turn(a, b, c) -> bool:
    """Whether a -> b -> c turns left or goes straight on (not back: a collinear reversal
    is the spike of two polygons glued along one side of a T)."""
    ab = (b[0] - a[0], b[1] - a[1])
    bc = (c[0] - b[0], c[1] - b[1])
    cross = ab[0] * bc[1] - ab[1] * bc[0]
    tol = 1e-9 * math.hypot(*ab) * math.hypot(*bc)
    return cross > tol or (cross >= -tol and ab[0] * bc[0] + ab[1] * bc[1] > 0.0)


def _drop_collinear(polygon: list, flat: dict) -> list:
    """The polygon without corners lying on the line of their two neighbours."""
    changed = True
    while changed and len(polygon) > 3:
        changed = False
        for k in range(len(polygon)):
            a, b, c = flat[polygon[k - 1]], flat[polygon[k]], flat[polygon[(k + 1) % len(polygon)]]
            # Doubled area over the base: the distance of b to the line a-c, m.
            if abs(_cross(a, b, c)) <= 1e-7 * max(math.dist(a, c), 1e-12):
                del polygon[k]
                changed = True
                break
    return polygon
