"""Which one-foot key postures does the swing-sole fallback of `motion._centred_configuration` change?

    python docs/results/2026-12-07-motion-mesh-contact/one_foot_fallback.py runs/motion_plans_checked/*.npz \\
        > docs/results/2026-12-07-motion-mesh-contact/one_foot_fallback.txt

For each plan (talos_maze's left out: its 2145 postures are not executed here), the one-foot
postures that `centred_postures` would move (CoM under `MotionConfig.single_support_margin`
inside the stance sole) but whose IK cannot keep the swing sole where it is; for each, whether
the fallback (the swing sole carried with the CoM) gives a configuration within the joint
limits and free of collisions, i.e. whether the motion made from the plan changes.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))


def main(paths: list[str]) -> int:
    from leas_jax.contacts.commands import load_plan_file
    from leas_jax.contacts.robot.clearance import BodyClearance
    from leas_jax.contacts.robot.model import load_talos
    from leas_jax.motion import motion as m
    from leas_jax.motion.config import MotionConfig
    from leas_jax.motion.wbik import IKError, Targets, WholeBodyIK
    from leas_jax.terrain import loads_terrain

    config, talos = MotionConfig(), load_talos()
    ik = WholeBodyIK(talos, config.ik_iterations, config.ik_damping, config.ik_tolerance)
    lower, upper = talos.model.lowerPositionLimit[7:], talos.model.upperPositionLimit[7:]
    for path in sorted(p for p in paths if "maze" not in p):
        plan = load_plan_file(path)
        clearance = BodyClearance(talos, loads_terrain(plan.terrain))
        changed = []
        for k in range(1, len(plan)):
            on = m._contacts(plan, k)
            if on.all():
                continue
            feet, com, rotation = m.posture_frames(talos, plan.q[k])
            target = m.centred_com(m.sole_corners(feet, on), com, config.single_support_margin)
            if np.allclose(target, com):
                continue
            try:
                ik.solve(plan.q[k], Targets(feet, target, rotation, plan.q[k]))
                continue  # the swing sole kept: as before
            except IKError:
                pass
            q = m._centred_configuration(ik, plan.q[k], feet, com, target, rotation, on)
            usable = (
                q is not None
                and not ((q[7:] < lower) | (q[7:] > upper)).any()
                and not clearance.collisions(q)
            )
            changed.append(f"{k} ({'centred' if usable else 'refused: as before'})")
        print(f"{Path(path).name}: {', '.join(changed) or '-'}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
