"""Contact generator: guide path -> quasi-static contact plan for Talos (RB-PRM style).

Host-only (Pinocchio, coal, hpp-centroidal-dynamics, SciPy), not jittable.

Algorithm (docs/design.md §6, after the RB-PRM contact generator of Tonneau et al., T-RO
2018, used by the paper through [7]):

1. Contact planning runs on a subsampled guide: every `stride`-th pose plus the last.
2. Initial stance: both soles at their half-sitting places under guide pose 0,
   moved onto support surfaces.
3. At each planning pose the generator first tries to keep both contacts: root on
   the guide (yaw from the guide, height from the guide, lowered by at most
   `max_root_offset_z` if a leg would be overstretched, shifted horizontally by at
   most `max_root_offset_xy` toward the support centre if needed for equilibrium),
   both legs by analytic IK, joint limits, terrain and leg collisions (coal),
   double-support equilibrium (hpp-centroidal-dynamics LP, mu = 0.5).
4. If keeping fails, a foot leaves its comfort region, or (once per pose) a foot
   lags more than the step trigger behind its nominal place, the foot that lags
   most steps: candidates are database samples (per-leg sole positions in the root
   frame) near where the foot should be `lookahead` s ahead on the guide, projected
   on nearby support surfaces (at the guide's yaw, and on narrow beams also turned to
   the beam's axis), kept when the sole rectangle lies inside the face
   polygon and nothing covers it, then ranked by distance to that target. The step
   adds a single-support posture (foot in the air, NaN row; root shifted over the
   stance sole; balanced on the stance foot alone) and a double-support posture with
   the foot placed. The other foot is tried if the most lagging one cannot step;
   steps that bring their foot nearer its target (`min_step_gain`) are tried on both
   feet before a step that does not. At most `max_steps_per_pose` steps per planning
   pose.
5. The generator stops at the first planning pose it cannot pass; `last_valid_index`
   is the guide index of the last posture, `coverage` its arc-length fraction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from leas_jax.contacts.plan import ContactPlan, coverage_of
from leas_jax.contacts.planner.surfaces import (
    SOLE_CORNERS,
    height_at,
    sole_corners_world,
    sole_inside_union,
    sole_rotation_single,
    surface_arrays,
    uncovered,
)
from leas_jax.contacts.robot.collision import robot_collision, terrain_collision
from leas_jax.contacts.robot.database import DatabaseConfig, leg_database
from leas_jax.contacts.robot.equilibrium import HppEquilibrium, flat_support_margin
from leas_jax.contacts.robot.ik import leg_ik, leg_ik_single
from leas_jax.contacts.robot.model import (
    FRICTION,
    LEFT,
    NOMINAL_ROOT_HEIGHT,
    RIGHT,
    SOLE_LENGTH,
    SOLE_WIDTH,
    load_talos,
    quat_xyzw_from_matrix_single,
)
from leas_jax.errors import UsageError

# m, how far outside the support polygon a CoM must be for `_build` to reject a flat
# stance without the equilibrium LP (far above rounding, far below any real margin)
_OUTSIDE_MARGIN = 1e-6


@dataclass(frozen=True)
class GeneratorConfig:
    """Settings of the contact generator; defaults from docs/design.md §6 and the Talos model."""

    stride: int = 5  # guide poses per planning pose, docs/design.md §6 ("every 5th pose by default")
    lookahead: float = 0.7  # s, where a moving foot should land on the guide, docs/design.md §6 (0.6-0.8 s)
    mu: float = FRICTION  # friction coefficient, docs/design.md §6 checks 1 and 4
    # m, horizontal lag of a foot behind its nominal place that makes it step. 0.07 m, not
    # 0.10: LeaS slows to ~0.06 m/s on eval_stairs and its root rises with each tread; with
    # 0.10 the trailing foot stayed a whole tread lower until the leg was overstretched
    # (4 of 60 stairs guides stopped mid-flight); with 0.07 all 60 are covered
    # (stairs_side: 51 -> 60 of 60), at ~10 % more footsteps on flat ground.
    step_trigger: float = 0.07
    step_trigger_yaw: float = 0.20  # rad, yaw lag that makes a foot step (~ pi/9 rad/s x 0.5 s x 1.15)
    # Steps that bring their foot nearer its step target come first: the horizontal gap, in
    # step triggers, cut by at least this much, or to under 1. Only when neither foot has such
    # a step may one step with less. Beside the void on eval_bridge, a guide sidling left kept
    # stepping the right foot in place (its place past the left foot was out of reach) while
    # the left foot, which could lead, never moved; both then lagged out of reach.
    # None: any step, the most lagging foot first.
    min_step_gain: float | None = 0.5
    max_foot_offset: float = 0.25  # m, comfort region: sole to its nominal place in the root frame
    # rad, comfort region in yaw; the hip-yaw joints allow 0.35 rad inward, 1.57 rad outward
    max_foot_yaw: float = 0.5
    max_steps_per_pose: int = 2  # steps per planning pose (0.5 s at the default stride and timestep)
    max_root_offset_xy: float = (
        0.12  # m, root shift off the guide to reach equilibrium (~ half the foot spacing + margin)
    )
    max_root_offset_z: float = 0.10  # m, root lowering when a leg is overstretched (stairs of 0.15 m rise)
    min_knee: float = (
        0.05  # rad, knee bend kept when lowering the root (away from the straight-leg singularity)
    )
    candidate_radius: float = 0.15  # m, database samples this close to a step target are candidates
    candidate_slab: float = 0.10  # m, samples this close (vertically) to a face are dropped on it
    candidate_grid: float = 0.01  # m, candidates closer than this are merged (one per cell)
    max_candidates: int = 12  # candidates tried per step (in rank order)
    # On a beam (a face narrower than `beam_width` across one of its edges), a sole turned
    # by at most `beam_align_yaw` to the beam's axis is a candidate too, after the one at
    # the guide's yaw at the same place. eval_bridge's 0.30 m beam leaves 2 cm beside two
    # soles side by side; at 11 degrees off its axis they need 5 cm more, and LeaS guides
    # wander that much (bridge success 8 -> 10 of 60 guides of the shipped policy). Beams
    # only: aligning soles to every face's edges cost 5 of 60 eval_stairs guides. Walking
    # along such a beam, each foot's step target also moves into its lane (`_beam_lane`).
    beam_width: float = 0.5  # m; the arena's bridges are 0.30-0.45 m wide, its stair treads 0.30 m deep
    beam_align_yaw: float = (
        0.35  # rad, the hip-yaw joint's inward limit (max_foot_yaw is 0.5); 0 disables (lanes too)
    )
    beam_drop: float = 0.05  # m, a beam's lanes need terrain this much lower this far beyond both its edges
    # m, sole rectangle kept this far inside the face polygon (docs/design.md §6's 5 mm tolerance). Two
    # soles side by side take 2 x 0.13 + feet_gap + 2 x edge_margin: with 1 cm and 2 cm that was
    # exactly the 0.30 m of eval_bridge, which no guide could cross: a centred straight guide at
    # 0.18 m/s stopped 8 cm onto it (tests/test_contacts_generator.py crosses it now)
    edge_margin: float = 0.005
    cover_tol: float = (
        0.005  # m, a sole is covered if the terrain rises more than this above it (docs/design.md §6: 5 mm)
    )
    feet_gap: float = 0.01  # m, minimal gap between the two sole rectangles (see edge_margin)
    swing_lift: float = 0.05  # m, height of a foot in the air above its last contact
    swing_clearance: float = 0.05  # m, how far out of its hip a lifted foot may be held (see `_step`)
    # m: where single support with the CoM over the stance sole's centre fails, the CoM is
    # aimed instead at the point of that sole, this far inside its edges, nearest the guide
    # root (a shorter root shift; eval_circuit's pillars). 3 cm leaves twice flat_com_margin. None: off.
    single_support_com_inset: float | None = 0.03
    min_robustness: float = (
        1.0  # hpp-centroidal-dynamics robustness kept (>= 0 is the contract; ~3 mm of CoM margin)
    )
    # m, on horizontal faces a CoM this far inside the support polygon is in equilibrium
    # without solving the LP (equilibrium.flat_support_margin); 1.5 cm is ~5 x the CoM
    # margin of min_robustness, so the shortcut never accepts what the LP would reject
    flat_com_margin: float = 0.015
    database: DatabaseConfig = field(default_factory=DatabaseConfig)


@dataclass
class ContactPosture:
    """One key posture: configuration, feet (NaN row in the air), guide index."""

    q: np.ndarray  # [39] Pinocchio configuration (root xyz + quaternion xyzw, joints)
    feet: np.ndarray  # [2, 7] world sole placements (xyz + quaternion xyzw), NaN row in the air
    guide_index: int


_Posture = ContactPosture  # the name the generator's code uses


def _axis_difference(axis_yaw, yaw):
    """Angle (rad) from `yaw` to the undirected axis `axis_yaw`, wrapped to [-pi/2, pi/2)
    (an axis has no sense). Floats or arrays."""
    return (axis_yaw - yaw + 0.5 * math.pi) % math.pi - 0.5 * math.pi


def _rotz(yaw: float) -> np.ndarray:
    """[3, 3] Rz(yaw) for one angle (scalar fast path of model.rotz)."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _placement_row(pos, rot) -> np.ndarray:
    """[7] xyz + quaternion xyzw of a placement (pos [3], rot [3, 3])."""
    return np.concatenate([pos, quat_xyzw_from_matrix_single(rot)])


