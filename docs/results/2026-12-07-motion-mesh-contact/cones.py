"""The friction solver's settings on motions that they change: which cone, which impratio?

    python docs/results/2026-12-07-motion-mesh-contact/cones.py > docs/results/2026-12-07-motion-mesh-contact/cones.txt

Simulates motions kept by execute.sh (runs/motions_checked) on columns (`mesh_contact`), the
noslip solver on, with pyramidal or elliptic friction cones at several impratios; prints each
verdict, the largest slip of a supporting sole and the simulation's CPU time.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))

MOTIONS = ("hpp_talos_stairs15_0", "hpp_talos_plateformes_0", "hpp_slalom_debris_0", "hpp_rubble_1")
SOLVERS = (
    ("pyramidal", 1.0),
    ("pyramidal", 10.0),
    ("elliptic", 1.0),
    ("elliptic", 10.0),
    ("elliptic", 100.0),
)


def main() -> int:
    from leas_jax.motion.config import SimulationConfig
    from leas_jax.motion.motion import Motion
    from leas_jax.motion.simulate import simulate

    for name in MOTIONS:
        motion = Motion.load(ROOT / "runs/motions_checked" / f"{name}.npz")
        print(f"{name} ({len(motion.phases)} phases, {motion.duration:.0f} s)", flush=True)
        for cone, impratio in SOLVERS:
            rollout = simulate(
                motion, config=SimulationConfig(mesh_contact="columns", cone=cone, impratio=impratio)
            )
            slip = max(p.slip for p in rollout.phases if p.reached)
            verdict = "executed" if rollout.success else ("fell" if rollout.fallen else "failed")
            print(
                f"  {cone:9s} impratio {impratio:5.0f}: {verdict:8s} max slip {100 * slip:.2f} cm, "
                f"{rollout.cpu_seconds:.1f} CPU s; {rollout.message}",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
