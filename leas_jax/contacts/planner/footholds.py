"""Footholds: ranked sole placements for one foot near a step target (host-only, not jittable).

The candidate stage of the generator (HPP's contact generation from limb sample
databases): database samples (per-leg sole positions in the root frame) near the
target, projected vertically on nearby support surfaces at the guide's yaw (and, on a
narrow beam, also turned to the beam's axis), kept when the sole rectangle lies inside
the face polygon (or its coplanar group), away from the other sole, uncovered by the
terrain and reachable by the leg, ranked by horizontal distance to the target
(docs/design.md §6).
"""

from __future__ import annotations

import math

import numpy as np

from leas_jax.contacts.planner.config import GeneratorConfig
from leas_jax.contacts.planner.projection import rotz
from leas_jax.contacts.planner.surfaces import (
    height_at,
    sole_corners_world,
    sole_inside_union,
    sole_rotation_single,
    uncovered,
)
from leas_jax.contacts.robot.collision import foot_footprint, robot_collision
from leas_jax.contacts.robot.ik import leg_ik
from leas_jax.contacts.robot.model import LEFT, RIGHT, SOLE_LENGTH, SOLE_WIDTH

SCREEN_CHUNK = 6  # pool candidates screened at once (the cost is mostly per call)
RISE_SAMPLING = 0.04  # m between terrain samples on a swing's path (`Footholds.rise`): 2 raster cells


def _axis_difference(axis_yaw, yaw):
    """Angle (rad) from `yaw` to the undirected axis `axis_yaw`, wrapped to [-pi/2, pi/2)
    (an axis has no sense). Floats or arrays."""
    return (axis_yaw - yaw + 0.5 * math.pi) % math.pi - 0.5 * math.pi


