"""How far inside the stance sole can the CoM stay in a single support that no root height reaches?

For the single-support phase between plan postures k and k + 1 (at its nominal 0.6 s lift or
0.8 s landing, its references as `make_motion` builds them): at every 4th sample, every root
placement moved from the one-foot key posture's by a horizontal offset on a 2 cm grid within
+-0.10 m and a lowering from -0.15 to 0.30 m by 2.5 cm, with both soles reached by the analytic
leg IK (`held_root_configuration`); the largest CoM margin inside the stance sole among them.
The phase's "min over samples" is the least of those: a root free to move within 0.10 m can
keep the CoM that far inside at every sample checked (a bound, not a smooth path).

    PYTHONPATH=$PWD python docs/results/2026-12-06-motion-root-shift/room.py PLAN K
"""

import sys

import numpy as np
import pinocchio as pin

from leas_jax.contacts.plan import ContactPlan
from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion import motion as M
from leas_jax.motion.config import MotionConfig
from leas_jax.motion.paths import slerp
from leas_jax.terrain import loads_terrain


def phase(plan, k, talos, config, terrain):
    """(spec, one-foot key posture q [39], its CoM [3]) of the single support between k and k + 1."""
    frames = [M.posture_frames(talos, q) for q in plan.q[k : k + 2]]
    (feet_a, com_a, rot_a), (feet_b, com_b, rot_b) = frames
    on_a, on_b = M._contacts(plan, k), M._contacts(plan, k + 1)
    if on_a.all():
        swing, q = int(np.flatnonzero(~on_b)[0]), plan.q[k + 1]
        lifted = feet_a.copy()
        lifted[swing] = feet_b[swing]
        start, end = feet_a[swing][:3, 3], feet_b[swing][:3, 3]
        apex = max(M._terrain_top(terrain, start, end) + config.swing_clearance, start[2], end[2])
        spec = M._PhaseSpec(
            "lift", (k, k + 1), swing, 60, feet_a, lifted, com_b, com_b, rot_a, rot_b, q, q, apex
        )
        return spec, q, com_b
    swing, q = int(np.flatnonzero(~on_a)[0]), plan.q[k]
    landed = feet_a.copy()
    landed[swing] = feet_b[swing]
    apex = M._apex(terrain, feet_a[swing][:3, 3], feet_b[swing][:3, 3], config.swing_clearance)
    spec = M._PhaseSpec("land", (k, k + 1), swing, 80, feet_a, landed, com_a, com_a, rot_a, rot_b, q, q, apex)
    return spec, q, com_a


def main(name: str, k: int) -> None:
    plan = ContactPlan.load(f"runs/motion_plans/{name}.npz")
    talos, config = load_talos(), MotionConfig()
    data = talos.model.createData()
    terrain = loads_terrain(plan.terrain, source="plan")
    spec, q, com = phase(plan, k, talos, config, terrain)
    fractions = np.arange(spec.samples + 1) / spec.samples
    feet = M.swing_feet(spec, fractions)
    rotations = slerp(spec.rot0, spec.rot1, M.turn_scaling(spec, fractions))
    _, knees, _ = M.single_support_schedule(talos, q, feet, spec.swing, spec.kind == "lift", config)
    stance = M.sole_corners(spec.feet0, np.array([side != spec.swing for side in (0, 1)]))
    print(name, k, spec.kind, "key CoM margin", round(M.support_margin(stance, com[:2]), 3))
    grid = np.arange(-0.10, 0.101, 0.02)
    dips = np.arange(-0.15, 0.301, 0.025)
    bests = []
    for i in range(0, spec.samples + 1, 4):
        best, where, count = -1.0, None, 0
        for dx in grid:
            for dy in grid:
                for dip in dips:
                    offset = np.r_[dx, dy, -dip]
                    c = M.held_root_configuration(talos, q, feet[i], rotations[i], offset, knees[i], 0.0)
                    if c is None:
                        continue
                    count += 1
                    margin = M.support_margin(stance, pin.centerOfMass(talos.model, data, c, False)[:2])
                    if margin > best:
                        best, where = margin, (round(dx, 3), round(dy, 3), round(dip, 3))  # dip: lowering
        bests.append(best)
        print(i, f"feasible {count:5d} best margin {best:+.3f} at {where}")
    print("phase min over samples of best margin", round(min(bests), 3))


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]))
