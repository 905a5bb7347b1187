"""Does raising the root, or moving it back towards the double-support posture, separate the
knees at a lift's first sample? Usage: python lift_off.py PLAN.npz K (the lift K -> K + 1).

The lift's first configuration as `motion.held_root_support` makes it (the root at posture
K + 1's, both soles on posture K's contacts, legs by the analytic IK), checked with
`BodyClearance.collisions`: raised by 0-6 cm, then with the root moved a fraction of the way
back to posture K's root.
"""

import sys

import numpy as np

from leas_jax.contacts.plan import ContactPlan
from leas_jax.contacts.robot.clearance import BodyClearance
from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion import motion
from leas_jax.terrain import loads_terrain

if __name__ == "__main__":
    path, k = sys.argv[1], int(sys.argv[2])
    talos = load_talos()
    plan = ContactPlan.load(path)
    clearance = BodyClearance(talos, loads_terrain(plan.terrain))
    feet, lifted = motion.posture_frames(talos, plan.q[k])[0], plan.q[k + 1]
    rotation = motion.posture_frames(talos, lifted)[2]
    print(
        f"postures {k} and {k + 1} collide: {clearance.collisions(plan.q[k])}, {clearance.collisions(lifted)}"
    )
    for rise in (0.0, 0.01, 0.02, 0.03, 0.04, 0.06):
        q = motion.held_root_configuration(talos, lifted, feet, rotation, np.r_[0.0, 0.0, rise], np.zeros(2))
        knees = "out of reach" if q is None else f"knees {q[10]:.2f} {q[16]:.2f} rad"
        print(f"root raised {rise:.2f} m: {knees}; {None if q is None else clearance.collisions(q)}")
    for back in (0.0, 0.25, 0.5, 0.75, 1.0):
        offset = back * (plan.q[k][:3] - lifted[:3])
        q = motion.held_root_configuration(talos, lifted, feet, rotation, offset, np.zeros(2))
        print(
            f"root {back:.2f} of the way back to posture {k}'s: {None if q is None else clearance.collisions(q)}"
        )
