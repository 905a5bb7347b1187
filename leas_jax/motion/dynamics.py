"""Inverse dynamics of a Talos motion with its feet on the ground (Pinocchio's rnea).

Host-only, not jittable. `rnea` on a free-flyer model gives 38 generalised forces; its
first six (the root's) no actuator supplies: the soles in contact must. The contact
wrenches are the ones that cancel them (unique on one foot; in double support the
6 equations leave 6 free, taken nearest to the static split `static_wrenches`: each sole
carries the weight's share of `load_split` with its centre of pressure under the CoM's
offset from the segment between the soles, so both stay on their soles wherever the CoM
is over their support polygon; the dynamic remainder is shared in proportion to those
loads), and the joint torques are what remains: tau =
rnea(q, v, a)[6:] - J_c[:, 6:]^T f.
"""

from __future__ import annotations

import numpy as np

from leas_jax.contacts.robot.equilibrium import GRAVITY


def load_split(com_xy: np.ndarray, sole_xy: np.ndarray) -> np.ndarray:
    """Share of the weight each sole carries when the CoM is at com_xy [2].

    Args:
        com_xy: [2] CoM, world; sole_xy: [2, 2] (left, right) sole centres, world.

    Returns:
        [2] shares in [0, 1] summing to 1: the CoM's projection on the segment between
        the soles, clipped to it.
    """
    axis = sole_xy[1] - sole_xy[0]
    length2 = float(axis @ axis)
    if length2 < 1e-12:
        return np.array([0.5, 0.5])
    right = float(np.clip((com_xy - sole_xy[0]) @ axis / length2, 0.0, 1.0))
    return np.array([1.0 - right, right])


def static_wrenches(com_xy: np.ndarray, soles: np.ndarray, weight: float) -> np.ndarray:
    """Sole wrenches [2, 6] (force, torque at the sole frame, sole frame) that hold `weight` N
    still with the CoM over com_xy [2] (world), both soles on the ground at soles [2, 4, 4]
    (world placements).

    Each sole carries its `load_split` share vertically, at the centre of pressure o_i + d in
    its sole plane (o_i: its centre; d: the CoM's horizontal offset from the shares' point
    on the segment between the centres, the same for both soles). The centres of pressure
    then average to the CoM, so the wrenches balance the weight about it; where the CoM is
    over the soles' support polygon, d is within a sole's half-width of the segment.
    (A vertical split alone would leave the moment of that offset to the least-squares
    correction of `contact_torques`, which puts most of it on one ankle: centres of pressure
    up to 0.27 m off a 0.13 m-wide sole in navigate's eval_bridge plans.)
    """
    centres = soles[:, :2, 3]
    shares = load_split(com_xy, centres)
    offset = np.r_[com_xy - shares @ centres, 0.0]
    out = np.zeros((2, 6))
    for side in (0, 1):
        rotation = soles[side][:3, :3]
        force = rotation.T @ np.array([0.0, 0.0, shares[side] * weight])
        lever = rotation.T @ offset
        lever[2] = 0.0  # in the sole plane
        out[side] = np.r_[force, np.cross(lever, force)]
    return out


def contact_torques(model, data, q, v, a, frames, contact, mass: float):
    """Joint torques and sole wrenches that realise (q, v, a) with the given soles in contact.

    Args:
        model, data: Pinocchio model and data (free flyer).
        q: [39] configuration; v: [38] velocity; a: [38] acceleration (Pinocchio's).
        frames: (left, right) sole frame ids.
        contact: [2] bool, soles in contact.
        mass: robot mass, kg.

    Returns:
        (tau [32] joint torques, N m; wrenches [2, 6] (force, torque) at each sole frame,
        in the sole frame, zero for a foot in the air; root residual [6], the part of the
        root's generalised force the contacts cannot supply, zero with a contact).
    """
    import pinocchio as pin

    full = pin.rnea(model, data, q, v, a)
    wrenches = np.zeros((2, 6))
    sides = [side for side in (0, 1) if contact[side]]
    if not sides:
        return full[6:].copy(), wrenches, full[:6].copy()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    jacs = [pin.getFrameJacobian(model, data, frames[side], pin.ReferenceFrame.LOCAL) for side in sides]
    # root rows: sum_i J_i[:, :6]^T f_i = full[:6]
    root = np.hstack([jac[:, :6].T for jac in jacs])  # [6, 6 n]
    if len(sides) == 2:
        com = pin.centerOfMass(model, data, q, False)
        soles = np.array([data.oMf[frames[s]].homogeneous for s in (0, 1)])
        desired = static_wrenches(com[:2], soles, mass * GRAVITY).reshape(-1)
        weights = np.repeat(load_split(com[:2], soles[:, :2, 3]), 6)
    else:  # one foot: the wrench is unique
        desired, weights = np.zeros(6), np.ones(6)
    # f = f_des + W A^T (A W A^T)^-1 (b - A f_des): the wrenches nearest f_des in the metric
    # W^-1 that meet the root rows; W, each sole's load share, gives the dynamic remainder to
    # the soles in proportion to their load (none to a sole about to lift or just landed)
    spread = weights[:, None] * root.T
    correction = spread @ np.linalg.solve(root @ spread, full[:6] - root @ desired)
    stacked = desired + correction
    tau = full[6:].copy()
    for k, side in enumerate(sides):
        wrenches[side] = stacked[6 * k : 6 * k + 6]
        tau -= jacs[k][:, 6:].T @ wrenches[side]
    residual = full[:6] - root @ stacked
    return tau, wrenches, residual
