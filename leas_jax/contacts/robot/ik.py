"""Analytic inverse kinematics of the Talos legs, vectorised over candidates.

Host-only (NumPy), not jittable. The Talos leg (checked in `model._leg_kinematics`)
is hip yaw z (q1), hip roll x (q2), hip pitch y (q3) with concurrent axes at the hip
point h, a thigh of length A along -z, knee pitch y (q4), a shin of length B along
-z, ankle pitch y (q5) and ankle roll x (q6) with concurrent axes at the ankle point,
and the sole frame a distance d below the ankle, aligned with the ankle-roll link.
This is the HRP-type leg of Kajita et al., "Introduction to Humanoid Robotics"
(2014), §2.5.6; the closed form below is re-derived for Talos's axes and signs.

In the root (base_link) frame, with the sole placement rootMsole = (R_s, p_s):

    (1) R_s = Rz(q1) Rx(q2) Ry(q3 + q4 + q5) Rx(q6)
    (2) p_a = p_s + d R_s e_z                                   (ankle point)
    (3) r = R_s^T (h - p_a) = Rx(-q6) Ry(-q5) v,  v = (-A sin q4, 0, A cos q4 + B)
    (4) |r|^2 = A^2 + B^2 + 2 A B cos q4        ->  q4 = arccos(...) >= 0 (knee limit)
    (5) q6 = atan2(r_y, r_z)       (branch |q6| <= pi/2, w_z = r_z / cos q6)
    (6) q5 = atan2(-A sin q4, A cos q4 + B) - atan2(r_x, w_z)
    (7) R_h = R_s Rx(-q6) Ry(-(q4 + q5)) = Rz(q1) Rx(q2) Ry(q3), whose entries give
        q1 = atan2(-R_h[0,1], R_h[1,1]), q2 = atan2(R_h[2,1], c1 R_h[1,1] - s1 R_h[0,1]),
        q3 = atan2(-R_h[2,0], R_h[2,2])   (cos q2 > 0: |q2| <= 0.52 rad by the limits).

The solution is exact (no iteration) whenever the ankle is within reach, so it meets
the < 1 mm, < 1 deg requirement to rounding error; `tests/test_contacts_ik.py`
checks it against Pinocchio's forward kinematics.
"""

from __future__ import annotations

import math

import numpy as np

from leas_jax.contacts.robot.model import LegKinematics


def leg_ik(leg: LegKinematics, rootRsole, root_p_sole) -> tuple[np.ndarray, np.ndarray]:
    """Joint angles placing one sole at given placements relative to the root.

    Host-only, not jittable.

    Args:
        leg: the leg's constants (`TalosModel.legs[side]`).
        rootRsole: [N, 3, 3] sole orientations in the root (base_link) frame.
        root_p_sole: [N, 3] sole positions in the root frame, m.

    Returns:
        (q [N, 6] leg joints in radians, order hip yaw ... ankle roll — NaN-free but
        meaningless where unreachable; reachable [N] bool: the ankle is within the
        thigh + shin span). Joint limits are not checked here (`within_limits`).
    """
    rot = np.asarray(rootRsole, dtype=np.float64).reshape(-1, 3, 3)
    pos = np.asarray(root_p_sole, dtype=np.float64).reshape(-1, 3)
    thigh, shin = leg.thigh, leg.shin
    # (2) ankle point, (3) hip seen from the ankle in the sole frame.
    ankle = pos + leg.sole_depth * rot[:, :, 2]
    r = np.einsum("nji,nj->ni", rot, leg.hip_offset - ankle)
    dist2 = np.einsum("ni,ni->n", r, r)
    # (4) knee from the law of cosines.
    cos_knee = (dist2 - thigh * thigh - shin * shin) / (2.0 * thigh * shin)
    reachable = np.abs(cos_knee) <= 1.0
    q4 = np.arccos(np.clip(cos_knee, -1.0, 1.0))
    # (5), (6) ankle roll and pitch. (3) gives (r_y, r_z) = w_z (sin q6, cos q6) with
    # w_z = +-hypot(r_y, r_z); the branch with |q6| <= pi/2 is the one the roll
    # limits (+-0.52 rad) allow, it has w_z < 0 only for a hip below the ankle plane.
    flip = np.where(r[:, 2] < 0.0, -1.0, 1.0)
    q6 = np.arctan2(flip * r[:, 1], flip * r[:, 2])
    w_z = flip * np.hypot(r[:, 1], r[:, 2])
    s4 = np.sin(q4)
    c4 = np.cos(q4)
    q5 = np.arctan2(-thigh * s4, thigh * c4 + shin) - np.arctan2(r[:, 0], w_z)
    # (7) hip rotation R_h = R_s Rx(-q6) Ry(-(q4 + q5)).
    c6, s6 = np.cos(q6), np.sin(q6)
    pitch = q4 + q5
    cp, sp = np.cos(pitch), np.sin(pitch)
    # Rx(-q6) Ry(-p) = [[cp, 0, -sp], [s6 sp, c6, s6 cp], [c6 sp, -s6, c6 cp]]
    m = np.empty((len(r), 3, 3))
    m[:, 0, 0], m[:, 0, 1], m[:, 0, 2] = cp, 0.0, -sp
    m[:, 1, 0], m[:, 1, 1], m[:, 1, 2] = s6 * sp, c6, s6 * cp
    m[:, 2, 0], m[:, 2, 1], m[:, 2, 2] = c6 * sp, -s6, c6 * cp
    hip = rot @ m
    q1 = np.arctan2(-hip[:, 0, 1], hip[:, 1, 1])
    c1, s1 = np.cos(q1), np.sin(q1)
    q2 = np.arctan2(hip[:, 2, 1], c1 * hip[:, 1, 1] - s1 * hip[:, 0, 1])
    q3 = np.arctan2(-hip[:, 2, 0], hip[:, 2, 2])
    return np.stack([q1, q2, q3, q4, q5, q6], axis=1), reachable


