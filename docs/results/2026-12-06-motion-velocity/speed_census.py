"""For each plan: make the phase specs (no IK) and record single supports the speed term lengthens."""

import dataclasses
import sys
import time

import leas_jax.motion.motion as M
from leas_jax.contacts.commands import load_plan_file
from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.config import MotionConfig
from leas_jax.motion.wbik import WholeBodyIK
from leas_jax.terrain import loads_terrain

config = MotionConfig()
talos = load_talos()
orig = M.speed_samples
hits = []


def spy(c, samples, speeds, dt):
    out = orig(c, samples, speeds, dt)
    if out > samples:
        hits.append((samples, out))
    return out


M.speed_samples = spy
for name in sys.argv[1:]:
    t = time.process_time()
    plan = load_plan_file(f"runs/motion_plans/{name}.npz")
    terrain = loads_terrain(plan.terrain, source="x")
    ik = WholeBodyIK(talos, config.ik_iterations, config.ik_damping, config.ik_tolerance)
    frames = [M.posture_frames(talos, q) for q in plan.q]
    keys, moved = M.centred_postures(talos, plan, frames, config.support_margin, ik)
    if moved:
        plan = dataclasses.replace(plan, q=keys)
        frames = [M.posture_frames(talos, q) for q in plan.q]
    found = []
    err = None
    for k in range(len(plan) - 1):
        hits.clear()
        try:
            M._segment_phases(plan, k, frames, terrain, config, talos)
        except M.MotionError as e:
            err = str(e)[:100]
            break
        if hits:
            found.append((k, list(hits)))
    print(name, f"{time.process_time() - t:.0f} CPU s", "speed-lengthened:", found, "error:", err, flush=True)
