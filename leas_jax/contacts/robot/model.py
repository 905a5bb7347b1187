"""Talos model for the contact generator: Pinocchio model, leg constants, collision geometry.

Host-only (Pinocchio, coal), not jittable. The robot is the full Talos of
`example-robot-data` (`talos_reduced.urdf` + `talos.srdf`): a free-flyer root
(`base_link`), q = [x, y, z, qx, qy, qz, qw, 32 joints] (nq = 39, quaternion
**xyzw**, Pinocchio's order), upper body rigid in one of `UPPER_BODY_POSTURES`: the
half-sitting reference configuration, or the same with the arms held in.

Leg kinematics (read from the model and checked at load, see `_leg_kinematics`):
each leg is hip yaw (z), hip roll (x), hip pitch (y) meeting at one point
`hip_offset` below the root, a thigh of length `thigh` and a shin of length
`shin` along -z, ankle pitch (y) and ankle roll (x) meeting at one point, and the
sole frame `sole_depth` below the ankle along the ankle-roll link's -z with the
same orientation. This structure is what makes the leg IK analytic (`ik.py`).
"""

from __future__ import annotations

import functools
import hashlib
import math
from dataclasses import dataclass

import numpy as np

# Base-link height above the soles at the half-sitting reference configuration,
# measured from the model (`referenceConfigurations["half_sitting"]`: both soles at
# z = 0, base_link at z = 1.01927 m; `tests/test_contacts_model.py` re-measures it).
# Guide paths give the root z as this base-link height.
NOMINAL_ROOT_HEIGHT = 1.01927  # m
# Sole rectangle, docs/design.md §6 check 1 (the Talos foot sole is about 0.20 x 0.13 m),
# centred on the sole frame, long side along the sole frame x axis.
SOLE_LENGTH = 0.20  # m, along sole x
SOLE_WIDTH = 0.13  # m, along sole y
FRICTION = 0.5  # friction coefficient, docs/design.md §6 checks 1 and 4
SOLE_FRAMES = ("leg_left_sole_fix_joint", "leg_right_sole_fix_joint")
LEG_PREFIXES = ("leg_left", "leg_right")
LEFT, RIGHT = 0, 1
NQ = 39  # Talos free-flyer configuration size (7 + 32 joints)
# The foot collision meshes reach 0.4 mm below the sole plane (ankle_X_collision.stl
# spans z in [-0.1074, 0.053] in the ankle frame, sole at -0.107). A foot resting on
# a face would always "collide" with it, so the foot meshes are raised by this much
# along the sole normal for terrain collision; it equals the 5 mm contact tolerance
# of docs/design.md §6 check 1.
FOOT_CLEARANCE = 0.005  # m
# Upper-body postures a posture may hold, by name: joint values that differ from
# half-sitting (left arm; the right arm mirrors it: roll and yaw joints change sign).
# "arms_in": shoulders pitched back and rolled in against the trunk, upper arms turned
# out, elbows as bent as at half-sitting. The bounding boxes of the arms and grippers
# reach 0.55 m to the side of the root at half-sitting, 0.38 m held in (the shoulders'
# width), hands in front of the hips, still free of self-collision (7 mm from the torso
# on the SRDF's pairs; tests/test_contacts_model.py). An arm or gripper meeting a wall,
# pillar or platform edge beside the path was the most frequent reason the generator
# stopped on the shipped policy's arena guides (docs/results/2026-12-02-arms-in).
UPPER_BODY_POSTURES = {
    "half_sitting": {},
    "arms_in": {
        "arm_left_1_joint": -0.30,  # shoulder, rad (half-sitting 0.258)
        "arm_left_2_joint": 0.01,  # shoulder roll, rad (half-sitting 0.173; lower limit 0)
        "arm_left_3_joint": 0.30,  # upper-arm yaw, rad (half-sitting 0)
        "arm_left_4_joint": -0.60,  # elbow, rad (half-sitting -0.525)
    },
}
_MIRRORED_ARM_JOINTS = ("arm_left_1_joint", "arm_left_2_joint", "arm_left_3_joint")  # sign flips on the right
# Leg joint order inside a leg: hip yaw, hip roll, hip pitch, knee, ankle pitch, ankle roll.
_LEG_AXES = ("Z", "X", "Y", "Y", "Y", "X")


