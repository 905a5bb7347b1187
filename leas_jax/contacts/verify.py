"""Verifier: re-run the five checks of docs/design.md §6 on a contact plan, from its arrays alone.

Host-only (Pinocchio, coal, hpp-centroidal-dynamics), not jittable. Independent of
the generator's code paths where it matters: forward kinematics and geometry
placements come from Pinocchio (the generator uses its own NumPy kinematics), the
support surfaces and collision objects are rebuilt from the terrain text stored in
the plan (`leas_jax.terrain.loads_terrain`), and equilibrium is hpp-centroidal-
dynamics' LP on the CoM Pinocchio computes for each saved configuration.

Checks (numbering of docs/design.md §6; 0 is the plan's own consistency):
    0. arrays: finite q and guide, unit quaternions, feet rows all-finite or all-NaN, guide
       indices in range and non-decreasing, last_valid_index / coverage consistent with the
       guide; each posture's root where the generator puts it for its guide pose (yaw of
       the pose, within max_root_offset_xy horizontally, max_single_support_offset_xy on
       one foot, and max_root_offset_z below), and
       its soles in contact within SOLE_TO_GUIDE_XY of that pose's root;
    1. each foot in contact lies flat on a support surface (sole rectangle 0.20 x 0.13 m
       inside a face whose normal is within the friction cone), within 5 mm and 3 deg;
    2. Pinocchio forward kinematics of q puts the sole frames at `feet` within 1 mm;
    3. joint limits hold; no collision with the terrain (coal), nor between the legs;
    4. static equilibrium with robustness >= 0 (hpp-centroidal-dynamics LP over the
       sole corners of the feet in contact, mu = 0.5);
    5. consecutive postures differ by at most one foot, and a foot changes placement
       only through a posture where it is in the air.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from leas_jax.contacts.robot.model import FRICTION, matrix_from_quat_xyzw

CONTACT_DIST_TOL = 0.005  # m, docs/design.md §6 check 1
CONTACT_ANGLE_TOL = math.radians(3.0)  # rad, docs/design.md §6 check 1
CONTACT_EDGE_TOL = 0.005  # m, how far a sole corner may stick out of its face (same 5 mm tolerance)
FK_TOL = 0.001  # m, docs/design.md §6 check 2
FK_ANGLE_TOL = math.radians(
    1.0
)  # rad, sole orientation from FK vs `feet` (the 1 mm of check 2 over a 0.1 m half-sole is ~0.6 deg)
JOINT_TOL = 1e-6  # rad, rounding allowance on the joint limits
SAME_PLACEMENT_TOL = 1e-6  # m (and unit-free on rotation matrices): a foot that stays in place
QUATERNION_TOL = 1e-6  # | |q| - 1 | allowed on every quaternion (the generator's are unit to ~1e-12)
ROOT_TOL = 1e-6  # m and rad, rounding allowance on the generator's root bounds
# m, horizontal distance from a sole in contact to its posture's guide root. The generator
# keeps the root within max_root_offset_xy (0.12 m) of the guide and steps a foot when it
# lags; over the plans of the four LeaS guides of tests/data and eval_ground (597 postures)
# the largest distance was 0.215 m. 0.5 m is more than twice that, within the leg's reach.
SOLE_TO_GUIDE_XY = 0.5


@dataclass
class VerificationReport:
    """Result of `verify`.

    Attributes:
        failures: list of (posture index, check number 0-5, message); posture index -1
            for plan-level problems.
        postures: number of postures checked.
    """

    failures: list = field(default_factory=list)
    postures: int = 0

    @property
    def ok(self) -> bool:
        """True when every posture passes every check."""
        return not self.failures

    def checks_failed(self) -> set[int]:
        """The set of check numbers with at least one failure."""
        return {check for _, check, _ in self.failures}

    def __str__(self) -> str:
        if self.ok:
            return f"OK: {self.postures} postures pass all checks"
        lines = [f"posture {k}: check {c}: {m}" for k, c, m in self.failures]
        return "\n".join(lines + [f"FAILED: {len(self.failures)} failed checks"])


def verify(plan, terrain=None) -> VerificationReport:
    """Re-run the docs/design.md §6 checks on every posture of a plan.

    Host-only, not jittable.

    Args:
        plan: a ContactPlan (e.g. `ContactPlan.load(path)`).
        terrain: the Terrain to check against; None (default) rebuilds it from
            `plan.terrain` (the terrain file text saved with the plan; for meshes the
            loader reads the files again and rejects any whose SHA-256 changed).
            A given terrain's meshes must have the SHA-256 the plan's text records.

    Returns:
        VerificationReport listing each (posture, check, message) that fails.
    """
    from leas_jax.contacts.plan import coverage_of
    from leas_jax.contacts.planner.surfaces import find_support, surface_arrays
    from leas_jax.contacts.robot.collision import robot_collision, terrain_collision, terrain_object_name
    from leas_jax.contacts.robot.equilibrium import HppEquilibrium, sole_corners
    from leas_jax.contacts.robot.model import load_talos
    from leas_jax.quiet import c_stdout_discarded
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.sources import mesh_hash_mismatches

    if terrain is None:
        terrain = loads_terrain(plan.terrain, source="<plan terrain>")
    mesh_mismatches = mesh_hash_mismatches(plan.terrain, terrain)
    talos = load_talos()
    robot = robot_collision(talos)
    objects = terrain_collision(terrain)
    surfaces = surface_arrays(terrain, FRICTION)
    equilibrium = HppEquilibrium(talos.mass, FRICTION)

    q_all = np.asarray(plan.q, dtype=np.float64)
    feet_all = np.asarray(plan.feet, dtype=np.float64)
    guide = np.asarray(plan.guide, dtype=np.float64)
    guide_index = np.asarray(plan.guide_index)
    report = VerificationReport(postures=len(q_all))
    fail = report.failures

    # 0. plan consistency
    fail.extend((-1, 0, message) for message in mesh_mismatches)
    if len(q_all) and (np.any(guide_index < 0) or np.any(guide_index >= len(guide))):
        fail.append((-1, 0, f"guide_index outside [0, {len(guide) - 1}]"))
    if np.any(np.diff(guide_index) < 0):
        fail.append((-1, 0, "guide_index decreases"))
    last = int(plan.last_valid_index)
    expected_last = int(guide_index[-1]) if len(guide_index) else -1
    if last != expected_last:
        fail.append((-1, 0, f"last_valid_index {last} is not the last posture's guide index {expected_last}"))
    if abs(float(plan.coverage) - coverage_of(guide, last)) > 1e-6:
        fail.append(
            (
                -1,
                0,
                f"coverage {float(plan.coverage):.6f} is not the arc-length fraction "
                f"{coverage_of(guide, last):.6f} of guide index {last}",
            )
        )

    fail.extend(_guide_consistency(q_all, feet_all, guide, guide_index))

    contact = np.zeros(feet_all.shape[:2], dtype=bool)
    for k in range(len(q_all)):
        q = q_all[k]
        if not np.all(np.isfinite(q)):
            fail.append((k, 0, "q has NaN or inf"))
            continue
        feet = feet_all[k]
        for side in (0, 1):
            finite = np.isfinite(feet[side])
            if finite.any() and not finite.all():
                fail.append((k, 0, f"{_foot(side)} row is partly NaN"))
            contact[k, side] = finite.all()
        rotations = [matrix_from_quat_xyzw(feet[side, 3:]) if contact[k, side] else None for side in (0, 1)]

        # 1. flat on a support surface
        for side in (0, 1):
            if contact[k, side]:
                index, reason = find_support(
                    terrain,
                    surfaces,
                    feet[side, :3],
                    rotations[side],
                    CONTACT_DIST_TOL,
                    CONTACT_ANGLE_TOL,
                    CONTACT_EDGE_TOL,
                )
                if index < 0:
                    fail.append((k, 1, f"{_foot(side)}: {reason}"))

        # 2. forward kinematics
        soles = talos.sole_placements(q)
        for side in (0, 1):
            if contact[k, side]:
                err = float(np.linalg.norm(soles[side, :3] - feet[side, :3]))
                rot_fk = matrix_from_quat_xyzw(soles[side, 3:])
                angle = _angle_between(rot_fk, rotations[side])
                if err > FK_TOL or angle > FK_ANGLE_TOL:
                    fail.append(
                        (
                            k,
                            2,
                            f"{_foot(side)}: FK sole is {1000 * err:.2f} mm and "
                            f"{math.degrees(angle):.2f} deg from feet",
                        )
                    )

        # 3. joint limits, collisions
        for name, value, lo, hi in talos.joint_limit_violations(q, JOINT_TOL):
            fail.append((k, 3, f"joint {name} = {value:.4f} outside [{lo:.4f}, {hi:.4f}]"))
        rot, pos = robot.placements_pinocchio(talos, q)
        for g, b in robot.terrain_contacts(rot, pos, objects, first_only=False):
            fail.append((k, 3, f"{robot.names[g]} collides with {terrain_object_name(terrain, b)}"))
        for ga, gb in robot.self_contacts(rot, pos, first_only=False):
            fail.append((k, 3, f"{robot.names[ga]} collides with {robot.names[gb]}"))

        # 4. static equilibrium
        if not contact[k].any():
            fail.append((k, 4, "no foot in contact"))
        else:
            points, normals = sole_corners(feet[contact[k]])
            equilibrium.set_contacts(points, normals)
            com = talos.com(q)
            with c_stdout_discarded():  # the LP's debug line where qpOASES fails (CLP answers)
                robustness = equilibrium.robustness(com)
            if not robustness >= 0.0:
                fail.append(
                    (
                        k,
                        4,
                        f"not in static equilibrium: robustness {robustness:.4g} < 0 "
                        f"(CoM {np.round(com, 4).tolist()}, feet in contact: "
                        f"{', '.join(_foot(s) for s in (0, 1) if contact[k, s])})",
                    )
                )

        # 5. one foot at a time, through the air
        if k > 0 and np.all(np.isfinite(q_all[k - 1])):
            changed = []
            for side in (0, 1):
                before, now = contact[k - 1, side], contact[k, side]
                if before != now:
                    changed.append(side)
                elif now and not _same_placement(feet_all[k - 1, side], feet[side]):
                    changed.append(side)
                    fail.append(
                        (k, 5, f"{_foot(side)} moves from posture {k - 1} without a posture in the air")
                    )
            if len(changed) > 1:
                fail.append((k, 5, f"both feet change between postures {k - 1} and {k}"))
    return report


def _guide_consistency(q_all, feet_all, guide, guide_index) -> list:
    """Check-0 failures tying the postures to the guide: finite guide, unit quaternions, each
    root within the generator's bounds of its guide pose, soles in contact near that pose."""
    from leas_jax.contacts.planner.generator import GeneratorConfig

    found = []
    if not np.all(np.isfinite(guide)):
        return [(-1, 0, "guide has NaN or inf")]
    config = GeneratorConfig()
    in_range = (guide_index >= 0) & (guide_index < len(guide))
    for k in range(len(q_all)):
        q = q_all[k]
        if not np.all(np.isfinite(q)):
            continue  # reported by the posture loop
        norm = float(np.linalg.norm(q[3:7]))
        if abs(norm - 1.0) > QUATERNION_TOL:
            found.append((k, 0, f"root quaternion has norm {norm:.6f}, not 1"))
            continue
        for side in (0, 1):
            row = feet_all[k, side]
            if np.all(np.isfinite(row)) and abs(float(np.linalg.norm(row[3:])) - 1.0) > QUATERNION_TOL:
                found.append(
                    (k, 0, f"{_foot(side)} quaternion has norm {float(np.linalg.norm(row[3:])):.6f}, not 1")
                )
        if not in_range[k]:
            continue
        index = int(guide_index[k])
        pose = guide[index]
        offset = float(np.hypot(*(q[:2] - pose[:2])))
        one_foot = not np.all(np.isfinite(feet_all[k, :, 0]))
        bound = config.max_single_support_offset_xy if one_foot else config.max_root_offset_xy
        drop = float(pose[2] - q[2])
        rot = matrix_from_quat_xyzw(q[3:7])
        yaw_error = abs((math.atan2(rot[1, 0], rot[0, 0]) - pose[3] + math.pi) % (2 * math.pi) - math.pi)
        tilt = float(np.hypot(rot[2, 0], rot[2, 1]))
        if (
            offset > bound + ROOT_TOL
            or not -ROOT_TOL <= drop <= config.max_root_offset_z + ROOT_TOL
            or yaw_error > ROOT_TOL
            or tilt > ROOT_TOL
        ):
            found.append(
                (
                    k,
                    0,
                    f"root is {offset:.3f} m beside, {drop:.3f} m below and {math.degrees(yaw_error):.2f} deg "
                    f"off guide pose {index} (the generator keeps it within {bound} m, "
                    f"0 to {config.max_root_offset_z} m below, at the pose's yaw, level)",
                )
            )
        for side in (0, 1):
            row = feet_all[k, side]
            if np.all(np.isfinite(row)):
                distance = float(np.hypot(*(row[:2] - pose[:2])))
                if distance > SOLE_TO_GUIDE_XY:
                    found.append(
                        (
                            k,
                            0,
                            f"{_foot(side)} is {distance:.3f} m from guide pose {index} (> {SOLE_TO_GUIDE_XY} m)",
                        )
                    )
    return found


def _foot(side: int) -> str:
    return ("left", "right")[side] + " foot"


def _angle_between(rot_a: np.ndarray, rot_b: np.ndarray) -> float:
    """Angle of the rotation rot_a^T rot_b, rad."""
    cos = (np.trace(rot_a.T @ rot_b) - 1.0) / 2.0
    return float(math.acos(min(1.0, max(-1.0, cos))))


def _same_placement(row_a: np.ndarray, row_b: np.ndarray) -> bool:
    """Whether two [7] placements are the same (positions and rotation matrices, not quaternion signs)."""
    if np.max(np.abs(row_a[:3] - row_b[:3])) > SAME_PLACEMENT_TOL:
        return False
    diff = matrix_from_quat_xyzw(row_a[3:]) - matrix_from_quat_xyzw(row_b[3:])
    return bool(np.max(np.abs(diff)) <= SAME_PLACEMENT_TOL)