class ContactGenerator:
    """Contact generator for one terrain; reuses its collision objects across guides.

    Host-only, not jittable; holds Pinocchio/coal/LP solver state, so use one per
    process or thread.

    Args:
        terrain: a leas_jax.terrain.Terrain.
        config: generator settings.
    """

    _SCREEN_CHUNK = 6  # pool candidates screened at once by _step (cost is mostly per call)

    def __init__(self, terrain, config: GeneratorConfig = GeneratorConfig()):
        self.terrain = terrain
        self.config = config
        self.talos = load_talos()
        self.robot = robot_collision(self.talos)
        self.terrain_objects = terrain_collision(terrain)
        self.surfaces = surface_arrays(terrain, config.mu)
        self.equilibrium = HppEquilibrium(self.talos.mass, config.mu)
        self.databases = (leg_database(LEFT, config.database), leg_database(RIGHT, config.database))
        legs = self.talos.legs
        self._reach = [
            math.sqrt(leg.thigh**2 + leg.shin**2 + 2 * leg.thigh * leg.shin * math.cos(config.min_knee))
            for leg in legs
        ]
        self._nominal = self.talos.nominal_sole_in_root  # [2, 3] root frame
        self._nominal_xy = [tuple(row[:2].tolist()) for row in self._nominal]
        self._beams = {}  # face index -> [A, 3] beam edges (`_beam_edges`)
        # Diagnostics: postures built, candidates that passed the cover and reach tests
        # (those screened: `_step` screens its candidates lazily).
        self.stats = {"postures_tried": 0, "candidates": 0}

    # ------------------------------------------------------------------ postures

    def _legs_ik(self, root_R, root_p, contacts) -> np.ndarray | None:
        """Leg joints [2, 6] placing each contact sole, or None (unreachable / joint limits).

        contacts: list of (side, pos [3], rot [3, 3]) world sole placements for both legs.
        """
        leg_q = np.empty((2, 6))
        for side, pos, rot in contacts:
            q = leg_ik_single(self.talos.legs[side], root_R.T @ rot, root_R.T @ (pos - root_p))
            if q is None:
                return None
            leg_q[side] = q
        return leg_q

    def _root_height(self, guide_pose, root_xy, root_R, contacts) -> float | None:
        """Root z: the guide's, lowered (<= max_root_offset_z) so that no contact leg is overstretched."""
        z = float(guide_pose[2])
        cos_yaw, sin_yaw = float(root_R[0, 0]), float(root_R[1, 0])
        for side, pos, rot in contacts:
            leg = self.talos.legs[side]
            hx, hy, hz = leg.hip_offset.tolist()
            ankle = (pos + leg.sole_depth * rot[:, 2]).tolist()
            hip_x = float(root_xy[0]) + cos_yaw * hx - sin_yaw * hy
            hip_y = float(root_xy[1]) + sin_yaw * hx + cos_yaw * hy
            horizontal = math.hypot(hip_x - ankle[0], hip_y - ankle[1])
            reach = self._reach[side]
            if horizontal >= reach:
                return None
            z = min(z, ankle[2] + math.sqrt(reach * reach - horizontal * horizontal) - hz)
        if guide_pose[2] - z > self.config.max_root_offset_z:
            return None
        return z

    def _posture(self, guide_pose, guide_index: int, contacts, air=None, com_target=None) -> _Posture | None:
        """Check and build a posture at a guide pose.

        Args:
            guide_pose: [4] (x, y, z, yaw) guide root pose, world.
            guide_index: its guide index.
            contacts: list of (side, pos, rot) soles in contact, world.
            air: None, or (side, list of (pos, rot, follows_root) placements to try for
                the foot in the air, in order: at each root offset, the first with which
                every check passes). pos [3], rot [3, 3] world; with follows_root, pos
                moves with the root's horizontal shift (the foot held `swing_clearance` out of its hip).
            com_target: [2] where the root shift should bring the CoM (x, y), or None to
                try the guide root first and shift toward the support centre only if needed.

        Returns:
            the posture, or None when no root offset gives a valid posture.
        """
        self.stats["postures_tried"] += 1
        root_R = _rotz(guide_pose[3])
        guide_xy = np.asarray(guide_pose[:2], dtype=np.float64)
        support_centre = np.mean([pos[:2] for _, pos, _ in contacts], axis=0)
        target = support_centre if com_target is None else np.asarray(com_target)
        offsets = [None] if com_target is not None else [np.zeros(2), None]
        airs = [None] if air is None else [(air[0], *option) for option in air[1]]
        for offset in offsets:
            for one_air in airs:
                built = self._build(
                    guide_pose, guide_index, root_R, guide_xy, offset, target, contacts, one_air
                )
                if built is not None:
                    return built
        return None

    def _build(self, guide_pose, guide_index, root_R, guide_xy, offset, target, contacts, air):
        """One root offset (None: shift the CoM onto `target`) and one placement of the foot in
        the air (None, or (side, pos [3], rot [3, 3], follows_root), see `_posture`); all checks.
        Returns a posture or None."""
        cfg = self.config
        talos = self.talos
        iterations = 1 if offset is not None else 3
        shift = np.zeros(2) if offset is None else offset
        for it in range(iterations):
            norm = float(np.hypot(*shift))
            if norm > cfg.max_root_offset_xy:
                shift = shift * (cfg.max_root_offset_xy / norm)
            root_xy = guide_xy + shift
            z = self._root_height(guide_pose, root_xy, root_R, contacts)
            if z is None:
                return None
            root_p = np.array([root_xy[0], root_xy[1], z])
            leg_q = self._legs_ik(root_R, root_p, contacts)
            if leg_q is None:
                return None
            if air is not None:
                side, pos, rot, follows_root = air
                if follows_root:
                    pos = pos + np.array([shift[0], shift[1], 0.0])
                solved = self._legs_ik(root_R, root_p, [(side, pos, rot)])
                if solved is None:
                    return None
                leg_q[side] = solved[side]
            q = talos.configuration(root_p, root_R, leg_q)
            com = talos.com(q)
            if offset is None and it + 1 < iterations:
                error = target - com[:2]
                if float(np.hypot(*error)) < 0.005:
                    iterations = it + 1  # converged: check this one
                else:
                    shift = shift + error
                    continue
            points = np.concatenate([pos + SOLE_CORNERS @ rot.T for _, pos, rot in contacts])
            normals = np.repeat(np.array([rot[:, 2] for _, _, rot in contacts]), 4, axis=0)
            margin = flat_support_margin(points, normals, com)
            if margin < cfg.flat_com_margin:
                # Coplanar horizontal contacts with the CoM strictly outside their hull:
                # no static equilibrium (the centre of pressure would have to be the CoM's
                # projection), the LP's robustness is < 0; rejected without the LP.
                if -math.inf < margin < -_OUTSIDE_MARGIN and cfg.min_robustness >= 0.0:
                    return None
            # Every check must pass, so their order changes no result: cheapest first
            # (terrain collision ~50 us, the LP ~300 us, self-collision ~100 us and rarely failing).
            rot, pos = self.robot.placements_fast(talos, root_R, root_p, leg_q)
            aabb = self.robot.world_aabb(rot, pos)
            if self.robot.terrain_contacts(rot, pos, self.terrain_objects, aabb=aabb):
                return None
            if margin < cfg.flat_com_margin:
                self.equilibrium.set_contacts(points, normals)
                if self.equilibrium.robustness(com) < cfg.min_robustness:
                    return None
            if self.robot.self_contacts(rot, pos, aabb=aabb):
                return None
            feet = np.full((2, 7), np.nan)  # built for an accepted posture only
            for side, sole_pos, sole_rot in contacts:
                feet[side] = _placement_row(sole_pos, sole_rot)
            return _Posture(q=q, feet=feet, guide_index=guide_index)
        return None

    # ------------------------------------------------------------------ candidates

    def _nominal_placement(self, guide_pose, side: int) -> tuple[np.ndarray, float]:
        """World (x, y, z) of a sole at its half-sitting place under a guide pose, and its yaw."""
        root_R = _rotz(guide_pose[3])
        pos = np.asarray(guide_pose[:3], dtype=np.float64) + root_R @ self._nominal[side]
        return pos, float(guide_pose[3])

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
        pos, rot = self._candidate_pool(side, guide_pose, target_pos, target_yaw, avoid)
        keep = self._screen(side, guide_pose, pos, rot)
        return pos[keep], rot[keep]

    def _first_candidate(self, side: int, guide_pose, target_pos, target_yaw: float, avoid=None):
        """`candidates(...)`'s first placement (pos [3], rot [3, 3]), or None if it has none;
        the pool is screened a few at a time (each entry passes or fails on its own)."""
        pos, rot = self._candidate_pool(side, guide_pose, target_pos, target_yaw, avoid)
        for start in range(0, len(pos), self._SCREEN_CHUNK):
            chunk = slice(start, start + self._SCREEN_CHUNK)
            keep = np.flatnonzero(self._screen(side, guide_pose, pos[chunk], rot[chunk]))
            if len(keep):
                return pos[start + keep[0]], rot[start + keep[0]]
        return None

    def _candidate_pool(self, side: int, guide_pose, target_pos, target_yaw: float, avoid=None):
        """The ranked placements of `candidates` before the cover and reach tests.

        Returns:
            (pos [M, 3], rot [M, 3, 3]), M <= 4 x max_candidates, world, in rank order.
            Each passes or fails `_screen` on its own, so screening a prefix of this
            list gives a prefix of `candidates` (what lets `_step` screen lazily).
        """
        cfg = self.config
        surfaces = self.surfaces
        db = self.databases[side]
        root_R = _rotz(guide_pose[3])
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
        # passing ones are kept, and go through the costlier tests of `_screen`.
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

    def _screen(self, side: int, guide_pose, pos, rot) -> np.ndarray:
        """[N] the cover and reach tests of `candidates` on placements pos [N, 3], rot [N, 3, 3]:
        nothing of the terrain over the sole, and reachable within the joint limits from
        the guide root or the lowest allowed root. Each entry depends on its row only."""
        cfg = self.config
        if len(pos) == 0:
            return np.zeros(0, dtype=bool)
        root_R = _rotz(guide_pose[3])
        root_p = np.asarray(guide_pose[:3], dtype=np.float64)
        corners = sole_corners_world(pos, rot)
        probe = np.concatenate([corners, pos[:, None, :]], axis=1).reshape(-1, 3)
        free = np.all(uncovered(self.terrain, probe, cfg.cover_tol).reshape(-1, 5), axis=1)
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
        self.stats["candidates"] += int(reachable.sum())
        keep = np.zeros(len(free), dtype=bool)
        keep[np.nonzero(free)[0][reachable]] = True
        return keep

    def _beam_edges(self, s: int) -> np.ndarray:
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

    def _beam_lane(self, side: int, target_pos: np.ndarray, target_yaw: float) -> np.ndarray:
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
        level) or a stair tread (one neighbour higher) is no beam: lanes there put the
        feet on a tread's far half (arena poses walked from: 3293 -> 3161 before this test).
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
            beams = self._beam_edges(s)
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
        axes = self._beam_edges(s)[:, 0]
        if len(axes) == 0 or self.config.beam_align_yaw <= 0.0:
            return [target_yaw]
        diff = _axis_difference(axes, target_yaw)
        best = float(diff[np.argmin(np.abs(diff))])
        if 1e-3 < abs(best) <= self.config.beam_align_yaw:
            return [target_yaw, target_yaw + best]
        return [target_yaw]

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

    # ------------------------------------------------------------------ walking

    def _foot_lag(self, guide_pose, side, pos, rot) -> tuple[float, float]:
        """(horizontal distance, |yaw difference|) of a sole to its nominal place under a guide pose."""
        yaw0 = float(guide_pose[3])
        c, s = math.cos(yaw0), math.sin(yaw0)
        dx, dy = float(pos[0] - guide_pose[0]), float(pos[1] - guide_pose[1])
        nx, ny = self._nominal_xy[side]
        dist = math.hypot(c * dx + s * dy - nx, -s * dx + c * dy - ny)
        yaw = math.atan2(rot[1, 0], rot[0, 0]) - yaw0
        return dist, abs((yaw + math.pi) % (2 * math.pi) - math.pi)

    def _comfortable(self, guide_pose, contacts) -> bool:
        cfg = self.config
        for side, pos, rot in contacts:
            dist, yaw = self._foot_lag(guide_pose, side, pos, rot)
            if dist > cfg.max_foot_offset or yaw > cfg.max_foot_yaw:
                return False
        return True

    def _lag_score(self, guide_pose, side, pos, rot) -> float:
        dist, yaw = self._foot_lag(guide_pose, side, pos, rot)
        return max(dist / self.config.step_trigger, yaw / self.config.step_trigger_yaw)

    def _step_gap(self, pos, target_pos) -> float:
        """How far a sole at pos [3] is from a step target, in step triggers (horizontal).

        Position only: on a narrow beam soles turn to its axis, away from the target's yaw,
        and a yaw term made every such step look like no progress."""
        return (
            math.hypot(float(pos[0] - target_pos[0]), float(pos[1] - target_pos[1]))
            / self.config.step_trigger
        )

    def _step(
        self, guide, timestep, index: int, feet, side: int, min_gain: float | None = None
    ) -> tuple[list[_Posture] | None, bool]:
        """Move foot `side` at planning index `index`.

        min_gain: None, or the least cut of the foot's gap to its step target (`_step_gap`)
        a placement must bring, unless it brings the gap under 1.

        Returns:
            ([single-support, double-support] postures, or None), and whether `min_gain`
            passed over a placement (without it the step might succeed)."""
        cfg = self.config
        pose = guide[index]
        other = 1 - side
        stance = (other, feet[other][0], feet[other][1])
        old_pos, old_rot = feet[side]
        lifted = [(old_pos + np.array([0.0, 0.0, cfg.swing_lift]), old_rot, False)]
        # Or under its hip, swing_lift above its last contact (or above the half-sitting sole
        # height where that is higher, as on a step up). The half-sitting height alone put the
        # foot 12 cm underground under a root 0.85 m above the ground, where crouched walking
        # fails otherwise (the trailing foot cannot stay flat: ankle pitch < -1.31 rad).
        nominal_pos, _ = self._nominal_placement(pose, side)
        nominal_pos[2] = max(nominal_pos[2], old_pos[2]) + cfg.swing_lift
        lifted.append((nominal_pos, _rotz(pose[3]), False))
        # Or swing_clearance farther out, following the root's shift toward the stance sole:
        # where that sole is nearer the guide's line than its nominal place, the stance
        # shin meets a foot held under its hip.
        outward = _rotz(pose[3])[:, 1] * (1.0 if side == LEFT else -1.0)
        lifted.append((nominal_pos + cfg.swing_clearance * outward, _rotz(pose[3]), True))
        single = self._posture(pose, index, [stance], air=(side, lifted), com_target=feet[other][0][:2])
        if single is None and cfg.single_support_com_inset is not None:
            # The root shift that brings the CoM over the sole's centre can put the body into
            # the terrain (an arm into a pillar beside the path); a CoM target on the sole,
            # inset from its edges, nearer the guide, needs a shorter shift.
            nearer = self._sole_point_toward(feet[other], pose[:2], cfg.single_support_com_inset)
            single = self._posture(pose, index, [stance], air=(side, lifted), com_target=nearer)
        if single is None:
            return None, False
        ahead = guide[min(index + int(round(cfg.lookahead / timestep)), len(guide) - 1)]
        target_pos, target_yaw = self._nominal_placement(ahead, side)
        target_pos = self._beam_lane(side, target_pos, target_yaw)
        # Same candidates, in the same order, as `candidates(...)[:max_candidates]`, but
        # screened a few at a time: the first or second usually gives a posture, and
        # screening all 4 x max_candidates of the pool was a quarter of a plan's time.
        pool_pos, pool_rot = self._candidate_pool(side, pose, target_pos, target_yaw, avoid=feet[other])
        needed = math.inf if min_gain is None else max(1.0, self._step_gap(old_pos, target_pos) - min_gain)
        tried, held_back = 0, False
        for start in range(0, len(pool_pos), self._SCREEN_CHUNK):
            chunk = slice(start, start + self._SCREEN_CHUNK)
            keep = self._screen(side, pose, pool_pos[chunk], pool_rot[chunk])
            for pos, rot in zip(pool_pos[chunk][keep], pool_rot[chunk][keep]):
                if tried == cfg.max_candidates:
                    return None, held_back
                tried += 1
                contacts = [stance, (side, pos, rot)]
                if self._step_gap(pos, target_pos) > needed:
                    held_back = True
                    continue
                if not self._comfortable(pose, contacts[1:]):
                    continue
                double = self._posture(pose, index, contacts)
                if double is not None:
                    feet[side] = (pos, rot)
                    return [single, double], held_back
        return None, held_back

    def _step_either(self, guide, timestep, index: int, feet, order) -> list[_Posture] | None:
        """Step one foot, trying the sides in `order`: first with `min_step_gain`, then, on
        the sides where that test passed a placement over, without it. Postures or None."""
        retry = []
        for side in order:
            stepped, held_back = self._step(guide, timestep, index, feet, side, self.config.min_step_gain)
            if stepped is not None:
                return stepped
            if held_back:
                retry.append(side)
        for side in retry:
            stepped, _ = self._step(guide, timestep, index, feet, side)
            if stepped is not None:
                return stepped
        return None

    @staticmethod
    def _sole_point_toward(foot, xy, inset: float) -> np.ndarray:
        """[2] the point of a sole's rectangle shrunk by `inset` (m) nearest to `xy` [2] (world).

        foot: (pos [3], rot [3, 3]) world sole placement; the rectangle is taken in its yaw frame.
        """
        pos, rot = foot
        yaw = math.atan2(float(rot[1, 0]), float(rot[0, 0]))
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = float(xy[0]) - float(pos[0]), float(xy[1]) - float(pos[1])
        u = min(max(c * dx + s * dy, -(SOLE_LENGTH / 2 - inset)), SOLE_LENGTH / 2 - inset)
        v = min(max(-s * dx + c * dy, -(SOLE_WIDTH / 2 - inset)), SOLE_WIDTH / 2 - inset)
        return np.array([float(pos[0]) + c * u - s * v, float(pos[1]) + s * u + c * v])

    def double_support(self, pose) -> ContactPosture | None:
        """The first posture of a plan whose guide starts at `pose`, or None.

        Host-only, not jittable. Both soles at their half-sitting places under the pose,
        moved onto support surfaces (best candidate each), then every check of a
        posture: leg IK and joint limits, equilibrium, terrain and self collision, with
        the root allowed its usual offsets (`max_root_offset_xy`, `max_root_offset_z`).

        Args:
            pose: [4] root pose (x, y, z, yaw), world frame, z = base_link height.

        Returns:
            the double-support posture (guide_index 0), or None where the generator
            cannot stand there.
        """
        start = self._initial(np.asarray(pose, dtype=np.float64).reshape(1, 4))
        return None if start is None else start[1]

    def _initial(self, guide) -> tuple[list, _Posture] | None:
        """Initial stance at guide pose 0: feet at their nominal places moved onto faces.

        The best candidate of each foot first (the right one's avoids the left one); if
        that stance fails a check (a sole across a rubble tile's edge tilts the legs
        out of balance), pairs of lower-ranked candidates, by increasing rank sum,
        up to `max_candidates` stances in all.
        """
        pose = guide[0]
        left_target, left_yaw = self._nominal_placement(pose, LEFT)
        right_target, right_yaw = self._nominal_placement(pose, RIGHT)
        left = self._first_candidate(LEFT, pose, left_target, left_yaw)
        if left is None:
            return None
        right = self._first_candidate(RIGHT, pose, right_target, right_yaw, left)
        if right is None:
            return None
        posture = self._posture(pose, 0, [(LEFT, *left), (RIGHT, *right)])
        if posture is not None:
            return [left, right], posture
        lefts = list(zip(*self.candidates(LEFT, pose, left_target, left_yaw)))
        rights = {}  # left rank -> right candidates avoiding that left sole
        pairs = sorted(
            ((i, j) for i in range(len(lefts)) for j in range(self.config.max_candidates)),
            key=lambda ij: (ij[0] + ij[1], ij[0]),
        )
        tried = 0
        for i, j in pairs[1:]:
            if i not in rights:
                rights[i] = list(zip(*self.candidates(RIGHT, pose, right_target, right_yaw, lefts[i])))
            if j >= len(rights[i]):
                continue
            if tried == self.config.max_candidates:
                break
            tried += 1
            posture = self._posture(pose, 0, [(LEFT, *lefts[i]), (RIGHT, *rights[i][j])])
            if posture is not None:
                return [lefts[i], rights[i][j]], posture
        return None

    def plan(self, guide, timestep: float) -> ContactPlan:
        """Contact plan along a guide path (see the module docstring).

        Host-only, not jittable.

        Args:
            guide: [T, 4] root poses (x, y, z, yaw), world frame, z = base_link height.
            timestep: s between guide poses.

        Returns:
            ContactPlan with the postures up to the first planning pose that fails.
        """
        guide = np.asarray(guide, dtype=np.float64)
        if guide.ndim != 2 or guide.shape[1] != 4 or len(guide) == 0:
            raise UsageError(f"guide must have shape [T, 4] with T >= 1, got {guide.shape}")
        if not np.all(np.isfinite(guide)):
            raise UsageError("guide contains NaN or inf")
        if not (timestep > 0 and math.isfinite(timestep)):
            raise UsageError(f"timestep must be a positive number of seconds, got {timestep!r}")
        cfg = self.config
        postures: list[_Posture] = []
        last_valid = -1
        start = self._initial(guide)
        if start is not None:
            feet, first = start
            postures.append(first)
            last_valid = 0
            indices = list(range(cfg.stride, len(guide), cfg.stride))
            if len(guide) > 1 and (not indices or indices[-1] != len(guide) - 1):
                indices.append(len(guide) - 1)
            for index in indices:
                added = self._advance(guide, timestep, index, feet)
                if added is None:
                    break
                postures.extend(added)
                last_valid = index
        return self._make_plan(guide, timestep, postures, last_valid)

    def _advance(self, guide, timestep, index: int, feet) -> list[_Posture] | None:
        """Postures that bring the robot to planning pose `index` (mutates `feet`), or None."""
        cfg = self.config
        pose = guide[index]

        def stance():
            return [(side, feet[side][0], feet[side][1]) for side in (LEFT, RIGHT)]

        def scores():
            return [self._lag_score(pose, side, *feet[side]) for side in (LEFT, RIGHT)]

        # The posture keeping both contacts is built only when it is used: here if no foot
        # lags, else after the steps, if none was possible (`_step` changes `feet` only when
        # it succeeds, so `stance()` is then still the one of this point).
        comfortable = self._comfortable(pose, stance())
        keep = None
        if comfortable and max(scores()) <= 1.0:
            keep = self._posture(pose, index, stance())
            if keep is not None:
                return [keep]
            comfortable = False  # built and failed: not again below
        added: list[_Posture] = []
        for _ in range(cfg.max_steps_per_pose):
            lag = scores()
            stepped = self._step_either(
                guide, timestep, index, feet, sorted((LEFT, RIGHT), key=lambda s: -lag[s])
            )
            if stepped is None:
                break
            added.extend(stepped)
            if self._comfortable(pose, stance()):
                return added  # its last double-support posture stands at this pose
        if not added and comfortable:
            keep = self._posture(pose, index, stance())
        if not added and keep is not None:
            return [keep]  # no step possible but the stance still holds: step later
        return None

    def _make_plan(self, guide, timestep, postures, last_valid) -> ContactPlan:
        if postures:
            q = np.stack([p.q for p in postures])
            feet = np.stack([p.feet for p in postures])
            guide_index = np.array([p.guide_index for p in postures], dtype=np.int64)
        else:
            q, feet, guide_index = np.zeros((0, 39)), np.zeros((0, 2, 7)), np.zeros(0, dtype=np.int64)
        return ContactPlan(
            q=q,
            feet=feet,
            guide_index=guide_index,
            last_valid_index=last_valid,
            coverage=coverage_of(guide, last_valid),
            terrain=self.terrain.text,
            guide=guide,
            timestep=timestep,
        )


