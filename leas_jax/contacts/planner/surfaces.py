"""Support surfaces as arrays, and sole-rectangle placement tests on them.

Host-only (NumPy), not jittable. Wraps `Terrain.support_surfaces(mu)` (box faces whose
normal is within the friction cone, and the convex polygons of coplanar mesh triangles,
`leas_jax.terrain.mesh`) with what the generator and the verifier need:
plane equations, polygon edges, bounding boxes, the sole orientation on a face and
the "sole rectangle inside the face polygon" test of docs/design.md §6 check 1.

A terrain face, for that test, is the union of the box faces of one plane that touch
(`SurfaceArrays.group`): a sole may rest across two coplanar boxes, as on the
training arena's ground, which is tiled from one box per free rectangle of each cell.
HPP's affordance extraction, which the paper's planner uses, likewise merges adjacent
coplanar triangles into one surface. Each box face alone stays convex, so a sole inside
one face is tested exactly; across faces the test samples the sole rectangle (edges
every `UNION_EDGE_STEP`, inside every `UNION_INNER_STEP`): a gap narrower than that
between two faces of one plane could go unseen (the terrains' gaps are >= 0.15 m).
"""

from __future__ import annotations

import functools
import math
import weakref
from dataclasses import dataclass

import numpy as np

from leas_jax.contacts.robot.model import SOLE_LENGTH, SOLE_WIDTH

