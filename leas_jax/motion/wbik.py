"""Whole-body inverse kinematics of Talos: both soles, the CoM and the root orientation.

Host-only (Pinocchio), not jittable. The unknowns are the root's 6 velocity coordinates
and the 12 leg joints; the upper body (torso, arms, grippers, head) follows its own
reference directly. The tasks are the two sole placements (6 each, world frame), the
CoM (3) and the root orientation (3): 18 equations in 18 unknowns, solved by damped
Newton steps (damped least squares). A configuration that meets every task (a plan's
key posture with its own upper body) is a fixed point, so the IK returns it unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


class IKError(RuntimeError):
    """The IK did not reach its tasks (message: the residual and which task)."""


@dataclass(frozen=True)
class Targets:
    """One sample's task references, world frame.

    Attributes:
        feet: [2, 4, 4] homogeneous placements of the left and right sole frames.
        com: [3] centre of mass, m.
        root_rotation: [3, 3] world_R_base_link.
        upper: [39] configuration whose upper-body joints (all but the legs) are imposed.
    """

    feet: np.ndarray
    com: np.ndarray
    root_rotation: np.ndarray
    upper: np.ndarray


class WholeBodyIK:
    """Damped Newton IK on the root and legs of Talos (Pinocchio model of `load_talos`)."""

    def __init__(self, talos, iterations: int, damping: float, tolerance: float):
        self.talos = talos
        self.model = talos.model
        self.data = self.model.createData()
        self.iterations = iterations
        self.damping = damping
        self.tolerance = tolerance
        legs_v = np.concatenate([leg.v_index for leg in talos.legs])
        self.free_v = np.concatenate([np.arange(6), legs_v])  # [18] velocity coordinates solved for
        self.leg_q = np.concatenate([leg.q_index for leg in talos.legs])  # [12]
        self.upper_q = np.setdiff1d(np.arange(7, self.model.nq), self.leg_q)  # [20]

    def residual(self, q: np.ndarray, targets: Targets) -> tuple[np.ndarray, np.ndarray]:
        """Task errors and their Jacobian at q [39].

        Returns:
            (e [18]: left sole, right sole (log of the placement error in the sole frame,
             linear then angular), CoM (m), root orientation (rad, root frame);
             J [18, 18]: d e / d(root velocity, leg joints)).
        """
        import pinocchio as pin

        model, data = self.model, self.data
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        errors, rows = [], []
        for side, frame in enumerate(self.talos.sole_frame_ids):
            current = data.oMf[frame]
            target = pin.SE3(targets.feet[side][:3, :3], targets.feet[side][:3, 3])
            gap = current.actInv(target)  # target in the sole frame
            jac = pin.getFrameJacobian(model, data, frame, pin.ReferenceFrame.LOCAL)
            errors.append(pin.log6(gap).vector)
            rows.append(-pin.Jlog6(gap.inverse()) @ jac)
        com = pin.centerOfMass(model, data, q, False)
        errors.append(targets.com - com)
        rows.append(-pin.jacobianCenterOfMass(model, data, q, False))
        gap = data.oMi[1].rotation.T @ targets.root_rotation  # target in the root frame
        errors.append(pin.log3(gap))
        jroot = np.zeros((3, model.nv))
        jroot[:, 3:6] = -pin.Jlog3(gap.T)  # the free flyer's angular velocity is in the root frame
        rows.append(jroot)
        jac = np.vstack(rows)[:, self.free_v]
        return np.concatenate(errors), jac

    def solve(self, q0: np.ndarray, targets: Targets) -> np.ndarray:
        """Configuration [39] meeting `targets`, by Newton steps from q0 [39].

        Raises:
            IKError: the residual stays above the tolerance after the iterations.
        """
        import pinocchio as pin

        q = np.array(q0, dtype=np.float64)
        q[self.upper_q] = targets.upper[self.upper_q]
        for _ in range(self.iterations):
            error, jac = self.residual(q, targets)
            if np.abs(error).max() < self.tolerance:
                return q
            step = -np.linalg.solve(jac.T @ jac + self.damping * np.eye(18), jac.T @ error)
            dv = np.zeros(self.model.nv)
            dv[self.free_v] = step
            q = pin.integrate(self.model, q, dv)
        error, _ = self.residual(q, targets)
        worst = int(np.argmax(np.abs(error)))
        task = ("left sole", "right sole", "CoM", "root orientation")[
            worst // 6 if worst < 12 else 2 + (worst >= 15)
        ]
        raise IKError(
            f"IK residual {np.abs(error).max():.2e} on the {task} after {self.iterations} iterations"
        )