def leg_ik_single(leg: LegKinematics, rootRsole, root_p_sole) -> np.ndarray | None:
    """`leg_ik` for one placement, in scalar arithmetic (the generator's hot path).

    Host-only, not jittable. Same equations (1)-(7) as `leg_ik`, and additionally
    checks the joint limits.

    Args:
        leg: the leg's constants.
        rootRsole: [3, 3] sole orientation in the root frame.
        root_p_sole: [3] sole position in the root frame, m.

    Returns:
        [6] leg joints, rad, or None when the ankle is out of reach or a joint limit is
        violated.
    """
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = np.asarray(rootRsole, dtype=np.float64).tolist()
    px, py, pz = np.asarray(root_p_sole, dtype=np.float64).tolist()
    hx, hy, hz = leg.hip_offset.tolist()
    d, a, b = leg.sole_depth, leg.thigh, leg.shin
    # (2) ankle, (3) r = R_s^T (h - ankle)
    vx, vy, vz = hx - (px + d * r02), hy - (py + d * r12), hz - (pz + d * r22)
    rx = r00 * vx + r10 * vy + r20 * vz
    ry = r01 * vx + r11 * vy + r21 * vz
    rz = r02 * vx + r12 * vy + r22 * vz
    cos_knee = (rx * rx + ry * ry + rz * rz - a * a - b * b) / (2.0 * a * b)
    if abs(cos_knee) > 1.0:
        return None
    q4 = math.acos(cos_knee)
    flip = -1.0 if rz < 0.0 else 1.0
    q6 = math.atan2(flip * ry, flip * rz)
    w_z = flip * math.hypot(ry, rz)
    q5 = math.atan2(-a * math.sin(q4), a * math.cos(q4) + b) - math.atan2(rx, w_z)
    c6, s6 = math.cos(q6), math.sin(q6)
    cp, sp = math.cos(q4 + q5), math.sin(q4 + q5)
    # (7) R_h = R_s M, M = Rx(-q6) Ry(-(q4 + q5)); entries (0,1), (1,1), (2,0), (2,1), (2,2).
    m00, m01, m02 = cp, 0.0, -sp
    m10, m11, m12 = s6 * sp, c6, s6 * cp
    m20, m21, m22 = c6 * sp, -s6, c6 * cp
    h01 = r00 * m01 + r01 * m11 + r02 * m21
    h11 = r10 * m01 + r11 * m11 + r12 * m21
    h20 = r20 * m00 + r21 * m10 + r22 * m20
    h21 = r20 * m01 + r21 * m11 + r22 * m21
    h22 = r20 * m02 + r21 * m12 + r22 * m22
    q1 = math.atan2(-h01, h11)
    q2 = math.atan2(h21, math.cos(q1) * h11 - math.sin(q1) * h01)
    q3 = math.atan2(-h20, h22)
    q = (q1, q2, q3, q4, q5, q6)
    lower, upper = leg.lower_list, leg.upper_list
    for k in range(6):
        if q[k] < lower[k] or q[k] > upper[k]:
            return None
    return np.array(q)


def within_limits(leg: LegKinematics, q, margin: float = 0.0) -> np.ndarray:
    """Whether leg joint vectors respect the joint limits shrunk by `margin`.

    Args:
        leg: the leg's constants.
        q: [N, 6] leg joints, rad.
        margin: distance kept from each limit, rad.

    Returns:
        [N] bool.
    """
    q = np.asarray(q, dtype=np.float64).reshape(-1, 6)
    return np.all((q >= leg.lower + margin) & (q <= leg.upper - margin), axis=1)


def leg_fk(leg: LegKinematics, q) -> tuple[np.ndarray, np.ndarray]:
    """Sole placements in the root frame from leg joints (closed form of eqs (1)-(3)).

    Used to build the sample database without a Pinocchio call per sample;
    `tests/test_contacts_ik.py` checks it against Pinocchio.

    Args:
        leg: the leg's constants.
        q: [N, 6] leg joints, rad.

    Returns:
        (rootRsole [N, 3, 3], root_p_sole [N, 3] m).
    """
    q = np.asarray(q, dtype=np.float64).reshape(-1, 6)
    n = len(q)
    rz = _axis_rot(q[:, 0], 2)
    rx = _axis_rot(q[:, 1], 0)
    ry3 = _axis_rot(q[:, 2], 1)
    ry34 = _axis_rot(q[:, 2] + q[:, 3], 1)
    ry345 = _axis_rot(q[:, 2] + q[:, 3] + q[:, 4], 1)
    rx6 = _axis_rot(q[:, 5], 0)
    hip = rz @ rx
    down = np.broadcast_to(np.array([0.0, 0.0, -1.0]), (n, 3))
    knee = leg.hip_offset + leg.thigh * np.einsum("nij,nj->ni", hip @ ry3, down)
    ankle = knee + leg.shin * np.einsum("nij,nj->ni", hip @ ry34, down)
    rot = hip @ ry345 @ rx6
    pos = ankle - leg.sole_depth * rot[:, :, 2]
    return rot, pos


def _axis_rot(angle: np.ndarray, axis: int) -> np.ndarray:
    """[N, 3, 3] rotations by `angle` [N] about the x (0), y (1) or z (2) axis."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros((len(angle), 3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    out[:, axis, axis] = 1.0
    out[:, i, i] = c
    out[:, j, j] = c
    out[:, i, j] = -s
    out[:, j, i] = s
    return out
