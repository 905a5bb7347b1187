"""The single phases behind this folder's settings, on the cached plans made with the transition
checks (runs/motion_plans_checked, docs/results/2026-12-07-motion-transitions/plans.py).

    python docs/results/2026-12-07-motion-arm-detours/diagnose.py > docs/results/2026-12-07-motion-arm-detours/diagnose.txt

1. Arm detours: which detour each phase of hpp_slalom_debris_0 and hpp_talos_stairs15_0 takes,
   and the arms' least distance to the terrain at their key postures.
2. hpp_talos_stairs15_0 made as it is, without the slower remake (`slowed_duration` 0),
   without centring its one-foot postures (`single_support_margin` 0, which also lets a
   remade single support's CoM reach its sole's edge) and without either: its failing
   equilibrium samples, robustness and the CoM's horizontal acceleration there.
3. hpp_darpa_0 made without the centre-of-pressure remakes nor the one-foot centring
   (`pressure_margin` below any, `single_support_margin` 0 for the key postures), with
   0.6 + 0.8 s and 1.2 + 1.6 s single supports: the least centre-of-pressure margin
   (`motion.pressure_margins`) over its single supports.
4. The one-foot key postures of hpp_rubbles_stairs_3_1: how far inside the stance sole their
   CoM lies (the least ten), and posture 239's.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))
PLANS = ROOT / "runs/motion_plans_checked"


def plan(name: str):
    from leas_jax.contacts.commands import load_plan_file

    return load_plan_file(PLANS / f"{name}.npz")


def arm_detours(name: str) -> None:
    from leas_jax.motion import motion

    chosen = []
    real = motion.detoured_phase

    def logged(spec, phase, sides, *args):
        found = real(spec, phase, sides, *args)
        offsets = None if found is None else found[0].upper_detour
        chosen.append(
            (phase.kind, phase.postures, sorted(sides), None if offsets is None else offsets[offsets != 0])
        )
        return found

    motion.detoured_phase = logged
    try:
        made = motion.make_motion(plan(name), check=False)
    finally:
        motion.detoured_phase = real
    print(f"{name}: {len(made.failures)} failing samples after the detours")
    for kind, postures, sides, offsets in chosen:
        sides_text = "+".join(("left", "right")[s] for s in sides)
        taken = "none clears" if offsets is None else f"offsets {np.round(offsets, 2).tolist()} rad"
        print(f"  {kind} {postures[0]}->{postures[1]}, {sides_text} arm: {taken}")


def key_clearance(name: str, postures) -> None:
    from leas_jax.contacts.robot.clearance import BodyClearance
    from leas_jax.contacts.robot.model import load_talos
    from leas_jax.terrain import loads_terrain

    p = plan(name)
    clearance = BodyClearance(load_talos(), loads_terrain(p.terrain))
    for k in postures:
        print(
            f"  {name} posture {k}: nearest geometry but the feet {clearance.distance(p.q[k], 0.2) * 100:.2f} cm from the terrain"
        )


def unslowed_equilibrium(name: str) -> None:
    from leas_jax.motion.config import MotionConfig
    from leas_jax.motion.motion import make_motion

    for label, config in (
        ("as made", MotionConfig()),
        ("without the slower remake", MotionConfig(slowed_duration=0.0)),
        ("without centring one-foot postures", MotionConfig(single_support_margin=0.0)),
        ("without either", MotionConfig(single_support_margin=0.0, slowed_duration=0.0)),
    ):
        made = make_motion(plan(name), config, check=False)
        failing = [(s, i, msg) for s, i, check, msg in made.failures if check == "equilibrium"]
        print(
            f"{name} {label}: {len(failing)} failing equilibrium samples, {len(made.failures)} failing in all"
        )
        _equilibrium_samples(made, failing)


def _equilibrium_samples(made, failing) -> None:
    """Per phase: its failing samples, the least robustness and the CoM's largest horizontal
    acceleration among them."""
    by_phase = {}
    for sample, index, message in failing:
        by_phase.setdefault(index, []).append((sample, float(message.split()[1])))
    for index, samples in by_phase.items():
        phase = made.phases[index]
        accelerations = [
            np.linalg.norm(((made.com[s + 1] - 2 * made.com[s] + made.com[s - 1]) / made.dt**2)[:2])
            for s, _ in samples
        ]
        print(
            f"  {phase.kind} {phase.postures[0]}->{phase.postures[1]}: {len(samples)} samples from "
            f"t = {samples[0][0] * made.dt:.2f} s, robustness down to {min(r for _, r in samples):.3g}, "
            f"CoM acceleration up to {max(accelerations):.2f} m/s^2 horizontal"
        )


def pressure(name: str) -> None:
    from leas_jax.motion.config import MotionConfig
    from leas_jax.motion.motion import make_motion, pressure_margins

    base = MotionConfig(pressure_margin=-1.0, single_support_margin=0.0)
    for label, config in (
        ("0.6 + 0.8 s", base),
        ("1.2 + 1.6 s", dataclasses.replace(base, lift_duration=1.2, land_duration=1.6)),
    ):
        made = make_motion(plan(name), config, check=False)
        margins = pressure_margins(made)
        per_phase = [
            (np.nanmin(margins[p.start + 1 : p.stop + 1]), p) for p in made.phases if p.single_support
        ]
        least, phase = min(per_phase, key=lambda item: item[0])
        under = sum(m < 0.02 for m, _ in per_phase)
        print(
            f"{name}, single supports {label}: least centre-of-pressure margin {least * 100:.2f} cm "
            f"({phase.kind} {phase.postures[0]}->{phase.postures[1]}); {under} of {len(per_phase)} under 2 cm"
        )


def one_foot_margins(name: str, posture: int) -> None:
    from leas_jax.contacts.robot.model import load_talos
    from leas_jax.motion.motion import posture_frames, sole_corners, support_margin

    p, talos = plan(name), load_talos()
    on = ~np.isnan(p.feet[:, :, 0])
    margins = {}
    for k in np.flatnonzero(on.sum(axis=1) == 1):
        feet, com, _ = posture_frames(talos, p.q[k])
        margins[int(k)] = support_margin(sole_corners(feet, on[k]), com[:2])
    least = sorted(margins.items(), key=lambda item: item[1])[:10]
    print(f"{name}: {len(margins)} one-foot postures; CoM inside the stance sole, least ten (cm):")
    print("  " + ", ".join(f"{k}: {m * 100:.2f}" for k, m in least))
    print(f"  posture {posture}: {margins[posture] * 100:.2f} cm")


def main() -> None:
    print("# 1. arm detours")
    arm_detours("hpp_slalom_debris_0")
    key_clearance("hpp_slalom_debris_0", (35, 36))
    arm_detours("hpp_talos_stairs15_0")
    print("# 2. the slower remake")
    unslowed_equilibrium("hpp_talos_stairs15_0")
    print("# 3. centres of pressure")
    pressure("hpp_darpa_0")
    print("# 4. one-foot postures")
    one_foot_margins("hpp_rubbles_stairs_3_1", 239)


if __name__ == "__main__":
    main()
