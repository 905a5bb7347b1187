"""simulate a saved motion (default settings); pickle its rollout; print the phases that slip, land off or fail."""

import pickle
import sys

from leas_jax.motion.motion import Motion
from leas_jax.motion.simulate import simulate

m = Motion.load(sys.argv[1])
r = simulate(m)
print(r.message, "fall", r.fall_time)
out = {
    "phases": [
        (
            p.kind,
            p.postures,
            p.swing,
            p.landing_position,
            p.slip,
            p.torque_ratio,
            p.other_contacts[:3],
            p.fallen,
            p.reached,
        )
        for p in r.phases
    ],
    "q": r.q,
    "h": r.root_height,
    "tilt": r.tilt,
}
pickle.dump(out, open(sys.argv[2], "wb"))
for i, p in enumerate(r.phases):
    if p.reached or p.fallen:
        bad = p.problems(__import__("leas_jax.motion.config", fromlist=["x"]).SimulationConfig())
        if bad or p.slip > 0.003 or (p.landing_position > 0.01):
            ph = m.phases[i]
            print(
                i,
                ph.describe(m.dt),
                f"slip {p.slip * 100:.2f} cm land {p.landing_position * 100:.2f} cm tq {p.torque_ratio:.2f}",
                bad,
            )