class Footholds:
    """Sole placements on one terrain's support surfaces, for both legs.

    Args:
        terrain: a leas_jax.terrain.Terrain.
        talos: the loaded Talos model (legs and nominal soles).
        surfaces: the terrain's support surfaces (`surfaces.surface_arrays`).
        databases: (left, right) leg sample databases (`robot.database.leg_database`).
        config: generator settings.
    """

    def __init__(self, terrain, talos, surfaces, databases, config: GeneratorConfig):
        self.terrain = terrain
        self.talos = talos
        self.surfaces = surfaces
        self.databases = databases
        self.config = config
        self._nominal = talos.nominal_sole_in_root  # [2, 3] root frame
        robot = robot_collision(talos)
        self._footprint = [foot_footprint(robot, side) for side in (LEFT, RIGHT)]  # [4, 3] sole frame
        self._beams = {}  # face index -> [A, 3] beam edges (`beam_edges`)

    def nominal_placement(self, guide_pose, side: int) -> tuple[np.ndarray, float]:
        """World (x, y, z) of a sole at its half-sitting place under a guide pose, and its yaw."""
        root_R = rotz(guide_pose[3])
        pos = np.asarray(guide_pose[:3], dtype=np.float64) + root_R @ self._nominal[side]
        return pos, float(guide_pose[3])

    def rise(self, from_pos, to_pos) -> float:
        """m, how far the terrain on the segment from_pos -> to_pos ([3] world; sampled every
        `RISE_SAMPLING` m, both ends included, through a sole's half length beyond to_pos)
        rises above from_pos: a stair riser or a block a foot swinging along it passes."""
        start = np.asarray(from_pos[:2], dtype=np.float64)
        delta = np.asarray(to_pos[:2], dtype=np.float64) - start
        length = math.hypot(float(delta[0]), float(delta[1]))
        reach = length + 0.5 * SOLE_LENGTH if length > 0.0 else 0.0
        count = max(2, int(math.ceil(reach / RISE_SAMPLING)) + 1)
        along = np.linspace(0.0, reach / max(length, 1e-12), count)
        tops = height_at(self.terrain, start + along[:, None] * delta)
        return float(tops.max() - from_pos[2])

    def candidates(self, side: int, guide_pose, target_pos, target_yaw: float, avoid=None):
        """Ranked sole placements for one foot near a target (vectorised).

        Host-only, not jittable.

        Args:
            side: 0 left, 1 right.
            guide_pose: [4] root pose the leg reaches from, world.
            target_pos: [3] where the sole should be, world (z: guess, the faces decide).
            target_yaw: heading of the sole, rad.
            avoid: None or (pos [3], rot [3, 3]) of the other sole, not to be overlapped.

        Returns:
            (pos [N, 3], rot [N, 3, 3]) world sole placements sorted by horizontal
            distance to the target: the target's vertical projection on each nearby
            face, and the database samples within `candidate_radius` of it horizontally
            and `candidate_slab` vertically, dropped vertically on the face; the 4 x max_candidates closest
            that pass the polygon and overlap tests go through the cover and reach tests.
        """
        pos, rot = self.candidate_pool(side, guide_pose, target_pos, target_yaw, avoid)
        keep = self.screen(side, guide_pose, pos, rot)
        return pos[keep], rot[keep]

    def first_candidate(self, side: int, guide_pose, target_pos, target_yaw: float, avoid=None):
        """`candidates(...)`'s first placement (pos [3], rot [3, 3]), or None if it has none;
        the pool is screened a few at a time (each entry passes or fails on its own)."""
        pos, rot = self.candidate_pool(side, guide_pose, target_pos, target_yaw, avoid)
        for start in range(0, len(pos), SCREEN_CHUNK):
            chunk = slice(start, start + SCREEN_CHUNK)
            keep = np.flatnonzero(self.screen(side, guide_pose, pos[chunk], rot[chunk]))
            if len(keep):
                return pos[start + keep[0]], rot[start + keep[0]]
        return None

    def candidate_pool(self, side: int, guide_pose, target_pos, target_yaw: float, avoid=None):
        """The ranked placements of `candidates` before the cover and reach tests.

        Returns:
            (pos [M, 3], rot [M, 3, 3]), M <= 4 x max_candidates, world, in rank order.
            Each passes or fails `screen` on its own, so screening a prefix of this
            list gives a prefix of `candidates` (what lets `walking.Walking.step` screen lazily).
        """
        cfg = self.config
        surfaces = self.surfaces
        db = self.databases[side]
        root_R = rotz(guide_pose[3])
        root_p = np.asarray(guide_pose[:3], dtype=np.float64)
        target_pos = np.asarray(target_pos, dtype=np.float64)
        empty = np.zeros((0, 3)), np.zeros((0, 3, 3))
        reach = cfg.candidate_radius + 0.5 * math.hypot(SOLE_LENGTH, SOLE_WIDTH)
        near = np.nonzero(
            np.all(
                (surfaces.bbox[:, 0, :2] - reach <= target_pos[:2])
                & (surfaces.bbox[:, 1, :2] + reach >= target_pos[:2]),
                axis=1,
            )
        )[0]
        points, pending, owner, rotations, faces = [], [], [], [], []
        disk_xy, disk = None, None  # the samples' (x, y) test is the same for every face
        done = set()  # (coplanar group, sole yaw): its faces give the same candidates
        for s in near:
            yaws = [yaw for yaw in self._sole_yaws(s, target_yaw) if (surfaces.group[s], yaw) not in done]
            if not yaws:
                continue
            done.update((surfaces.group[s], yaw) for yaw in yaws)
            normal = surfaces.normals[s]
            # Vertical projection of the target on the face plane: itself a candidate.
            on_plane = np.array([target_pos[0], target_pos[1], surfaces.plane_height(s, target_pos[:2])])
            local = root_R.T @ (on_plane - root_p)
            xy = (float(local[0]), float(local[1]))
            if xy != disk_xy:
                disk_xy, disk = xy, db.near_disk(local, cfg.candidate_radius)
            # = db.near_column(local, cfg.candidate_radius, cfg.candidate_slab)
            idx = db.near_column_z(disk, local[2], cfg.candidate_slab)
            world = np.vstack([on_plane, root_p + db.positions[idx] @ root_R.T])
            # Database samples in a vertical column about the target, dropped vertically
            # on the face (reachability is re-checked exactly by IK below).
            world[:, 2] = surfaces.plane_height(s, world[:, :2])
            grouped = len(surfaces.members[surfaces.group[s]]) > 1
            if not grouped:
                yaws = yaws + self._turned_yaws(s, world, normal, yaws, target_yaw, done)
            for yaw in yaws:
                rot = sole_rotation_single(normal, yaw)
                inside = self._inside_face(s, world, rot)
                # Outside face s alone, a sole may still lie inside its coplanar group's
                # union: tested below, lazily (costlier), on the closest ones only.
                keep = np.ones(len(world), dtype=bool) if grouped else inside
                points.append(world[keep])
                pending.append(~inside[keep])
                owner.append(np.full(int(keep.sum()), len(rotations)))
                rotations.append(rot)
                faces.append(s)
        if not points:
            return empty
        pos = np.concatenate(points)
        pending = np.concatenate(pending)
        owner = np.concatenate(owner)  # index into `rotations` and `faces`: one per (group, sole yaw)
        # Stable: at equal distances the guide's yaw comes before the beam's (appended after it).
        order = np.argsort(np.hypot(pos[:, 0] - target_pos[0], pos[:, 1] - target_pos[1]), kind="stable")
        pos, owner, pending = pos[order], owner[order], pending[order]
        # One candidate per grid cell, group and sole yaw (database samples cluster), the
        # closest to the target.
        cells = np.round((pos[:, :2] - target_pos[:2]) / cfg.candidate_grid).astype(np.int64) + 1000
        key = (cells[:, 0] * 2000 + cells[:, 1]) * (len(rotations) + 1) + owner
        _, first = np.unique(key, return_index=True)
        keep = np.sort(first)
        pos, owner, pending = pos[keep], owner[keep], pending[keep]
        rot = np.stack(rotations)[owner]
        # Row-wise tests (union, overlap), on a prefix first: only the closest `limit`
        # passing ones are kept, and go through the costlier tests of `screen`.
        limit = 4 * cfg.max_candidates
        ok = np.zeros(len(pos), dtype=bool)
        start = 0
        while start < len(pos) and int(ok.sum()) < limit:
            stop = min(len(pos), start + 2 * limit)
            passed = ~pending[start:stop]
            for k in np.unique(owner[start:stop][~passed]):
                rows = np.flatnonzero(pending[start:stop] & (owner[start:stop] == k))
                passed[rows] = self._inside_group(faces[k], pos[start + rows], rotations[k])
            if avoid is not None:
                passed &= ~self._overlaps(pos[start:stop], rot[start:stop], *avoid)
            ok[start:stop] = passed
            start = stop
        ok[np.cumsum(ok) > limit] = False
        return pos[ok], rot[ok]

    def screen(self, side: int, guide_pose, pos, rot) -> np.ndarray:
        """[N] the cover and reach tests of `candidates` on placements pos [N, 3], rot [N, 3, 3]:
        nothing of the terrain over the sole or the foot's footprint
        (`collision.foot_footprint`), and reachable within the joint limits from the guide
        root or the lowest allowed root. Each entry depends on its row only."""
        cfg = self.config
        if len(pos) == 0:
            return np.zeros(0, dtype=bool)
        root_R = rotz(guide_pose[3])
        root_p = np.asarray(guide_pose[:3], dtype=np.float64)
        # The sole's corners and centre, and the corners of the foot's footprint, which
        # overhangs the sole: nothing of the terrain may rise over any of them.
        footprint = pos[:, None, :] + np.einsum("nij,cj->nci", rot, self._footprint[side])
        probe = np.concatenate([sole_corners_world(pos, rot), pos[:, None, :], footprint], axis=1)
        free = np.all(
            uncovered(self.terrain, probe.reshape(-1, 3), cfg.cover_tol).reshape(len(pos), -1), axis=1
        )
        pos, rot = pos[free], rot[free]
        leg = self.talos.legs[side]
        local_rot = np.einsum("ji,njk->nik", root_R, rot)
        # Both root heights (guide, lowest allowed) in one call: leg_ik is row-wise.
        local_pos = [
            (pos - (root_p - np.array([0.0, 0.0, dz]))) @ root_R for dz in (0.0, cfg.max_root_offset_z)
        ]
        q, within = leg_ik(leg, np.concatenate([local_rot, local_rot]), np.concatenate(local_pos))
        ok = within & np.all((q >= leg.lower) & (q <= leg.upper), axis=1)
        reachable = ok[: len(pos)] | ok[len(pos) :]
        keep = np.zeros(len(free), dtype=bool)
        keep[np.nonzero(free)[0][reachable]] = True
        return keep

    def beam_edges(self, s: int) -> np.ndarray:
        """[A, 3] the edges face s is narrower than `beam_width` across: (axis yaw (rad), lo, hi),
        lo and hi bounding the face (m, world) along the axis's left normal (-sin, cos)(yaw)."""
        if s not in self._beams:
            verts = self.surfaces.surfaces[s].vertices
            rows = []
            for edge in np.roll(verts, -1, axis=0) - verts:
                axis = edge[:2] / max(math.hypot(edge[0], edge[1]), 1e-12)
                across = verts[:, :2] @ np.array([-axis[1], axis[0]])
                if np.ptp(across) < self.config.beam_width:
                    rows.append((math.atan2(axis[1], axis[0]), across.min(), across.max()))
            self._beams[s] = np.array(rows, dtype=np.float64).reshape(-1, 3)
        return self._beams[s]

    def beam_lane(self, side: int, target_pos: np.ndarray, target_yaw: float) -> np.ndarray:
        """A step target [3] (world) moved across a beam walked along into its side's lane.

        On a beam (a face narrower than `beam_width`) whose axis is within `beam_align_yaw`
        of the target yaw, the sole's centre is kept between SOLE_WIDTH / 2 + feet_gap / 2
        from the beam's centre line (room for the other sole) and SOLE_WIDTH / 2 +
        edge_margin from its edge, on the foot's side. A guide 4 cm off eval_bridge's 0.30 m
        centre line put the left sole on its nominal place, 4 cm left of the line, where
        the right one no longer fit beside it; with lanes, both feet stay centred and the
        root's balancing shift absorbs the guide's offset. A beam here drops on both
        sides: the terrain `beam_drop` beyond each of its edges, across from the target,
        is at least `beam_drop` lower. A narrow box of flat ground (its neighbours on a
        level) or a stair tread (one neighbour higher) is no beam: lanes there would put
        the feet on a tread's far half (test_beam_lanes_only_where_the_beam_drops_on_both_sides).
        Faces too narrow for two soles, and other faces, leave the target as it is.
        """
        if self.config.beam_align_yaw <= 0.0:
            return target_pos
        cfg, surfaces = self.config, self.surfaces
        xy = np.asarray(target_pos[:2], dtype=np.float64)
        inner = 0.5 * SOLE_WIDTH + 0.5 * cfg.feet_gap
        over = np.nonzero(np.all((surfaces.bbox[:, 0, :2] <= xy) & (surfaces.bbox[:, 1, :2] >= xy), axis=1))[
            0
        ]
        for s in over:
            beams = self.beam_edges(s)
            if len(beams) == 0 or not surfaces.inside(s, target_pos):
                continue
            for yaw, lo, hi in beams:
                along = math.cos(yaw - target_yaw)  # > 0: the axis points along the heading
                diff = _axis_difference(yaw, target_yaw)
                outer = 0.5 * (hi - lo) - 0.5 * SOLE_WIDTH - cfg.edge_margin
                if abs(diff) > cfg.beam_align_yaw or outer < inner:
                    continue
                normal = np.array([-math.sin(yaw), math.cos(yaw)])
                across = float(xy @ normal)
                beside = xy + np.outer(
                    [lo - cfg.beam_drop - across, hi + cfg.beam_drop - across], normal
                )  # [2, 2]
                if np.any(height_at(self.terrain, beside) > surfaces.plane_height(s, xy) - cfg.beam_drop):
                    continue
                sign = (1.0 if along > 0 else -1.0) * (
                    1.0 if side == LEFT else -1.0
                )  # the foot's side of the line
                offset = sign * (across - 0.5 * (lo + hi))
                moved = np.array(target_pos, dtype=np.float64)
                moved[:2] += (min(max(offset, inner), outer) - offset) * sign * normal
                return moved
        return target_pos

    def _sole_yaws(self, s: int, target_yaw: float) -> list[float]:
        """Sole yaws (rad) tried on face s: the target's, then the axis of the beam the face
        is (see `beam_width`) closest to it, when they differ by 1 mrad to `beam_align_yaw`."""
        axes = self.beam_edges(s)[:, 0]
        if len(axes) == 0 or self.config.beam_align_yaw <= 0.0:
            return [target_yaw]
        diff = _axis_difference(axes, target_yaw)
        best = float(diff[np.argmin(np.abs(diff))])
        if 1e-3 < abs(best) <= self.config.beam_align_yaw:
            return [target_yaw, target_yaw + best]
        return [target_yaw]

    def _turned_yaws(
        self, s: int, world: np.ndarray, normal, yaws: list, target_yaw: float, done: set
    ) -> list:
        """Sole yaws (rad) to try on face s beyond `yaws`, where none of those fits a sole at any
        of the candidate centres world [N, 3]: each way, the smallest of `sole_turns` off
        `target_yaw` at which one does (`sole_turns`); marked in `done` with the face's group."""
        turns = self.config.sole_turns
        if not turns or any(
            self._inside_face(s, world, sole_rotation_single(normal, yaw)).any() for yaw in yaws
        ):
            return []
        found = []
        for sign in (1.0, -1.0):
            for turn in turns:
                yaw = target_yaw + sign * turn
                if (self.surfaces.group[s], yaw) in done:
                    break
                if self._inside_face(s, world, sole_rotation_single(normal, yaw)).any():
                    found.append(yaw)
                    break
        done.update((self.surfaces.group[s], yaw) for yaw in found)
        return found

    def _inside_face(self, s: int, centres: np.ndarray, rot: np.ndarray) -> np.ndarray:
        """[N] whether soles with centres [N, 3] on face s and orientation rot [3, 3] lie
        inside its polygon, `edge_margin` from the edges.

        The rectangle is inside the convex polygon iff its centre is inside the polygon
        shrunk, edge by edge, by the rectangle's half-extent along the edge's inward
        normal m: |m . x_sole| L/2 + |m . y_sole| W/2 (one matrix product for all centres).
        """
        inward, offsets = self.surfaces.edges[s]
        extent = np.abs(inward @ rot[:, 0]) * SOLE_LENGTH / 2 + np.abs(inward @ rot[:, 1]) * SOLE_WIDTH / 2
        bound = offsets + extent + self.config.edge_margin
        return np.all(centres @ inward.T >= bound, axis=1)

    def _inside_group(self, s: int, centres: np.ndarray, rot: np.ndarray) -> np.ndarray:
        """[N] whether soles with centres [N, 3] on face s and orientation rot [3, 3] lie inside
        the union of its coplanar group (`surfaces.sole_inside_union`), `edge_margin` from the
        union's edges, tested against the group's faces near them."""
        members = self.surfaces.members[self.surfaces.group[s]]
        reach = 0.5 * math.hypot(SOLE_LENGTH, SOLE_WIDTH) + self.config.edge_margin
        lo, hi = centres[:, :2].min(axis=0) - reach, centres[:, :2].max(axis=0) + reach
        box = self.surfaces.bbox[members]
        near = members[np.all((box[:, 0, :2] <= hi) & (box[:, 1, :2] >= lo), axis=1)]
        return sole_inside_union(self.surfaces, near, centres, rot, self.config.edge_margin)

    def _overlaps(self, pos, rot, other_pos, other_rot) -> np.ndarray:
        """[N] whether sole rectangles (pos [N,3], rot [N,3,3]) come within feet_gap of another sole.

        Separating-axis test of the rectangles projected on the horizontal plane, grown
        by feet_gap / 2 each.
        """
        hx, hy = SOLE_LENGTH / 2 + self.config.feet_gap / 2, SOLE_WIDTH / 2 + self.config.feet_gap / 2
        # Columns of the projected axes as [N] arrays (a: candidates, b: the other sole);
        # written out component by component: the einsum form cost ~0.2 ms per call.
        ax0, ay0, ax1, ay1 = rot[:, 0, 0], rot[:, 1, 0], rot[:, 0, 1], rot[:, 1, 1]
        bx0, by0, bx1, by1 = (
            np.full(len(pos), float(v))
            for v in (other_rot[0, 0], other_rot[1, 0], other_rot[0, 1], other_rot[1, 1])
        )
        dx, dy = other_pos[0] - pos[:, 0], other_pos[1] - pos[:, 1]
        separated = np.zeros(len(pos), dtype=bool)
        for ux, uy in ((ax0, ay0), (ax1, ay1), (bx0, by0), (bx1, by1)):
            norm = np.sqrt(ux * ux + uy * uy)
            ux, uy = ux / norm, uy / norm
            ra = np.abs(ux * ax0 + uy * ay0) * hx + np.abs(ux * ax1 + uy * ay1) * hy
            rb = np.abs(ux * bx0 + uy * by0) * hx + np.abs(ux * bx1 + uy * by1) * hy
            separated |= np.abs(ux * dx + uy * dy) > ra + rb
        return ~separated
