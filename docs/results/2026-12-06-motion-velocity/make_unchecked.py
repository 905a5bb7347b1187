"""make_motion(check=False) of runs/motion_plans/NAME.npz, saved as /tmp/mv/NAME_TAG.npz (TAG: argv[2], default motion); prints its check failures."""

import sys
import time

from leas_jax.contacts.commands import load_plan_file
from leas_jax.motion.motion import make_motion

name = sys.argv[1]
plan = load_plan_file(f"runs/motion_plans/{name}.npz")
t0 = time.process_time()
m = make_motion(plan, check=False)
print(name, "made", m.duration, "s", time.process_time() - t0, "CPU s", flush=True)
m.save(f"/tmp/mv/{name}_{sys.argv[2] if len(sys.argv) > 2 else 'motion'}.npz")
for f in m.failures[:40]:
    print(f)
print(len(m.failures), "failures")