# Sole rectangle corners in the sole frame (x forward, y left), counter-clockwise.
SOLE_CORNERS = np.array(
    [[sx * SOLE_LENGTH / 2, sy * SOLE_WIDTH / 2, 0.0] for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
)

COPLANAR_NORMAL_TOL = 1e-6  # |n_a - n_b| below which two faces have the same normal
COPLANAR_OFFSET_TOL = 1e-5  # m, |offset_a - offset_b| below which they lie in one plane
TOUCH_TOL = 1e-3  # m, bounding boxes this close count as touching (grouping only)
UNION_EDGE_STEP = 0.02  # m, spacing of the sample points along the sole rectangle's edges (the raster's)
UNION_INNER_STEP = 0.04  # m, spacing of the sample points inside it
_INSIDE_TOL = 1e-6  # m, a sample point on a shared edge lies inside both faces


@dataclass(frozen=True)
class SurfaceArrays:
    """Support surfaces of a terrain, as arrays.

    Attributes:
        surfaces: the terrain's SupportSurface list.
        normals: [S, 3] unit outward normals.
        offsets: [S] plane offsets n . v0 (points x on the plane have n . x = offset).
        bbox: [S, 2, 3] axis-aligned bounds of each polygon, world.
        group: [S] coplanar group of each face: faces of one plane whose bounding
            boxes touch, transitively (`coplanar_groups`).
        members: per group, the sorted indices of its faces.
        edges: per face, (inward [E, 3], bounds [E]): the unit inward normals of its
            polygon's edges, in its plane, and inward . v_k; a point p on or near the
            plane is `m` inside edge k iff inward_k . p >= bounds_k + m.
    """

    surfaces: tuple
    normals: np.ndarray
    offsets: np.ndarray
    bbox: np.ndarray
    group: np.ndarray
    members: tuple
    edges: tuple

    def __len__(self) -> int:
        return len(self.surfaces)

    def plane_height(self, s: int, xy) -> np.ndarray:
        """[...] height of face s's plane above points xy [..., 2] (world, m)."""
        normal = self.normals[s]
        return (self.offsets[s] - np.asarray(xy, dtype=np.float64) @ normal[:2]) / normal[2]

    def inside(self, s: int, points, margin: float = 0.0) -> np.ndarray:
        """[...] whether points [..., 3] on or near face s's plane lie `margin` m inside its
        polygon (its cached `edges`; `inside_polygon` without them)."""
        return _inside_edges(np.asarray(points, dtype=np.float64), self.edges[s], margin)


_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def surface_arrays(terrain, mu: float) -> SurfaceArrays:
    """SurfaceArrays of `terrain.support_surfaces(mu)`, built once per terrain object and mu."""
    per_terrain = _CACHE.setdefault(terrain, {})
    if mu not in per_terrain:
        surfaces = tuple(terrain.support_surfaces(mu=mu))
        normals = np.array([s.normal for s in surfaces]).reshape(-1, 3)
        offsets = np.array([float(s.normal @ s.vertices[0]) for s in surfaces])
        bbox = np.array([[s.vertices.min(axis=0), s.vertices.max(axis=0)] for s in surfaces]).reshape(
            -1, 2, 3
        )
        group = coplanar_groups(normals, offsets, bbox)
        members = tuple(np.flatnonzero(group == g) for g in range(int(group.max(initial=-1)) + 1))
        edges = tuple(_edge_normals(s) for s in surfaces)
        per_terrain[mu] = SurfaceArrays(surfaces, normals, offsets, bbox, group, members, edges)
    return per_terrain[mu]


def _edge_normals(surface) -> tuple[np.ndarray, np.ndarray]:
    """(inward [E, 3], bounds [E]) of a face's polygon edges (see `SurfaceArrays.edges`)."""
    verts = surface.vertices
    inward = np.cross(surface.normal, np.roll(verts, -1, axis=0) - verts)
    inward /= np.linalg.norm(inward, axis=1, keepdims=True)
    return inward, np.einsum("ei,ei->e", inward, verts)


def coplanar_groups(normals: np.ndarray, offsets: np.ndarray, bbox: np.ndarray) -> np.ndarray:
    """Connected components of the faces that share a plane and whose bounding boxes touch.

    Touching bounding boxes are necessary, not sufficient, for touching polygons (a
    rotated face's box is larger than it): a group is only the set of faces that
    `sole_inside_union` tests together, each sample point against the real polygons.

    Args:
        normals: [S, 3] unit normals; offsets: [S] plane offsets; bbox: [S, 2, 3] bounds.

    Returns:
        [S] int group ids, numbered in order of each group's first face.
    """
    count = len(normals)
    parent = np.arange(count)

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    # Only faces whose offsets lie within the tolerance can share a plane: each face is
    # compared with that window of the faces sorted by offset (a mesh terrain has
    # thousands of faces, mostly in planes of their own), the later faces only.
    by_offset = np.argsort(offsets, kind="stable")
    sorted_offsets = offsets[by_offset]
    starts = np.searchsorted(sorted_offsets, offsets - COPLANAR_OFFSET_TOL, side="left")
    ends = np.searchsorted(sorted_offsets, offsets + COPLANAR_OFFSET_TOL, side="right")
    for i in range(count):
        window = by_offset[starts[i] : ends[i]]
        window = np.sort(window[window > i])
        same_plane = (np.linalg.norm(normals[window] - normals[i], axis=1) < COPLANAR_NORMAL_TOL) & (
            np.abs(offsets[window] - offsets[i]) < COPLANAR_OFFSET_TOL
        )
        touching = np.all(
            (bbox[window, 0] <= bbox[i, 1] + TOUCH_TOL) & (bbox[window, 1] >= bbox[i, 0] - TOUCH_TOL),
            axis=1,
        )
        for j in window[same_plane & touching]:
            a, b = root(i), root(int(j))
            if a != b:
                parent[max(a, b)] = min(a, b)
    # Each root is its component's smallest face index, so sorted roots number the
    # groups in order of their first face.
    roots = np.array([root(i) for i in range(count)], dtype=np.int64)
    return np.unique(roots, return_inverse=True)[1].reshape(-1)


@functools.lru_cache(maxsize=8)
def _sole_samples(grow: float) -> tuple[np.ndarray, np.ndarray]:
    """Points of the sole rectangle grown by `grow` (m) on every side, sole frame: its edges
    every <= UNION_EDGE_STEP and inside every <= UNION_INNER_STEP, as (corners [4, 3],
    the other points [P, 3])."""
    half = np.array([SOLE_LENGTH / 2 + grow, SOLE_WIDTH / 2 + grow])
    edge = [np.linspace(-h, h, int(math.ceil(2 * h / UNION_EDGE_STEP)) + 1) for h in half]
    inner = [np.linspace(-h, h, int(math.ceil(2 * h / UNION_INNER_STEP)) + 1)[1:-1] for h in half]
    border = np.concatenate(
        [np.stack([edge[0], np.full_like(edge[0], sy * half[1])], axis=1) for sy in (-1, 1)]
        + [np.stack([np.full_like(edge[1], sx * half[0]), edge[1]], axis=1) for sx in (-1, 1)]
    )
    grid = np.stack(np.meshgrid(*inner, indexing="ij"), axis=-1).reshape(-1, 2)
    points = np.unique(np.round(np.concatenate([border, grid]), 12), axis=0)
    points = np.concatenate([points, np.zeros((len(points), 1))], axis=1)
    corner = np.all(np.isclose(np.abs(points[:, :2]), half), axis=1)
    return points[corner], points[~corner]


def _inside_edges(points: np.ndarray, edges: tuple, margin: float) -> np.ndarray:
    """[...] whether points [..., 3] on or near a face's plane are `margin` inside all its
    edges (`SurfaceArrays.edges` of the face: the inward normals lie in the plane, so the
    points need no projection)."""
    inward, bounds = edges
    return np.all(points @ inward.T >= bounds + margin, axis=-1)


def sole_inside_union(surfaces: SurfaceArrays, faces, pos, rot, margin: float) -> np.ndarray:
    """Whether sole rectangles lie inside the union of some faces of one plane, `margin` from its edges.

    Every sample point of the rectangle grown by `margin` (`_sole_samples`) must lie in
    one of the polygons. The four corners are tested first, on all soles; the other
    points only on the soles whose corners passed.

    Args:
        surfaces: the terrain's SurfaceArrays.
        faces: indices of the faces (one plane).
        pos: [N, 3] sole centres, world (on the plane); rot: [3, 3] or [N, 3, 3] world_R_sole.
        margin: distance kept from the union's edges, m (negative: tolerance outside).

    Returns:
        [N] bool.
    """
    pos = np.asarray(pos, dtype=np.float64).reshape(-1, 3)
    rot = np.broadcast_to(np.asarray(rot, dtype=np.float64), (len(pos), 3, 3))
    ok = np.ones(len(pos), dtype=bool)
    for subset in _sole_samples(margin):
        idx = np.flatnonzero(ok)
        if len(idx) == 0:
            break
        points = (pos[idx, None, :] + np.einsum("nij,pj->npi", rot[idx], subset)).reshape(-1, 3)  # [n P, 3]
        covered = np.zeros(len(points), dtype=bool)
        for s in faces:
            covered |= surfaces.inside(s, points, -_INSIDE_TOL)
        ok[idx] = covered.reshape(len(idx), -1).all(axis=1)
    return ok


def sole_rotation(normal, yaw) -> np.ndarray:
    """Sole orientations lying flat on faces with a given heading.

    z = the face normal; x = the heading (cos yaw, sin yaw, 0) projected on the face;
    y = z x x.

    Args:
        normal: [N, 3] unit face normals (not vertical faces).
        yaw: [N] headings, rad.

    Returns:
        [N, 3, 3] world_R_sole.
    """
    normal = np.asarray(normal, dtype=np.float64).reshape(-1, 3)
    yaw = np.broadcast_to(np.asarray(yaw, dtype=np.float64), (len(normal),))
    heading = np.stack([np.cos(yaw), np.sin(yaw), np.zeros_like(yaw)], axis=1)
    x = heading - np.einsum("ni,ni->n", heading, normal)[:, None] * normal
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    y = np.cross(normal, x)
    return np.stack([x, y, normal], axis=2)


def sole_rotation_single(normal, yaw: float) -> np.ndarray:
    """`sole_rotation` of one face normal [3] and one yaw: [3, 3] world_R_sole.

    Same operations in the same order as the batched version (bit-identical), on
    Python floats: the batched NumPy calls cost ~0.1 ms for a single sole.
    """
    n0, n1, n2 = (float(v) for v in normal)
    h0, h1 = math.cos(yaw), math.sin(yaw)
    d = h0 * n0 + h1 * n1 + 0.0 * n2
    x0, x1, x2 = h0 - d * n0, h1 - d * n1, 0.0 - d * n2
    norm = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    x0, x1, x2 = x0 / norm, x1 / norm, x2 / norm
    y0, y1, y2 = n1 * x2 - n2 * x1, n2 * x0 - n0 * x2, n0 * x1 - n1 * x0
    return np.array([[x0, y0, n0], [x1, y1, n1], [x2, y2, n2]])


def sole_corners_world(pos, rot) -> np.ndarray:
    """[N, 4, 3] sole rectangle corners of soles at pos [N, 3], rot [N, 3, 3], world."""
    return np.asarray(pos)[:, None, :] + np.einsum("nij,cj->nci", rot, SOLE_CORNERS)


def inside_polygon(surface, points, margin: float = 0.0) -> np.ndarray:
    """Whether points on a face's plane lie inside its polygon, `margin` m from the edges.

    The polygon is counter-clockwise seen from the normal's tip, so edge k's inward
    normal in the plane is n x (v_{k+1} - v_k), normalised; the signed distance of p
    to the edge line is inward_k . (p - v_k) (`_edge_normals`, `_inside_edges`).

    Args:
        surface: a SupportSurface.
        points: [..., 3] world points on or near the face's plane (their offset along
            the normal does not change the test).
        margin: required distance from every edge, m (negative: tolerance outside).

    Returns:
        [...] bool.
    """
    return _inside_edges(np.asarray(points, dtype=np.float64), _edge_normals(surface), margin)


_BOUNDS_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_BOUND_MARGIN = (
    1e-3  # m, growth of the box footprints in `_height_bounds` (>> the terrain's 1e-7 m hit tolerance)
)


def _box_bounds(terrain) -> tuple:
    """Per box, cached per terrain: xy footprint of its AABB grown by _BOUND_MARGIN [B, 2, 2],
    top z [B], whether it is tilted (roll or pitch) [B], and the footprints' columns
    (`_footprint_columns`)."""
    if terrain not in _BOUNDS_CACHE:
        boxes = terrain.boxes
        aabb = np.array([box.aabb() for box in boxes]).reshape(-1, 2, 3)
        foot = aabb[:, :, :2] + np.array([-_BOUND_MARGIN, _BOUND_MARGIN])[None, :, None]
        top = np.array([float(box.center[2] + box.half[2]) for box in boxes])
        # Yaw only, exactly: z axis (0, 0, 1) in both the box and the world frame.
        tilted = np.array(
            [
                bool(np.any(box.rotation[2] != (0.0, 0.0, 1.0)) or np.any(box.rotation[:2, 2] != 0.0))
                for box in boxes
            ],
            dtype=bool,
        )
        _BOUNDS_CACHE[terrain] = (foot, top, tilted, _footprint_columns(foot[:, 0], foot[:, 1]))
    return _BOUNDS_CACHE[terrain]


def _footprint_columns(lo: np.ndarray, hi: np.ndarray) -> tuple:
    """(x low, x high, y low, y high) [B] contiguous columns of footprints lo, hi [B, 2]."""
    return tuple(np.ascontiguousarray(a[:, k]) for k in (0, 1) for a in (lo, hi))


def _boxes_meeting(columns, xy: np.ndarray) -> np.ndarray:
    """Sorted indices of the footprints (closed rectangles, `_footprint_columns` of them) that meet the
    bounding rectangle of the points xy [N, 2]: a superset of those holding a point."""
    x_lo, x_hi, y_lo, y_hi = columns
    if len(xy) == 0:
        return np.zeros(0, dtype=np.int64)
    x0, y0 = xy.min(axis=0).tolist()
    x1, y1 = xy.max(axis=0).tolist()
    return np.flatnonzero((x_lo <= x1) & (x_hi >= x0) & (y_lo <= y1) & (y_hi >= y0))


def _height_bounds(terrain, xy: np.ndarray) -> np.ndarray:
    """[N] upper bounds of `terrain.height_at(xy)` (xy [N, 2]); +inf where a tilted box may count.

    A box whose rotation keeps z vertical (yaw only) meets a vertical line, if at all,
    up to exactly its top z (`Box.column_top`: the only non-vertical slab is z); lines
    outside its grown footprint miss it. Where no box is hit the height is the void.
    So max(void, tops of the yaw-only boxes whose footprint holds the point) bounds the
    height, unless a tilted box's footprint holds the point (no cheap exact bound).
    """
    foot, top, tilted, columns = _box_bounds(terrain)
    # Only the boxes whose footprint meets the points' bounding rectangle can hold one.
    near = _boxes_meeting(columns, xy)
    foot, top, tilted = foot[near], top[near], tilted[near]
    hit = (
        (xy[:, None, 0] >= foot[None, :, 0, 0])
        & (xy[:, None, 0] <= foot[None, :, 1, 0])
        & (xy[:, None, 1] >= foot[None, :, 0, 1])
        & (xy[:, None, 1] <= foot[None, :, 1, 1])
    )  # [N, B']
    bound = np.maximum(
        np.max(np.where(hit, top[None, :], -np.inf), axis=1, initial=-np.inf), float(terrain.void_height)
    )
    if terrain.meshes:
        # The highest triangle registered in each point's cell bounds the meshes' part.
        bound = np.maximum(bound, terrain.mesh_index().top_bound(xy))
    return np.where(np.any(hit & tilted[None, :], axis=1), np.inf, bound)


_HEIGHT_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _column_bounds(terrain) -> tuple:
    """Per box, cached per terrain: the xy window `Terrain.height_at` tests points against,
    ([B, 2] low, [B, 2] high, their `_footprint_columns`): the box AABB's footprint grown by
    the terrain's edge tolerance, computed with the same operations (so the same float values)."""
    if terrain not in _HEIGHT_CACHE:
        from leas_jax.terrain.model import _EDGE_TOL

        lo, hi = [], []
        for box in terrain.boxes:
            box_lo, box_hi = box.aabb()[:, :2]
            lo.append(box_lo - _EDGE_TOL)
            hi.append(box_hi + _EDGE_TOL)
        lo, hi = np.array(lo).reshape(-1, 2), np.array(hi).reshape(-1, 2)
        _HEIGHT_CACHE[terrain] = (lo, hi, _footprint_columns(lo, hi))
    return _HEIGHT_CACHE[terrain]


def height_at(terrain, xy: np.ndarray) -> np.ndarray:
    """`terrain.height_at(xy)` for finite xy [N, 2], the same values, faster for a few points.

    `Terrain.height_at` scans every box (its AABB built anew each call) and ray casts
    (`Box.column_top`) the points inside each box's grown footprint; here the footprints
    are cached arrays, one [N, B] test finds the boxes that hold a point, and only those
    ray cast their points. `column_top` is point-wise and the maximum does not depend on
    the order, so the heights are identical. Meshes are ray cast by `MeshIndex.column_top`,
    as in `Terrain.height_at`.
    """
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    lo, hi, columns = _column_bounds(terrain)
    near = _boxes_meeting(columns, xy)
    lo, hi = lo[near], hi[near]
    x, y = xy[:, 0:1], xy[:, 1:2]
    hit = (
        (x >= lo[None, :, 0]) & (x <= hi[None, :, 0]) & (y >= lo[None, :, 1]) & (y <= hi[None, :, 1])
    )  # [N, B']
    top = np.full(len(xy), -np.inf)
    boxes = terrain.boxes
    for k in np.flatnonzero(hit.any(axis=0)).tolist():
        b = int(near[k])
        idx = np.flatnonzero(hit[:, k])
        top[idx] = np.maximum(top[idx], boxes[b].column_top(xy[idx, 0], xy[idx, 1]))
    if terrain.meshes:
        top = np.maximum(top, terrain.mesh_index().column_top(xy))
    return np.where(np.isfinite(top), top, terrain.void_height)


def uncovered(terrain, points, tol: float) -> np.ndarray:
    """Whether nothing of the terrain rises more than `tol` above points (vertical ray cast).

    Points whose height bound (`_height_bounds`: box tops, no ray cast) is already
    within `tol` are decided without `terrain.height_at`, which is called on the others
    only; the answer is the same as ray casting every point.

    Args:
        terrain: the Terrain.
        points: [N, 3] world points (sole corners and centres on a face).
        tol: allowed height difference, m.

    Returns:
        [N] bool.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    free = _height_bounds(terrain, points[:, :2]) <= points[:, 2] + tol
    rest = np.nonzero(~free)[0]
    if len(rest):
        free[rest] = height_at(terrain, points[rest, :2]) <= points[rest, 2] + tol
    return free


def find_support(
    terrain, surfaces: SurfaceArrays, pos, rot, dist_tol: float, angle_tol: float, edge_tol: float
) -> tuple[int, str]:
    """The support surface a sole rests on, docs/design.md §6 check 1.

    Args:
        terrain: the Terrain (unused by the test itself; kept for messages).
        surfaces: its support surfaces.
        pos: [3] sole position, world; rot: [3, 3] world_R_sole.
        dist_tol: max distance of the sole centre to the face plane, m (5 mm).
        angle_tol: max angle between the sole z axis and the face normal, rad (3 deg).
        edge_tol: how far the sole corners may stick out of the polygon, m.

    Returns:
        (surface index, "") when found (a face of the sole's coplanar group; the sole
        lies inside the group's union, see the module docstring), else (-1, reason
        naming the closest face).
    """
    del terrain
    pos = np.asarray(pos, dtype=np.float64)
    rot = np.asarray(rot, dtype=np.float64)
    if len(surfaces) == 0:
        return -1, "the terrain has no support surface"
    corners = sole_corners_world(pos[None], rot[None])[0]
    dist = surfaces.normals @ pos - surfaces.offsets
    cos_angle = np.clip(surfaces.normals @ rot[:, 2], -1.0, 1.0)
    angle = np.arccos(cos_angle)
    best_reason, best_score = "", np.inf
    on_plane = (np.abs(dist) <= dist_tol) & (angle <= angle_tol)
    for s in np.argsort(np.abs(dist)):
        surface = surfaces.surfaces[s]
        inside = inside_polygon(surface, corners, -edge_tol)
        if on_plane[s] and inside.all():
            return int(s), ""
        score = abs(dist[s]) + angle[s] + (0 if inside.all() else 1.0)
        if score < best_score:
            best_score = score
            best_reason = (
                f"closest face ({surface.origin}): plane distance {1000 * dist[s]:.1f} mm, "
                f"tilt {np.degrees(angle[s]):.2f} deg, {int((~inside).sum())} sole corners outside"
            )
    for group in np.unique(surfaces.group[on_plane]):
        members = surfaces.members[group]
        if len(members) > 1 and sole_inside_union(surfaces, members, pos, rot, -edge_tol)[0]:
            return int(members[0]), ""
    return -1, "sole not on a support surface; " + best_reason
