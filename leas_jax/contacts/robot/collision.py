"""Collision checks of Talos postures against the terrain boxes and between the legs (coal).

Host-only (coal, NumPy), not jittable. Geometry placements come either from
Pinocchio (`placements_pinocchio`, used by the verifier) or from a NumPy forward
kinematics of the legs with the upper body rigid in one of `model.UPPER_BODY_POSTURES`
(`placements_fast`, used by the generator; tests check that both agree). Each
geometry's local bounding box is moved to the world frame and tested against the
terrain boxes' bounding boxes first, so that coal only sees pairs that may touch.

Terrain collision objects (`coal.Box` + transform per terrain box, and a
`coal.BVHModelOBBRSS` per square tile of each terrain mesh) are built once per terrain
object and cached (`terrain_collision`).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from leas_jax.contacts.robot.model import LEFT, RIGHT, TalosModel

# Leg links whose meshes are checked for leg-leg and leg-body self-collision: thigh,
# shin, ankle pitch and foot (links 1-2 sit inside the pelvis and always touch it).
SELF_COLLISION_LINKS = (3, 4, 5, 6)
# Terrain meshes are cut into square tiles of this side (m, by triangle centroid), one
# BVH each: a robot geometry's bounding box then meets a few tiles instead of one BVH
# spanning the whole scene, as with the boxes.
MESH_TILE = 1.0


@dataclass
class TerrainCollision:
    """coal objects of a terrain's boxes, then of its mesh tiles.

    Attributes:
        shapes: coal.Box per terrain box (full extents), then a coal.BVHModelOBBRSS per
            mesh tile (world-frame triangles).
        transforms: coal.Transform3s per object (world_R_box and centre; identity for tiles).
        aabb: [B, 2, 3] world axis-aligned bounds (min, max) of each object.
    """

    shapes: list
    transforms: list
    aabb: np.ndarray

    def __post_init__(self):
        # Per-axis columns of the bounds, contiguous: `boxes_near` compares [B] vectors.
        self._lo = [np.ascontiguousarray(self.aabb[:, 0, k]) for k in range(3)]
        self._hi = [np.ascontiguousarray(self.aabb[:, 1, k]) for k in range(3)]

    def boxes_near(self, lo, hi) -> np.ndarray:
        """Sorted indices of the boxes whose bounds meet the box [lo, hi] (closed sets)."""
        near = (self._lo[0] <= hi[0]) & (self._hi[0] >= lo[0])
        for k in (1, 2):
            near &= (self._lo[k] <= hi[k]) & (self._hi[k] >= lo[k])
        return np.flatnonzero(near)


_TERRAIN_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def terrain_collision(terrain) -> TerrainCollision:
    """The coal objects of `terrain` (a leas_jax.terrain.Terrain), built once per terrain object."""
    cached = _TERRAIN_CACHE.get(terrain)
    if cached is None:
        import coal

        shapes, transforms, aabb = [], [], []
        for box in terrain.boxes:
            shapes.append(coal.Box(*(float(s) for s in box.size)))
            transforms.append(
                coal.Transform3s(np.array(box.rotation), np.array(box.center, dtype=np.float64))
            )
            aabb.append(box.aabb())
        for mesh in terrain.meshes:
            for tri in mesh_tiles(mesh.triangles, MESH_TILE):
                shapes.append(_bvh(coal, tri))
                transforms.append(coal.Transform3s())
                aabb.append(np.stack([tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)]))
        cached = TerrainCollision(shapes, transforms, np.array(aabb).reshape(-1, 2, 3))
        _TERRAIN_CACHE[terrain] = cached
    return cached


def terrain_object_name(terrain, index: int) -> str:
    """Name of collision object `index` of `terrain_collision(terrain)`: its boxes, then mesh tiles."""
    boxes = len(terrain.boxes)
    return f"terrain box {index}" if index < boxes else f"terrain mesh tile {index - boxes}"


def mesh_tiles(triangles: np.ndarray, tile: float) -> list[np.ndarray]:
    """Triangles [F, 3, 3] grouped by the square tile (side `tile`, m) holding their centroid's xy.

    Returns:
        list of [F_k, 3, 3] arrays, tiles in row-major order of their (x, y) indices.
    """
    cell = np.floor(triangles.mean(axis=1)[:, :2] / tile).astype(np.int64)
    _, label = np.unique(cell, axis=0, return_inverse=True)
    label = label.reshape(-1)
    order = np.argsort(label, kind="stable")
    return np.split(triangles[order], np.flatnonzero(np.diff(label[order])) + 1)


def _bvh(coal, triangles: np.ndarray):
    """coal.BVHModelOBBRSS of triangles [F, 3, 3] (world frame, three vertices per triangle)."""
    model = coal.BVHModelOBBRSS()
    model.beginModel(len(triangles), 3 * len(triangles))
    model.addVertices(np.ascontiguousarray(triangles.reshape(-1, 3), dtype=np.float64))
    model.addTriangles(np.arange(3 * len(triangles), dtype=np.int64).reshape(-1, 3))
    model.endModel()
    return model


def body_part(geometry_name: str) -> str:
    """The part of Talos a collision geometry belongs to: "arm" (arms and grippers),
    "leg" (legs and feet) or "trunk" (torso, head, base)."""
    if geometry_name.startswith(("arm_", "gripper_")):
        return "arm"
    if geometry_name.startswith("leg_"):
        return "leg"
    return "trunk"


class RobotCollision:
    """Robot-side collision data derived from a TalosModel.

    Host-only, not jittable; one per process (`robot_collision(talos)` caches it).

    Attributes:
        geometries: coal geometry per collision object of `talos.geom_model`.
        names: geometry names.
        local_center: [G, 3], local_half: [G, 3] bounding box of each geometry in its
            own frame (coal's local AABB).
        parent: [G] Pinocchio joint of each geometry.
        joint_geom: [G, 4, 4] joint-to-geometry placements.
        self_pairs: [P, 2] geometry index pairs checked for self-collision.
        rootMg_upper: {upper-body posture: [G, 4, 4]} root-to-geometry placements in each
            of `talos.upper_refs` (valid for the geometries not on the legs).
        parts: [G] the part of Talos each geometry belongs to (`body_part`): "arm" is
            what the upper-body postures move.
        leg_of: [G] 0 / 1 for left / right leg geometries, -1 for the rest.
        leg_link: [G] link number 1..6 inside the leg, 0 for the rest.
    """

    def __init__(self, talos: TalosModel):
        import pinocchio as pin

        gm = talos.geom_model
        self.geometries = [g.geometry for g in gm.geometryObjects]
        self.names = [g.name for g in gm.geometryObjects]
        centers, halves = [], []
        for geom in self.geometries:
            geom.computeLocalAABB()
            lo, hi = np.array(geom.aabb_local.min_), np.array(geom.aabb_local.max_)
            centers.append(0.5 * (lo + hi))
            halves.append(0.5 * (hi - lo))
        self.local_center = np.array(centers)
        self.local_half = np.array(halves)
        self.parent = np.array([g.parentJoint for g in gm.geometryObjects])
        self.joint_geom = np.array([g.placement.homogeneous for g in gm.geometryObjects])
        self.leg_of = np.full(len(self.names), -1)
        self.leg_link = np.zeros(len(self.names), dtype=np.int64)
        for side in (LEFT, RIGHT):
            for g in talos.leg_geom_ids[side]:
                self.leg_of[g] = side
                self.leg_link[g] = int(self.names[g].split("_")[2])
        # Root-frame placements of all geometries in each upper-body posture (root at the origin).
        data = talos.model.createData()
        gd = pin.GeometryData(gm)
        self.rootMg_upper = {}
        for upper, q_upper in talos.upper_refs.items():
            pin.updateGeometryPlacements(talos.model, data, gm, gd, q_upper)
            self.rootMg_upper[upper] = np.array([gd.oMg[g].homogeneous for g in range(len(self.names))])
        self.parts = [body_part(name) for name in self.names]
        self.self_pairs = self._self_pairs(talos)
        self._leg_geoms = np.nonzero(self.leg_of >= 0)[0]
        self._leg_side = self.leg_of[self._leg_geoms]
        self._leg_frame = self.leg_link[self._leg_geoms] - 1
        self._leg_hip = np.array([leg.hip_offset for leg in talos.legs])
        self._leg_thigh = np.array([leg.thigh for leg in talos.legs])
        self._leg_shin = np.array([leg.shin for leg in talos.legs])

    def _self_pairs(self, talos: TalosModel) -> np.ndarray:
        """Leg links 3-6 vs the other leg's links 3-6, and vs non-leg geometries not disabled in the SRDF."""
        import pinocchio as pin

        gm = talos.geom_model.copy()
        gm.addAllCollisionPairs()
        pin.removeCollisionPairs(talos.model, gm, talos.srdf_path)
        allowed = {(p.first, p.second) for p in gm.collisionPairs}
        pairs = []
        checked = [g for g in range(len(self.names)) if self.leg_link[g] in SELF_COLLISION_LINKS]
        for a in checked:
            for b in range(len(self.names)):
                if (a, b) not in allowed and (b, a) not in allowed:
                    continue
                if self.leg_of[b] == -1 or (
                    self.leg_of[b] != self.leg_of[a] and self.leg_link[b] in SELF_COLLISION_LINKS
                ):
                    if self.leg_of[b] == -1 or a < b:
                        pairs.append((a, b))
        return np.array(sorted(set(pairs)), dtype=np.int64).reshape(-1, 2)

    def placements_fast(
        self,
        talos: TalosModel,
        root_R: np.ndarray,
        root_p: np.ndarray,
        leg_q: np.ndarray,
        upper: str = "half_sitting",
    ) -> tuple[np.ndarray, np.ndarray]:
        """World placements of all geometries by NumPy forward kinematics.

        The upper body is rigid in posture `upper`, so its geometries follow the root;
        leg geometries follow the chain of `ik.py` eq. (1)-(3).

        Args:
            talos: the model.
            root_R: [3, 3] world_R_root; root_p: [3] root position, world, m.
            leg_q: [2, 6] leg joints, rad.
            upper: the upper body's posture, a key of `talos.upper_refs`.

        Returns:
            (R [G, 3, 3], p [G, 3]) world placements of the geometries.
        """
        oMroot = np.eye(4)
        oMroot[:3, :3] = root_R
        oMroot[:3, 3] = root_p
        oMg = oMroot @ self.rootMg_upper[upper]
        frames = _legs_joint_frames(self._leg_hip, self._leg_thigh, self._leg_shin, leg_q)  # [2, 6, 4, 4]
        oMg[self._leg_geoms] = (
            oMroot @ frames[self._leg_side, self._leg_frame] @ self.joint_geom[self._leg_geoms]
        )
        return oMg[:, :3, :3], oMg[:, :3, 3]

    def placements_pinocchio(self, talos: TalosModel, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World placements of all geometries by Pinocchio for configuration q [39]."""
        import pinocchio as pin

        pin.updateGeometryPlacements(talos.model, talos.data, talos.geom_model, talos.geom_data, q)
        oMg = np.array([talos.geom_data.oMg[g].homogeneous for g in range(len(self.names))])
        return oMg[:, :3, :3], oMg[:, :3, 3]

    def world_aabb(self, rot: np.ndarray, pos: np.ndarray) -> np.ndarray:
        """[G, 2, 3] world bounding boxes of the geometries at placements (rot [G,3,3], pos [G,3])."""
        center = np.einsum("gij,gj->gi", rot, self.local_center) + pos
        half = np.einsum("gij,gj->gi", np.abs(rot), self.local_half)
        return np.stack([center - half, center + half], axis=1)

    def terrain_contacts(
        self,
        rot: np.ndarray,
        pos: np.ndarray,
        terrain: TerrainCollision,
        first_only: bool = True,
        aabb: np.ndarray | None = None,
    ) -> list[tuple[int, int]]:
        """Geometry/terrain-box pairs in collision.

        Args:
            rot: [G, 3, 3], pos: [G, 3] geometry placements, world.
            terrain: the terrain's coal objects.
            first_only: stop at the first collision.
            aabb: [G, 2, 3] `world_aabb(rot, pos)` if already computed.

        Returns:
            list of (geometry index, terrain object index) in collision (empty: collision-free);
            objects are the boxes, then the mesh tiles (`TerrainCollision.shapes`).
        """
        import coal

        if len(terrain.aabb) == 0:
            return []
        aabb = self.world_aabb(rot, pos) if aabb is None else aabb
        # Only the boxes meeting the bounds of the whole robot can meet one of its
        # geometries: the [G, B] test runs on those (same pairs, same order as on all).
        near = terrain.boxes_near(aabb[:, 0].min(axis=0).tolist(), aabb[:, 1].max(axis=0).tolist())
        if len(near) == 0:
            return []
        box_lo, box_hi = terrain.aabb[near, 0], terrain.aabb[near, 1]
        overlap = np.all((aabb[:, None, 0] <= box_hi[None]) & (aabb[:, None, 1] >= box_lo[None]), axis=2)
        hits = []
        request = coal.CollisionRequest()
        result = coal.CollisionResult()
        for g, k in zip(*np.nonzero(overlap)):
            b = near[k]
            result.clear()
            tf = coal.Transform3s(rot[g], pos[g])
            if coal.collide(
                self.geometries[g], tf, terrain.shapes[b], terrain.transforms[b], request, result
            ):
                hits.append((int(g), int(b)))
                if first_only:
                    break
        return hits

    def self_contacts(
        self, rot: np.ndarray, pos: np.ndarray, first_only: bool = True, aabb: np.ndarray | None = None
    ) -> list[tuple[int, int]]:
        """Self-collision pairs (legs vs legs, legs vs upper body) in collision, same conventions."""
        import coal

        aabb = self.world_aabb(rot, pos) if aabb is None else aabb
        # Rows (min xyz, max xyz) gathered once per side of the pairs: two gathers instead of four.
        flat = aabb.reshape(len(aabb), 6)
        box_a, box_b = flat[self.self_pairs[:, 0]], flat[self.self_pairs[:, 1]]
        overlap = np.all((box_a[:, :3] <= box_b[:, 3:]) & (box_a[:, 3:] >= box_b[:, :3]), axis=1)
        pairs = self.self_pairs[overlap]
        if len(pairs):
            # Pairs whose oriented boxes (local bounds, which hold the meshes) are apart
            # cannot collide: coal would answer False; ~90 % of the pairs, ~5 us each.
            center = np.einsum("gij,gj->gi", rot, self.local_center) + pos
            pairs = pairs[~_obbs_apart(rot, center, self.local_half, pairs[:, 0], pairs[:, 1])]
        hits = []
        request = coal.CollisionRequest()
        result = coal.CollisionResult()
        for ga, gb in pairs.tolist():
            result.clear()
            if coal.collide(
                self.geometries[ga],
                coal.Transform3s(rot[ga], pos[ga]),
                self.geometries[gb],
                coal.Transform3s(rot[gb], pos[gb]),
                request,
                result,
            ):
                hits.append((int(ga), int(gb)))
                if first_only:
                    break
        return hits


# m, gap the test must see between two boxes to call them apart: far above the rounding
# error of the test, far below any distance that matters (coal sees touching as contact).
_SAT_MARGIN = 1e-6


def _obbs_apart(rot, center, half, a, b) -> np.ndarray:
    """[P] whether geometry a[p]'s and b[p]'s oriented bounding boxes are apart by > _SAT_MARGIN.

    Separating-axis test of two boxes (Gottschalk et al., "OBBTree", SIGGRAPH 1996) on
    the 3 + 3 face normals only, in a's frame (C = A^T B, t = A^T (c_b - c_a)); the 9
    edge-edge axes would separate < 1 % more of the generator's pairs and cost as much
    again. Conservative: missing axes only leave pairs to coal, and |C| is grown by 1e-12.

    Args:
        rot: [G, 3, 3] geometry orientations, world.
        center: [G, 3] world centres of the geometry-frame bounding boxes.
        half: [G, 3] their half extents (geometry frame).
        a, b: [P] geometry indices of the pairs.
    """
    A, B = rot[a], rot[b]
    ha, hb = half[a], half[b]
    At = A.transpose(0, 2, 1)
    C = np.matmul(At, B)
    t = np.matmul(At, (center[b] - center[a])[:, :, None])[:, :, 0]
    absC = np.abs(C) + 1e-12
    apart = np.any(np.abs(t) - ha - np.matmul(absC, hb[:, :, None])[:, :, 0] > _SAT_MARGIN, axis=1)
    tb = np.matmul(t[:, None, :], C)[:, 0]
    apart |= np.any(np.abs(tb) - hb - np.matmul(ha[:, None, :], absC)[:, 0] > _SAT_MARGIN, axis=1)
    return apart


_STEP_K = np.arange(6)
_STEP_AXIS = np.array([2, 0, 1, 1, 1, 0])  # joint axes of the leg chain z, x, y, y, y, x
_STEP_I = np.array([[1, 2, 0][a] for a in _STEP_AXIS])
_STEP_J = np.array([[2, 0, 1][a] for a in _STEP_AXIS])


def _legs_joint_frames(
    hip_offset: np.ndarray, thigh: np.ndarray, shin: np.ndarray, q: np.ndarray
) -> np.ndarray:
    """Root-frame placements of both legs' six joint frames (after each joint's rotation).

    Args:
        hip_offset: [2, 3] hip points, root frame; thigh, shin: [2] lengths, m.
        q: [2, 6] leg joints, rad.

    Returns:
        [2, 6, 4, 4] placements, chain z, x, y, y, y, x of `ik.py` eq. (1)-(3).
    """
    c, s = np.cos(q), np.sin(q)
    steps = np.zeros((2, 6, 4, 4))
    steps[:, :, 3, 3] = 1.0
    # Rotation about axis a of joint k: 1 at (a, a), cos at (i, i), (j, j), -sin at (i, j),
    # sin at (j, i), with (i, j) the axes after a (index arrays _STEP_*: one assignment each).
    k, axis, i, j = _STEP_K, _STEP_AXIS, _STEP_I, _STEP_J
    steps[:, k, axis, axis] = 1.0
    steps[:, k, i, i] = c
    steps[:, k, j, j] = c
    steps[:, k, i, j] = -s
    steps[:, k, j, i] = s
    steps[:, 0, :3, 3] = hip_offset
    steps[:, 3, 2, 3] = -thigh
    steps[:, 4, 2, 3] = -shin
    frames = np.empty((2, 6, 4, 4))
    frames[:, 0] = steps[:, 0]
    for k in range(1, 6):
        frames[:, k] = frames[:, k - 1] @ steps[:, k]
    return frames


def foot_footprint(robot: RobotCollision, side: int) -> np.ndarray:
    """[4, 3] corners of the horizontal bounds of a foot's collision geometry (the ankle-roll
    link's, link 6), in its sole frame (z = 0).

    The foot's mesh overhangs the 0.20 x 0.13 m sole rectangle (by 1.6 cm at the heel), so a
    sole that fits its face can still put the foot into a riser beside it. The sole frame
    lies straight below the link's frame (Talos's sole joint: 0, 0, -0.107 m), so the
    link frame's x and y bounds are the sole frame's.

    Args:
        robot: the robot's collision geometries.
        side: 0 left, 1 right.
    """
    (geometry,) = np.flatnonzero((robot.leg_of == side) & (robot.leg_link == 6))
    lo = robot.local_center[geometry, :2] - robot.local_half[geometry, :2]
    hi = robot.local_center[geometry, :2] + robot.local_half[geometry, :2]
    return np.array(
        [[x, y, 0.0] for x, y in ((hi[0], hi[1]), (lo[0], hi[1]), (lo[0], lo[1]), (hi[0], lo[1]))]
    )


_ROBOT_CACHE: dict = {}


def robot_collision(talos: TalosModel) -> RobotCollision:
    """RobotCollision of `talos`, built once per model object."""
    key = id(talos)
    if key not in _ROBOT_CACHE:
        _ROBOT_CACHE[key] = RobotCollision(talos)
    return _ROBOT_CACHE[key]
