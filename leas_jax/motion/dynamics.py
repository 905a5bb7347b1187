"""Inverse dynamics of a Talos motion with its feet on the ground (Pinocchio's rnea).

Host-only, not jittable. `rnea` on a free-flyer model gives 38 generalised forces; its
first six (the root's) no actuator supplies: the soles in contact must. The contact
wrenches are the ones that cancel them (unique on one foot; in double support the
6 equations leave 6 free, taken nearest to a vertical load split by the CoM's position
between the soles), and the joint torques are what remains: tau = rnea(q, v, a)[6:] -
J_c[:, 6:]^T f.
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
    desired = np.zeros(6 * len(sides))
    if len(sides) == 2:
        com = pin.centerOfMass(model, data, q, False)
        sole_xy = np.array([data.oMf[frames[s]].translation[:2] for s in (0, 1)])
        shares = load_split(com[:2], sole_xy)
    else:
        shares = np.ones(1)
    for k, side in enumerate(sides):
        world_force = np.array([0.0, 0.0, shares[k] * mass * GRAVITY])
        desired[6 * k : 6 * k + 3] = data.oMf[frames[side]].rotation.T @ world_force
    # f = f_des + A^T (A A^T)^-1 (b - A f_des): the wrenches nearest f_des meeting the root rows
    correction = root.T @ np.linalg.solve(root @ root.T, full[:6] - root @ desired)
    stacked = desired + correction
    tau = full[6:].copy()
    for k, side in enumerate(sides):
        wrenches[side] = stacked[6 * k : 6 * k + 6]
        tau -= jacs[k][:, 6:].T @ wrenches[side]
    residual = full[:6] - root @ stacked
    return tau, wrenches, residual