def rotz(yaw) -> np.ndarray:
    """Rotations about world z.

    Args:
        yaw: [...] angles, rad.

    Returns:
        [..., 3, 3] rotation matrices Rz(yaw).
    """
    yaw = np.asarray(yaw, dtype=np.float64)
    c, s = np.cos(yaw), np.sin(yaw)
    out = np.zeros(yaw.shape + (3, 3))
    out[..., 0, 0] = c
    out[..., 0, 1] = -s
    out[..., 1, 0] = s
    out[..., 1, 1] = c
    out[..., 2, 2] = 1.0
    return out


def quat_xyzw_from_matrix(rot) -> np.ndarray:
    """Unit quaternions (x, y, z, w) of rotation matrices (Shepperd's method).

    This and `matrix_from_quat_xyzw` are the only quaternion conversions of the
    contact package: Pinocchio and the plan files use the xyzw order.

    Args:
        rot: [..., 3, 3] rotation matrices.

    Returns:
        [..., 4] (x, y, z, w) with w >= 0.
    """
    rot = np.asarray(rot, dtype=np.float64)
    m = rot.reshape(-1, 3, 3)
    tr = m[:, 0, 0] + m[:, 1, 1] + m[:, 2, 2]
    # Pick the largest of 4w^2-1 = tr, 4x^2-1, 4y^2-1, 4z^2-1 for numerical stability.
    cand = np.stack([tr, m[:, 0, 0], m[:, 1, 1], m[:, 2, 2]], axis=1)
    k = np.argmax(cand, axis=1)
    q = np.empty((len(m), 4))
    for case in range(4):
        sel = k == case
        if not np.any(sel):
            continue
        r = m[sel]
        if case == 0:
            s = 2.0 * np.sqrt(1.0 + tr[sel])
            q[sel] = np.stack(
                [
                    (r[:, 2, 1] - r[:, 1, 2]) / s,
                    (r[:, 0, 2] - r[:, 2, 0]) / s,
                    (r[:, 1, 0] - r[:, 0, 1]) / s,
                    0.25 * s,
                ],
                axis=1,
            )
        elif case == 1:
            s = 2.0 * np.sqrt(1.0 + r[:, 0, 0] - r[:, 1, 1] - r[:, 2, 2])
            q[sel] = np.stack(
                [
                    0.25 * s,
                    (r[:, 0, 1] + r[:, 1, 0]) / s,
                    (r[:, 0, 2] + r[:, 2, 0]) / s,
                    (r[:, 2, 1] - r[:, 1, 2]) / s,
                ],
                axis=1,
            )
        elif case == 2:
            s = 2.0 * np.sqrt(1.0 + r[:, 1, 1] - r[:, 0, 0] - r[:, 2, 2])
            q[sel] = np.stack(
                [
                    (r[:, 0, 1] + r[:, 1, 0]) / s,
                    0.25 * s,
                    (r[:, 1, 2] + r[:, 2, 1]) / s,
                    (r[:, 0, 2] - r[:, 2, 0]) / s,
                ],
                axis=1,
            )
        else:
            s = 2.0 * np.sqrt(1.0 + r[:, 2, 2] - r[:, 0, 0] - r[:, 1, 1])
            q[sel] = np.stack(
                [
                    (r[:, 0, 2] + r[:, 2, 0]) / s,
                    (r[:, 1, 2] + r[:, 2, 1]) / s,
                    0.25 * s,
                    (r[:, 1, 0] - r[:, 0, 1]) / s,
                ],
                axis=1,
            )
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q *= np.where(q[:, 3:4] < 0.0, -1.0, 1.0)
    return q.reshape(rot.shape[:-2] + (4,))


