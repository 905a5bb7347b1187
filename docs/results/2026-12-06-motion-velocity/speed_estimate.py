"""Peak joint speed / limit of the held-root configurations of single supports k (before and after lengthening) against the whole-body IK's."""

import dataclasses
import sys

import numpy as np

import leas_jax.motion.motion as M
from leas_jax.contacts.commands import load_plan_file
from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.config import MotionConfig
from leas_jax.motion.wbik import WholeBodyIK
from leas_jax.terrain import loads_terrain

name = sys.argv[1]
ks = [int(k) for k in sys.argv[2:]]
plan = load_plan_file(f"runs/motion_plans/{name}.npz")
config = MotionConfig()
talos = load_talos()
terrain = loads_terrain(plan.terrain, source="x")
ik = WholeBodyIK(talos, config.ik_iterations, config.ik_damping, config.ik_tolerance)
frames = [M.posture_frames(talos, q) for q in plan.q]
keys, moved = M.centred_postures(talos, plan, frames, config.support_margin, ik)
if moved:
    plan = dataclasses.replace(plan, q=keys)
    frames = [M.posture_frames(talos, q) for q in plan.q]
orig = M._single_support_coms
speeds = talos.model.velocityLimit[6:]


def spy(talos_, spec, k, config_):
    out = orig(talos_, spec, k, config_)
    c = out[1]
    r = np.abs(np.diff(c[:, 7:], axis=0)) / config.dt / speeds
    j = np.unravel_index(np.argmax(r), r.shape)
    print(
        f"  {spec.kind} k={k} samples={spec.samples} profiled={out[2]} est peak ratio {r.max():.3f} joint {j[1]} at {j[0]}",
        flush=True,
    )
    return out


M._single_support_coms = spy
for k in ks:
    specs = M._segment_phases(plan, k, frames, terrain, config, talos)
    # IK the single-support spec from its start
    for spec in specs:
        print(spec.kind, spec.samples)
    # actual IK of the single support from posture k (land)
    spec = [s for s in specs if s.swing >= 0][0]
    if spec.kind == "land":
        q = plan.q[k]
        qs = [q]
        for ref in M.phase_references(spec, config.dt):
            q = ik.solve(q, ref)
            qs.append(q)
        qs = np.array(qs)
        steps = (
            np.array(
                [
                    __import__("pinocchio").difference(talos.model, qs[i], qs[i + 1])
                    for i in range(len(qs) - 1)
                ]
            )
            / config.dt
        )
        v = 0.5 * (steps[:-1] + steps[1:])
        print(
            f"  IK central peak ratio {(np.abs(v[:, 6:]) / speeds).max():.3f}, steps {(np.abs(steps[:, 6:]) / speeds).max():.3f}"
        )
