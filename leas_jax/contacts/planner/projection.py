"""Posture projection: contacts and a guide root pose -> a checked whole-body posture.

The stage every other stage of the generator calls (HPP's "projection" of a state onto
its contacts): the root follows the guide (yaw and height from it, lowered by at most
`max_root_offset_z` if a leg would be overstretched, shifted horizontally by at most
`max_root_offset_xy`, or `max_single_support_offset_xy` on one foot, to bring the CoM
over the support, or held back along the heading where a knee meets a riser it steps up,
`step_up_root_shifts`), the legs reach their soles by
analytic IK within the joint limits, the upper body holds the first of
`GeneratorConfig.upper_bodies` whose arms miss the terrain, and the posture must be free
of terrain and self collision (coal) and in static equilibrium (hpp-centroidal-dynamics
LP, docs/design.md §6).

Host-only (Pinocchio, coal, hpp-centroidal-dynamics), not jittable.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass

import numpy as np

from leas_jax.contacts.planner.config import GeneratorConfig
from leas_jax.contacts.planner.surfaces import SOLE_CORNERS
from leas_jax.contacts.robot.collision import robot_collision, terrain_collision
from leas_jax.contacts.robot.equilibrium import HppEquilibrium, flat_support_margin
from leas_jax.contacts.robot.ik import leg_ik_single
from leas_jax.contacts.robot.model import quat_xyzw_from_matrix_single

# m, how far outside the support polygon a CoM must be for `_build` to reject a flat
# stance without the equilibrium LP (far above rounding, far below any real margin)
_OUTSIDE_MARGIN = 1e-6


@dataclass
class ContactPosture:
    """One key posture: configuration, feet (NaN row in the air), guide index."""

    q: np.ndarray  # [39] Pinocchio configuration (root xyz + quaternion xyzw, joints)
    feet: np.ndarray  # [2, 7] world sole placements (xyz + quaternion xyzw), NaN row in the air
    guide_index: int


def rotz(yaw: float) -> np.ndarray:
    """[3, 3] Rz(yaw) for one angle (scalar fast path of model.rotz)."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def arm_clearance_offsets(root_R: np.ndarray, distances) -> list[np.ndarray]:
    """World [2] root offsets sideways of the heading (root frame +-y) by each of `distances`
    (m), nearest first, left before right."""
    left = root_R[:2, 1]
    return [sign * d * left for d in sorted(distances) for sign in (1.0, -1.0)]


def placement_row(pos, rot) -> np.ndarray:
    """[7] xyz + quaternion xyzw of a placement (pos [3], rot [3, 3])."""
    return np.concatenate([pos, quat_xyzw_from_matrix_single(rot)])


