"""Equilibrium failures of a motion saved by make_unchecked.py: per failing phase, the CoM's
margin inside the supporting soles, its acceleration and the robustness, sample by sample."""

import sys

import numpy as np

from leas_jax.motion.motion import Motion, _homogeneous, check_motion, sole_corners, support_margin

m = Motion.load(sys.argv[1])
fails = [f for f in check_motion(m) if f[2] == "equilibrium"]
print(len(fails), "equilibrium failures; phases", sorted({f[1] for f in fails}))
acc = np.zeros_like(m.com)
acc[1:-1] = (m.com[2:] - 2 * m.com[1:-1] + m.com[:-2]) / m.dt**2
for index in sorted({f[1] for f in fails}):
    p = m.phases[index]
    bad = [f[0] for f in fails if f[1] == index]
    print(
        p.describe(m.dt), "failing samples", bad[0] - p.start, "..", bad[-1] - p.start, "of", p.stop - p.start
    )
    for i in list(range(p.start, p.stop + 1, max(1, (p.stop - p.start) // 12))) + bad[:3]:
        feet = np.array([_homogeneous(f) for f in m.feet[i]])
        on = m.contact[i]
        margin = support_margin(sole_corners(feet, on), m.com[i, :2])
        msg = [f[3] for f in fails if f[0] == i]
        print(
            f"  {i - p.start:4d} contact {on.astype(int)} com margin {margin * 100:6.2f} cm  acc {np.round(acc[i], 2)} com z {m.com[i, 2]:.3f} {msg}"
        )
