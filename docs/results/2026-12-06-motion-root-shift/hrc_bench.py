"""CPU per `held_root_configuration` call: 3 000 random root offsets around straight_plan's first
one-foot posture (tests/motion_helpers.py), and a checksum of the configurations that reach.

    OMP_NUM_THREADS=1 PYTHONPATH=$PWD python docs/results/2026-12-06-motion-root-shift/hrc_bench.py
"""

import sys
import time

import numpy as np

sys.path.insert(0, "tests")
from motion_helpers import straight_plan  # noqa: E402

from leas_jax.contacts.robot.model import load_talos  # noqa: E402
from leas_jax.motion import motion as M  # noqa: E402

talos = load_talos()
q = straight_plan(0.3).q[1]
feet, com, rotation = M.posture_frames(talos, q)
rng = np.random.default_rng(0)
offsets = np.c_[rng.uniform(-0.1, 0.1, (3000, 2)), rng.uniform(-0.3, 0.15, 3000)]
start = time.process_time()
made = [M.held_root_configuration(talos, q, feet, rotation, o, np.zeros(2), 0.03) for o in offsets]
seconds = time.process_time() - start
reached = [c for c in made if c is not None]
print(
    f"{seconds / len(offsets) * 1e6:.1f} us/call, {len(reached)} reach, checksum {sum(float(c.sum()) for c in reached):.9f}"
)