def quat_xyzw_from_matrix_single(rot) -> np.ndarray:
    """`quat_xyzw_from_matrix` for one [3, 3] matrix, in scalar arithmetic (hot path)."""
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = np.asarray(rot, dtype=np.float64).tolist()
    tr = m00 + m11 + m22
    if tr >= m00 and tr >= m11 and tr >= m22:
        s = 2.0 * math.sqrt(1.0 + tr)
        q = ((m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s)
    elif m00 >= m11 and m00 >= m22:
        s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        q = (0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s)
    elif m11 >= m22:
        s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        q = ((m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        q = ((m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s)
    norm = math.sqrt(sum(c * c for c in q)) * (-1.0 if q[3] < 0.0 else 1.0)
    return np.array([c / norm for c in q])


def matrix_from_quat_xyzw(quat) -> np.ndarray:
    """Rotation matrices of quaternions (x, y, z, w); normalises them first.

    Args:
        quat: [..., 4] (x, y, z, w).

    Returns:
        [..., 3, 3] rotation matrices.
    """
    q = np.asarray(quat, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    out = np.empty(q.shape[:-1] + (3, 3))
    out[..., 0, 0] = 1 - 2 * (y * y + z * z)
    out[..., 0, 1] = 2 * (x * y - z * w)
    out[..., 0, 2] = 2 * (x * z + y * w)
    out[..., 1, 0] = 2 * (x * y + z * w)
    out[..., 1, 1] = 1 - 2 * (x * x + z * z)
    out[..., 1, 2] = 2 * (y * z - x * w)
    out[..., 2, 0] = 2 * (x * z - y * w)
    out[..., 2, 1] = 2 * (y * z + x * w)
    out[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return out


def yaw_of_matrix(rot) -> np.ndarray:
    """Heading of rotations: angle of the rotated x axis projected on the horizontal plane.

    Args:
        rot: [..., 3, 3] rotation matrices.

    Returns:
        [...] yaw, rad, in (-pi, pi].
    """
    rot = np.asarray(rot, dtype=np.float64)
    return np.arctan2(rot[..., 1, 0], rot[..., 0, 0])


@dataclass(frozen=True)
class LegKinematics:
    """Constants of one Talos leg, read from the model (root = base_link frame).

    Attributes:
        hip_offset: [3] common point of the three hip axes, root frame, m.
        thigh: hip-to-knee length along the hip-pitch link's -z, m.
        shin: knee-to-ankle length along the knee link's -z, m.
        sole_depth: ankle-to-sole distance along the ankle-roll link's -z, m.
        q_index: [6] indices of the leg joints in q (hip yaw ... ankle roll).
        v_index: [6] indices of the leg joints in the velocity vector.
        lower: [6] lower joint limits, rad.
        upper: [6] upper joint limits, rad.
    """

    hip_offset: np.ndarray
    thigh: float
    shin: float
    sole_depth: float
    q_index: np.ndarray
    v_index: np.ndarray
    lower: np.ndarray
    upper: np.ndarray

    @property
    def lower_list(self) -> list[float]:
        """`lower` as a list of floats (scalar hot paths)."""
        return self.__dict__.setdefault("_lower_list", self.lower.tolist())

    @property
    def upper_list(self) -> list[float]:
        """`upper` as a list of floats (scalar hot paths)."""
        return self.__dict__.setdefault("_upper_list", self.upper.tolist())


class TalosModel:
    """Talos for contact planning: model, data, sole frames, legs, collision geometry.

    Host-only, not jittable; holds mutable Pinocchio/coal data, so use one instance
    per process (`load_talos()` caches it) and do not share it between threads.

    Attributes:
        model: pinocchio.Model, full Talos with free flyer (nq = 39, nv = 38).
        data: pinocchio.Data for `model`.
        geom_model: pinocchio.GeometryModel, the collision meshes used for terrain
            collision (all of Talos's collision meshes; foot meshes raised by
            FOOT_CLEARANCE along the sole normal).
        geom_data: pinocchio.GeometryData for `geom_model`.
        q_ref: [39] half-sitting reference configuration (root at the origin, yaw 0).
        upper_refs: {name: [39]} `q_ref` with each of `UPPER_BODY_POSTURES`' joints set.
        mass: total mass, kg.
        sole_frame_ids: (left, right) Pinocchio frame ids of the sole frames.
        legs: (left, right) LegKinematics.
        nominal_sole_in_root: [2, 3] sole positions in the root frame at half-sitting.
        leg_geom_ids: (left, right) arrays of geometry ids of each leg's meshes.
        file_digest: sha256 of the URDF and SRDF files (database cache key).
    """

    def __init__(self):
        import pinocchio as pin
        from example_robot_data.robots_loader import loader

        # One loader: each TalosLoader() parses the URDF and loads its meshes again.
        talos = loader("talos")
        robot = talos.robot
        self.model = robot.model
        self.data = self.model.createData()
        self.urdf_path = talos.df_path
        self.srdf_path = talos.srdf_path
        digest = hashlib.sha256()
        for path in (self.urdf_path, self.srdf_path):
            with open(path, "rb") as handle:
                digest.update(handle.read())
        self.file_digest = digest.hexdigest()
        if self.model.nq != NQ:
            raise RuntimeError(f"Talos model has nq = {self.model.nq}, expected {NQ}")

        refs = {entry.key(): np.array(entry.data()) for entry in self.model.referenceConfigurations}
        if "half_sitting" not in refs:  # older example-robot-data: read the SRDF's configurations
            pin.loadReferenceConfigurations(self.model, self.srdf_path, False)
            refs = {entry.key(): np.array(entry.data()) for entry in self.model.referenceConfigurations}
        q_half = refs["half_sitting"]
        # Base height over the soles at half-sitting (both soles at z = 0 there).
        self.ref_root_height = float(q_half[2])
        q_ref = q_half.copy()
        q_ref[:6] = 0.0  # root at the origin, identity orientation (qw = 1)
        q_ref[6] = 1.0
        self.q_ref = q_ref
        self.q_ref.setflags(write=False)
        self.upper_refs = {
            name: upper_body_reference(self.model, q_ref, joints)
            for name, joints in UPPER_BODY_POSTURES.items()
        }
        self.mass = float(pin.computeTotalMass(self.model))
        self.sole_frame_ids = tuple(self.model.getFrameId(name) for name in SOLE_FRAMES)
        self.legs = tuple(
            _leg_kinematics(self.model, prefix, frame) for prefix, frame in zip(LEG_PREFIXES, SOLE_FRAMES)
        )
        self.lower = np.array(self.model.lowerPositionLimit)
        self.upper = np.array(self.model.upperPositionLimit)

        pin.framesForwardKinematics(self.model, self.data, q_ref)
        self.nominal_sole_in_root = np.array([self.data.oMf[fid].translation for fid in self.sole_frame_ids])
        self.geom_model, self.leg_geom_ids, self.foot_geom_ids = _collision_geometry(
            robot.collision_model, self.model
        )
        self.geom_data = pin.GeometryData(self.geom_model)

    def configuration(self, root_pos, root_rot, leg_q, upper: str = "half_sitting") -> np.ndarray:
        """Full configuration from a root placement and the two legs' joints.

        Args:
            root_pos: [3] base_link position, world frame, m.
            root_rot: [3, 3] world_R_root.
            leg_q: [2, 6] (left, right) leg joints, rad, order hip yaw ... ankle roll.
            upper: the upper body's posture, a key of `UPPER_BODY_POSTURES`.

        Returns:
            [39] q: root xyz + quaternion xyzw, legs from `leg_q`, rest from `upper`.
        """
        q = self.upper_refs[upper].copy()
        q[:3] = root_pos
        q[3:7] = quat_xyzw_from_matrix_single(root_rot)
        for side in (LEFT, RIGHT):
            q[self.legs[side].q_index] = leg_q[side]
        return q

    def sole_placements(self, q: np.ndarray) -> np.ndarray:
        """World placements of both soles by forward kinematics (updates `data`).

        Args:
            q: [39] configuration.

        Returns:
            [2, 7] (left, right) xyz + quaternion xyzw, world frame.
        """
        import pinocchio as pin

        pin.framesForwardKinematics(self.model, self.data, q)
        out = np.empty((2, 7))
        for side, fid in enumerate(self.sole_frame_ids):
            oMf = self.data.oMf[fid]
            out[side, :3] = oMf.translation
            out[side, 3:] = quat_xyzw_from_matrix(oMf.rotation)
        return out

    def com(self, q: np.ndarray) -> np.ndarray:
        """[3] centre of mass of configuration q [39], world frame, m (updates `data`)."""
        import pinocchio as pin

        return np.array(pin.centerOfMass(self.model, self.data, q))

    def joint_limit_violations(
        self, q: np.ndarray, tol: float = 1e-9
    ) -> list[tuple[str, float, float, float]]:
        """Actuated joints outside their limits.

        Args:
            q: [39] configuration.
            tol: allowed excess, rad.

        Returns:
            list of (joint name, value, lower, upper) for each violated joint.
        """
        out = []
        for jid in range(2, self.model.njoints):
            idx = self.model.joints[jid].idx_q
            value, lo, hi = q[idx], self.lower[idx], self.upper[idx]
            if value < lo - tol or value > hi + tol:
                out.append((self.model.names[jid], float(value), float(lo), float(hi)))
        return out


def upper_body_reference(model, q_ref: np.ndarray, joints: dict) -> np.ndarray:
    """[39] `q_ref` with the left-arm joint values `joints` set and mirrored on the right arm.

    Raises:
        ValueError: a joint the model lacks, or a value outside its limits.
    """
    q = q_ref.copy()
    for name, value in joints.items():
        for side_name, side_value in (
            (name, value),
            (name.replace("_left_", "_right_"), -value if name in _MIRRORED_ARM_JOINTS else value),
        ):
            if not model.existJointName(side_name):
                raise ValueError(f"upper-body posture: Talos has no joint {side_name!r}")
            index = model.joints[model.getJointId(side_name)].idx_q
            lo, hi = model.lowerPositionLimit[index], model.upperPositionLimit[index]
            if not lo <= side_value <= hi:
                raise ValueError(f"upper-body posture: {side_name} = {side_value} is outside [{lo}, {hi}]")
            q[index] = side_value
    q.setflags(write=False)
    return q


def _leg_kinematics(model, prefix: str, sole_frame: str) -> LegKinematics:
    """Read one leg's constants and check the structure the analytic IK relies on.

    Raises:
        RuntimeError: the leg is not the hip(zxy)-knee(y)-ankle(yx) chain with
            concurrent hip and ankle axes described in the module docstring.
    """
    jids = [model.getJointId(f"{prefix}_{k}_joint") for k in range(1, 7)]
    placements = [model.jointPlacements[j] for j in jids]
    problems = []
    for k, (jid, axis) in enumerate(zip(jids, _LEG_AXES)):
        if model.joints[jid].shortname() != f"JointModelR{axis}":
            problems.append(f"{model.names[jid]} is {model.joints[jid].shortname()}, expected R{axis}")
        if not np.allclose(placements[k].rotation, np.eye(3), atol=1e-9):
            problems.append(f"{model.names[jid]} placement is rotated")
    if model.parents[jids[0]] != 1:
        problems.append(f"{model.names[jids[0]]} is not attached to the root joint")
    # Hip axes concurrent (joints 2, 3 at the hip point), ankle axes concurrent (joint 6).
    for k in (1, 2, 5):
        if not np.allclose(placements[k].translation, 0.0, atol=1e-9):
            problems.append(f"{model.names[jids[k]]} is offset from its parent joint")
    for k in (3, 4):
        if not np.allclose(placements[k].translation[:2], 0.0, atol=1e-9):
            problems.append(f"{model.names[jids[k]]} offset is not along z")
    frame = model.frames[model.getFrameId(sole_frame)]
    if (
        frame.parentJoint != jids[5]
        or not np.allclose(frame.placement.rotation, np.eye(3), atol=1e-9)
        or not np.allclose(frame.placement.translation[:2], 0.0, atol=1e-9)
    ):
        problems.append(f"{sole_frame} is not straight below {model.names[jids[5]]}")
    if problems:
        raise RuntimeError(
            "Talos leg structure differs from what the analytic IK assumes: " + "; ".join(problems)
        )
    q_index = np.array([model.joints[j].idx_q for j in jids])
    v_index = np.array([model.joints[j].idx_v for j in jids])
    return LegKinematics(
        hip_offset=np.array(placements[0].translation),
        thigh=float(-placements[3].translation[2]),
        shin=float(-placements[4].translation[2]),
        sole_depth=float(-frame.placement.translation[2]),
        q_index=q_index,
        v_index=v_index,
        lower=np.array(model.lowerPositionLimit[q_index]),
        upper=np.array(model.upperPositionLimit[q_index]),
    )


def _collision_geometry(collision_model, model):
    """Collision meshes for terrain and leg-leg checks.

    All of Talos's collision meshes are kept (the per-geometry bounding-box test in
    `collision.py` makes the far ones free); the two ankle-roll meshes (the feet) are
    raised by FOOT_CLEARANCE along their z axis (the sole normal) so that a foot resting
    on a face does not count as colliding with it.

    Returns:
        (GeometryModel, (left ids, right ids) of each leg's geometries [n] int,
         (left, right) geometry id of each foot mesh).
    """
    import pinocchio as pin

    geom_model = pin.GeometryModel()
    leg_ids = ([], [])
    foot_ids = [None, None]
    for geom in collision_model.geometryObjects:
        geom = geom.copy()
        name = geom.name
        for side, prefix in enumerate(LEG_PREFIXES):
            if name.startswith(prefix):
                if name.startswith(f"{prefix}_6_link"):
                    placement = geom.placement.copy()
                    placement.translation = placement.translation + placement.rotation[:, 2] * FOOT_CLEARANCE
                    geom.placement = placement
                    foot_ids[side] = geom_model.ngeoms
                leg_ids[side].append(geom_model.ngeoms)
        geom_model.addGeometryObject(geom)
    if None in foot_ids:
        raise RuntimeError("Talos collision model has no ankle-roll (foot) mesh")
    return geom_model, tuple(np.array(ids) for ids in leg_ids), tuple(foot_ids)


@functools.lru_cache(maxsize=1)
def load_talos() -> TalosModel:
    """The Talos model, loaded once per process (0.9 s the first time on 2 cores,
    benchmarks/contact_worker_startup.py).

    Host-only, not jittable.
    """
    return TalosModel()
