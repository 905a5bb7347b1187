"""Simulated sole displacement over some phases of a saved motion's rollout (`simulate_saved.py`'s pickle).

PYTHONPATH=$PWD python docs/results/2026-12-06-motion-velocity/sole_drift.py MOTION.npz ROLLOUT.pkl PHASE...
"""

import pickle
import sys

import numpy as np
import pinocchio as pin

from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.motion import Motion

motion, rollout = Motion.load(sys.argv[1]), pickle.load(open(sys.argv[2], "rb"))
talos = load_talos()
data = talos.model.createData()
q = rollout["q"]


def soles(configuration):
    pin.framesForwardKinematics(talos.model, data, configuration)
    return np.array([data.oMf[f].translation.copy() for f in talos.sole_frame_ids])


for index in (int(i) for i in sys.argv[3:]):
    phase = motion.phases[index]
    start, stop = phase.start, min(phase.stop, len(q) - 1)
    moved = (soles(q[stop]) - soles(q[start])) * 1000
    offset = (soles(q[start]) - motion.feet[start, :, :3]) * 1000
    print(
        index,
        phase.describe(motion.dt),
        "sole moves (mm) L",
        np.round(moved[0], 1),
        "R",
        np.round(moved[1], 1),
        "| off its reference at the start (mm) L",
        np.round(offset[0], 1),
        "R",
        np.round(offset[1], 1),
    )
