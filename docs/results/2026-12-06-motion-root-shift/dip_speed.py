"""Time `dip_profile` on a lengthened phase's bounds: solved at every sample against at knots.

Builds hpp_stairs_0's lift 84 -> 85 as `make_motion` does (`_segment_phases`), keeping the
bounds of the longest profile it asks for (the phase lengthened for its acceleration), then
solves it at knots and, with --dense, at every sample (one CPU, process time).

    OMP_NUM_THREADS=1 PYTHONPATH=$PWD python docs/results/2026-12-06-motion-root-shift/dip_speed.py [--dense]
"""

import sys
import time

import numpy as np

from leas_jax.contacts.plan import ContactPlan
from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion import motion as M
from leas_jax.motion.config import MotionConfig
from leas_jax.terrain import loads_terrain

kept = {}
solve = M.dip_profile


def keep(low, high, weight):
    if len(weight) > len(kept.get("weight", ())):
        kept.update(low=low.copy(), high=high.copy(), weight=weight.copy())
    return solve(low, high, weight)


M.dip_profile = keep
plan = ContactPlan.load("runs/motion_plans/hpp_stairs_0.npz")
talos = load_talos()
terrain = loads_terrain(plan.terrain, source="plan")
frames = [M.posture_frames(talos, q) for q in plan.q]
specs = M._segment_phases(plan, 84, frames, terrain, MotionConfig(), talos)
print("phases", [(s.kind, s.samples) for s in specs])
low, high, weight = kept["low"], kept["high"], kept["weight"]


def timed(name: str) -> None:
    start = time.process_time()
    dips = solve(low.copy(), high.copy(), weight)
    inside = bool(((dips >= low) & (dips <= high)).all())
    peak = np.abs(np.diff(dips, 2)).max() / 0.01**2
    seconds = time.process_time() - start
    print(
        f"{len(weight)} samples {name}: {seconds:.2f} CPU s, inside {inside}, peak acceleration {peak:.3f} m/s^2"
    )


timed(f"at {M.PROFILE_KNOTS} knots")
if "--dense" in sys.argv:
    M.PROFILE_KNOTS = len(weight)
    timed("at every sample")