_GENERATORS: dict = {}


def plan_contacts(
    terrain, guide, timestep: float, config: GeneratorConfig = GeneratorConfig()
) -> ContactPlan:
    """Contact plan of a guide path on a terrain (docs/design.md §6).

    Host-only, not jittable. Reuses one ContactGenerator per (terrain object, config)
    in the process (the latest one only), so repeated calls on one terrain share its
    collision objects.

    Args:
        terrain: a leas_jax.terrain.Terrain.
        guide: [T, 4] root poses (x, y, z, yaw), world frame, z = base_link height
            (NOMINAL_ROOT_HEIGHT above the ground for standing on flat ground).
        timestep: s between guide poses.
        config: generator settings.

    Returns:
        ContactPlan.
    """
    return _generator(terrain, config).plan(guide, timestep)


def _generator(terrain, config: GeneratorConfig) -> ContactGenerator:
    """The process's ContactGenerator for (terrain object, config): the latest one is kept."""
    key = (id(terrain), config)
    generator = _GENERATORS.get("latest")
    if generator is None or generator[0] != key or generator[1].terrain is not terrain:
        generator = (key, ContactGenerator(terrain, config))
        _GENERATORS["latest"] = generator
    return generator[1]


def double_support_posture(
    terrain, pose, config: GeneratorConfig = GeneratorConfig()
) -> ContactPosture | None:
    """Balanced, collision-free double-support posture of Talos at a root pose, or None.

    Host-only, not jittable. What the generator does for the first posture of a plan
    (`ContactGenerator.double_support`); the ground truth the reachability condition
    is calibrated against (benchmarks/reachability_calibration.py). Reuses the
    process's generator like `plan_contacts`.

    Args:
        terrain: a leas_jax.terrain.Terrain.
        pose: [4] root pose (x, y, z, yaw), world frame, z = base_link height.
        config: generator settings.
    """
    return _generator(terrain, config).double_support(pose)


__all__ = [
    "ContactGenerator",
    "ContactPosture",
    "GeneratorConfig",
    "NOMINAL_ROOT_HEIGHT",
    "double_support_posture",
    "plan_contacts",
]
