"""Why talos_plateformes_0's soles slip on its 15 deg platforms, and what holds them.

    python docs/results/2026-12-07-motion-mesh-contact/diagnose.py > docs/results/2026-12-07-motion-mesh-contact/diagnose.txt

Reads the motion that execute.sh kept (runs/motions_checked/hpp_talos_plateformes_0.npz) and
simulates it on both collision surfaces (`SimulationConfig.mesh_contact`) with MuJoCo's default
friction solver (pyramidal cones, impratio 1) and with elliptic cones and impratio 10, the noslip
solver on throughout (5 iterations). For each: the verdict, the largest slip of a supporting
sole and the phases over 1 cm. Then, on the columns with MuJoCo's default solver, the stance
(right) sole's contact force over the single support that first slips (phases 17-18: the left
foot lifted and landed): its tangential part over its normal part, the face's normal, and how far
the sole moves.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))

MOTION = ROOT / "runs/motions_checked/hpp_talos_plateformes_0.npz"
SOLVERS = {"pyramidal, impratio 1": ("pyramidal", 1.0), "elliptic, impratio 10": ("elliptic", 10.0)}


def main() -> int:
    import mujoco

    from leas_jax.motion import robot
    from leas_jax.motion.config import SimulationConfig
    from leas_jax.motion.motion import Motion
    from leas_jax.motion.simulate import simulate

    motion = Motion.load(MOTION)
    print(f"{MOTION.name}: {len(motion.phases)} phases, {motion.duration:.1f} s")
    for surface in robot.MESH_CONTACTS:
        for name, (cone, impratio) in SOLVERS.items():
            config = SimulationConfig(mesh_contact=surface, cone=cone, impratio=impratio)
            rollout = simulate(motion, config=config)
            slips = [p.slip for p in rollout.phases if p.reached]
            print(
                f"{surface:8s} {name:22s} success {rollout.success!s:5s} fallen {rollout.fallen!s:5s} "
                f"max slip {100 * max(slips):.2f} cm, phases over 1 cm {sum(s > 0.01 for s in slips)}: "
                f"{rollout.message}"
            )
    # the stance sole's contact force in the first slipping single support (columns, MuJoCo's default)
    first, last = motion.phases[17], motion.phases[18]
    scene = {}
    real_scene, real_step = robot.terrain_scene, mujoco.mj_step
    rows, steps = [], [0]

    def keep_scene(*args, **kwargs):
        scene["mj"] = real_scene(*args, **kwargs)
        return scene["mj"]

    def step(model, data):
        real_step(model, data)
        steps[0] += 1
        sample = steps[0] * model.opt.timestep / motion.dt
        if not (first.start <= sample <= last.stop) or steps[0] % 50:
            return
        mj = scene["mj"]
        geom, force, normal = mj.sole_geoms[1], np.zeros(3), None
        for c in range(data.ncon):
            contact = data.contact[c]
            if geom not in (contact.geom1, contact.geom2):
                continue
            wrench = np.zeros(6)
            mujoco.mj_contactForce(model, data, c, wrench)
            frame = contact.frame.reshape(3, 3)
            sign = 1.0 if contact.geom2 == geom else -1.0  # the force on the sole
            force += sign * (frame.T @ wrench[:3])
            normal = sign * frame[0]
        if normal is not None:
            along = force @ normal
            tangential = np.linalg.norm(force - along * normal)
            rows.append((sample, along, tangential / along, normal, data.site_xpos[mj.sole_sites[1]].copy()))

    robot.terrain_scene, mujoco.mj_step = keep_scene, step
    try:
        simulate(motion, config=SimulationConfig(mesh_contact="columns", cone="pyramidal", impratio=1.0))
    finally:
        robot.terrain_scene, mujoco.mj_step = real_scene, real_step
    ratios = np.array([r[2] for r in rows])
    start, end = rows[0][4], rows[-1][4]
    print(
        f"\ncolumns, pyramidal, impratio 1: right (stance) sole, samples {first.start}-{last.stop} "
        f"(phases 17-18), every 50 ms: normal force {min(r[1] for r in rows):.0f}-{max(r[1] for r in rows):.0f} N, "
        f"tangential / normal {ratios.min():.2f}-{ratios.max():.2f} (mu = 0.5), face normal "
        f"{np.round(rows[0][3], 3).tolist()}, the sole moves {1000 * np.linalg.norm(end - start):.1f} mm "
        f"({np.round(1000 * (end - start), 1).tolist()} mm, world)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