class PostureProjection:
    """Builds and checks postures of Talos on one terrain; holds its collision and LP state.

    Host-only, not jittable; one per process or thread.

    Args:
        terrain: a leas_jax.terrain.Terrain.
        talos: the loaded Talos model (`robot.model.load_talos`).
        config: generator settings.
    """

    def __init__(self, terrain, talos, config: GeneratorConfig):
        self.config = config
        self.talos = talos
        # None, or a Counter of the checks that rejected postures, by `rejection_name`
        # (what `ContactGenerator.stop_reasons` reads); counting is off by default.
        self.rejections: Counter | None = None
        self.robot = robot_collision(talos)
        self.terrain_objects = terrain_collision(terrain)
        self.equilibrium = HppEquilibrium(talos.mass, config.mu)
        self._reach = [
            math.sqrt(leg.thigh**2 + leg.shin**2 + 2 * leg.thigh * leg.shin * math.cos(config.min_knee))
            for leg in talos.legs
        ]

    def count_rejection(self, check: str, geometry: int | None = None) -> None:
        """Count one rejected posture under `check` (with the body part for a collision)."""
        if self.rejections is not None:
            part = "" if geometry is None else f": {self.robot.parts[geometry]}"
            self.rejections[check + part] += 1

    def legs_ik(self, root_R, root_p, contacts) -> np.ndarray | None:
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

    def root_height(self, guide_pose, root_xy, root_R, contacts) -> float | None:
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

    def posture(
        self, guide_pose, guide_index: int, contacts, air=None, com_target=None
    ) -> ContactPosture | None:
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
        root_R = rotz(guide_pose[3])
        guide_xy = np.asarray(guide_pose[:2], dtype=np.float64)
        support_centre = np.mean([pos[:2] for _, pos, _ in contacts], axis=0)
        target = support_centre if com_target is None else np.asarray(com_target)
        offsets = [None] if com_target is not None else [np.zeros(2), None]
        airs = [None] if air is None else [(air[0], *option) for option in air[1]]
        # Each upper body is a fallback for the one before: tried only where an arm or gripper
        # of that one met the terrain (another moves only the arms: any other check fails the
        # same way). Where the first succeeds the posture is the one it alone would give.
        legs_hit = False
        for upper in self.config.upper_bodies:
            arms_hit = False
            for offset in offsets:
                for one_air in airs:
                    built, hit = self._build(
                        guide_pose, guide_index, root_R, guide_xy, offset, target, contacts, one_air, upper
                    )
                    if built is not None:
                        return built
                    arms_hit |= hit == "arm"
                    legs_hit |= hit == "leg"
            if not arms_hit:
                if legs_hit and air is None:
                    return self._held_back(guide_pose, guide_index, root_R, guide_xy, target, contacts, upper)
                return None
        # The last upper body's arm still meets the terrain: the root steps sideways off the
        # guide, to either side (`arm_clearance_shifts`, within the usual root bounds).
        for offset in arm_clearance_offsets(root_R, self.config.arm_clearance_shifts):
            for one_air in airs:
                built, _ = self._build(
                    guide_pose, guide_index, root_R, guide_xy, offset, target, contacts, one_air, upper
                )
                if built is not None:
                    return built
        return None

    def _held_back(self, guide_pose, guide_index, root_R, guide_xy, target, contacts, upper):
        """A stepping-up double-support posture with the root held back along the heading by
        each of `step_up_root_shifts` in turn (nearest first; within `max_root_offset_xy`), or
        None. Only where one sole is more than `swing_rise` above the other and ahead of it
        along the heading (a foot on a riser's tread, the other on the ground before it), after
        a leg met the terrain at the root's usual places (`posture`).

        Talos's knees bend forward: with the root 1 m over the ground and the hip over or ahead
        of the ankle, the knee joint is 0.16-0.2 m ahead of the hip and about 0.4 m up, the
        thigh's mesh down to 0.28 m. With the lower sole near a riser's foot and the root over
        the support, that mesh meets the edge of a riser about as high, and straight guides up
        0.29-0.34 m steps stopped there while lower and higher ones passed
        (docs/results/2026-12-06-generator-steps). The root held back over the lower sole, as a
        person's hips stay back until the weight goes onto the upper foot, takes the knee back
        with it."""
        cfg = self.config
        if len(contacts) != 2:
            return None
        (_, low, _), (_, high, _) = sorted(contacts, key=lambda contact: float(contact[1][2]))
        heading = root_R[:2, 0]
        if float(high[2] - low[2]) <= cfg.swing_rise or float((high[:2] - low[:2]) @ heading) <= 0.0:
            return None  # soles level, or the higher one behind: no riser ahead of the lower one
        back = -heading
        for distance in cfg.step_up_root_shifts:
            built, _ = self._build(
                guide_pose, guide_index, root_R, guide_xy, distance * back, target, contacts, None, upper
            )
            if built is not None:
                return built
        return None

    def _build(self, guide_pose, guide_index, root_R, guide_xy, offset, target, contacts, air, upper):
        """One root offset (None: shift the CoM onto `target`), one placement of the foot in
        the air (None, or (side, pos [3], rot [3, 3], follows_root), see `posture`) and one
        upper-body posture (a key of `talos.upper_refs`); all checks.

        Returns:
            (the posture or None, the part of Talos that met the terrain where that is why it
            failed ("arm", "leg", "trunk"; `robot.collision.body_part`), else None)."""
        cfg = self.config
        talos = self.talos
        iterations = 1 if offset is not None else 3
        shift = np.zeros(2) if offset is None else offset
        bound = cfg.max_root_offset_xy if air is None else cfg.max_single_support_offset_xy
        for it in range(iterations):
            norm = float(np.hypot(*shift))
            if norm > bound:
                shift = shift * (bound / norm)
            root_xy = guide_xy + shift
            z = self.root_height(guide_pose, root_xy, root_R, contacts)
            if z is None:
                self.count_rejection("root height")
                return None, None
            root_p = np.array([root_xy[0], root_xy[1], z])
            leg_q = self.legs_ik(root_R, root_p, contacts)
            if leg_q is None:
                self.count_rejection("leg IK")
                return None, None
            if air is not None:
                side, pos, rot, follows_root = air
                if follows_root:
                    pos = pos + np.array([shift[0], shift[1], 0.0])
                solved = self.legs_ik(root_R, root_p, [(side, pos, rot)])
                if solved is None:
                    self.count_rejection("leg IK")
                    return None, None
                leg_q[side] = solved[side]
            q = talos.configuration(root_p, root_R, leg_q, upper)
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
                    self.count_rejection("equilibrium")
                    return None, None
            # Every check must pass, so their order changes no result: cheapest first
            # (terrain collision ~50 us, the LP ~300 us, self-collision ~100 us and rarely failing).
            rot, pos = self.robot.placements_fast(talos, root_R, root_p, leg_q, upper)
            aabb = self.robot.world_aabb(rot, pos)
            hits = self.robot.terrain_contacts(rot, pos, self.terrain_objects, aabb=aabb)
            if hits:
                self.count_rejection("terrain collision", hits[0][0])
                return None, self.robot.parts[hits[0][0]]
            if margin < cfg.flat_com_margin:
                self.equilibrium.set_contacts(points, normals)
                if self.equilibrium.robustness(com) < cfg.min_robustness:
                    self.count_rejection("equilibrium")
                    return None, None
            pairs = self.robot.self_contacts(rot, pos, aabb=aabb)
            if pairs:
                self.count_rejection("self collision", pairs[0][1])
                return None, None
            feet = np.full((2, 7), np.nan)  # built for an accepted posture only
            for side, sole_pos, sole_rot in contacts:
                feet[side] = placement_row(sole_pos, sole_rot)
            return ContactPosture(q=q, feet=feet, guide_index=guide_index), None
        return None, None
