"""Which of a plan's phases need `reach_shift_attempt.patch`'s moved root: every segment's
phases made as `make_motion` makes them, with `reach_shift` 0; prints the segments that fail.

Usage (with the patch applied): python reach_shift_where.py PLAN.npz
"""

import dataclasses
import sys

import leas_jax.motion.motion as M
from leas_jax.contacts.commands import load_plan_file
from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.config import MotionConfig
from leas_jax.motion.wbik import WholeBodyIK
from leas_jax.terrain import loads_terrain

plan = load_plan_file(sys.argv[1])
talos = load_talos()
terrain = loads_terrain(plan.terrain, source="<plan terrain>")
config = MotionConfig()
ik = WholeBodyIK(talos, config.ik_iterations, config.ik_damping, config.ik_tolerance)
frames = [M.posture_frames(talos, q) for q in plan.q]
keys, _ = M.centred_postures(talos, plan, frames, config.support_margin, ik)
plan = dataclasses.replace(plan, q=keys)
frames = [M.posture_frames(talos, q) for q in plan.q]
for k in range(len(plan) - 1):
    try:
        M._segment_phases(plan, k, frames, terrain, dataclasses.replace(config, reach_shift=0.0), talos)
    except M.MotionError as e:
        print("reach shift used:", e)
