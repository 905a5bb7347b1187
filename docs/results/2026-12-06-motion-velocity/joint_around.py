"""The fastest joint around samples of a saved motion: its position, velocity, acceleration, the root and swing sole heights."""

import sys

import numpy as np

from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.motion import Motion

m = Motion.load(sys.argv[1])
talos = load_talos()
names = [talos.model.names[j] for j in range(2, talos.model.njoints)]
samples = [int(s) for s in sys.argv[2:]]
for s in samples:
    idx = m.phase_at(s)
    p = m.phases[idx]
    print(
        "phase",
        idx,
        p.kind,
        p.postures,
        "swing",
        p.swing,
        p.start,
        p.stop,
        "len",
        p.stop - p.start,
        "sample in phase",
        s - p.start,
    )
    j = int(np.argmax(np.abs(m.v[s, 6:])))
    print("joint", names[j])
    lo = max(p.start, s - 25)
    hi = min(p.stop, s + 25)
    for i in range(lo, hi + 1, 2):
        print(
            i - p.start,
            f"q={m.q[i, 7 + j]:.4f} v={m.v[i, 6 + j]:.3f} a={m.a[i, 6 + j]:.1f} rootz={m.q[i, 2]:.4f} comz={m.com[i, 2]:.4f} vz={m.v[i, 2]:.3f} swingz={m.feet[i, p.swing, 2] if p.swing >= 0 else 0:.4f} knees={m.q[i, 7 + 3]:.3f},{m.q[i, 7 + 9]:.3f}",
        )
    # whole phase summary
    seg = slice(p.start, p.stop + 1)
    print("phase peak |v| per leg joint:", np.round(np.abs(m.v[seg, 6:18]).max(0), 2))
    print(
        "com z range",
        m.com[seg, 2].min(),
        m.com[seg, 2].max(),
        "root z",
        m.q[seg, 2].min(),
        m.q[seg, 2].max(),
    )
