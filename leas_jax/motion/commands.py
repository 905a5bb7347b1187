"""`leas motion` and `leas simulate`: whole-body motions of contact plans, run in MuJoCo (host-only).

    leas motion PLAN.npz --out MOTION.npz     # exit 0: made and checked, 1: a phase cannot be made
    leas simulate MOTION.npz [--html view.html]   # exit 0: executed, 1: a phase fails or Talos falls

Bad input (missing or malformed files) raises `UsageError`, printed by `leas_jax.cli.main`
on one line with exit code 2.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from leas_jax.errors import UsageError

# Simulated postures stored in the HTML view (one every `HTML_PERIOD` s, at most this many).
HTML_MAX_POSTURES = 400
HTML_PERIOD = 0.25  # s


def cmd_motion(args) -> int:
    """Make, check and save the motion of a plan file; one line on stdout."""
    from leas_jax.contacts.commands import load_plan_file
    from leas_jax.motion.motion import MotionError, make_motion

    plan = load_plan_file(args.plan)
    if len(plan) < 2:
        raise UsageError(f"PLAN: {args.plan}: {len(plan)} posture(s), a motion needs at least 2")
    started = time.perf_counter()
    try:
        motion = make_motion(plan)
    except MotionError as exc:
        print(f"{args.plan}: no motion: {exc}", file=sys.stderr)
        return 1
    seconds = time.perf_counter() - started
    motion.save(args.out)
    kinds = [p.kind for p in motion.phases]
    from leas_jax.contacts.robot.model import load_talos

    ratio = float((np.abs(motion.tau) / load_talos().model.effortLimit[6:]).max())
    print(
        f"{args.plan}: motion of {motion.duration:.2f} s ({len(motion.q)} samples, {len(kinds)} phases: "
        f"{kinds.count('shift')} shift, {kinds.count('lift')} lift, {kinds.count('land')} land), "
        f"max torque ratio {ratio:.2f}, made in {seconds:.1f} s -> {args.out}"
    )
    return 0


def cmd_simulate(args) -> int:
    """Simulate a motion file in MuJoCo; one line on stdout, the failing phase on stderr."""
    from leas_jax.motion.motion import Motion, MotionError
    from leas_jax.motion.simulate import simulate

    if not Path(args.motion).is_file():
        raise UsageError(f"MOTION: {args.motion}: no such file")
    try:
        motion = Motion.load(args.motion)
    except MotionError as exc:
        raise UsageError(f"MOTION: {exc}") from None
    rollout = simulate(motion)
    summary = rollout.summary()
    print(
        f"{args.motion}: {'success' if rollout.success else 'FAILED'}, "
        f"{summary['phases_reached']}/{summary['phases']} phases"
        f"{f', fell at {rollout.fall_time:.2f} s' if rollout.fallen else ''}; "
        f"landings {summary['landings']}, max error {summary['max_landing_position_m'] * 100:.2f} cm / "
        f"{summary['max_landing_angle_deg']:.2f} deg; max slip {summary['max_slip_m'] * 100:.2f} cm; "
        f"max torque ratio {summary['max_torque_ratio']:.2f}; {motion.duration:.1f} s simulated in "
        f"{rollout.seconds:.1f} s"
    )
    if args.html:
        write_rollout_html(motion, rollout, args.html)
        print(f"wrote {args.html}")
    if not rollout.success:
        print(f"{args.motion}: {rollout.message}", file=sys.stderr)
        return 1
    return 0


def write_rollout_html(motion, rollout, path) -> None:
    """3D HTML view of the simulated postures (the contact plan viewer, one posture per 0.25 s).

    The footprints are the plan's sole placements; the green line is the simulated root path.
    """
    from leas_jax.contacts.robot.model import matrix_from_quat_xyzw, yaw_of_matrix
    from leas_jax.contacts.viewer import write_html

    stride = max(1, round(HTML_PERIOD / motion.dt))
    chosen = np.arange(0, len(rollout.q), stride)
    q = rollout.q[chosen]
    yaw = yaw_of_matrix(matrix_from_quat_xyzw(rollout.q[:, 3:7]))
    path_xyzyaw = np.c_[rollout.q[:, :3], yaw]
    view = SimpleNamespace(
        q=q,
        feet=motion.plan_feet,
        guide_index=chosen,
        last_valid_index=len(rollout.q) - 1,
        coverage=1.0,
        terrain=motion.terrain,
        guide=path_xyzyaw,
    )
    write_html(view, path, max_postures=HTML_MAX_POSTURES)


def register(subparsers) -> None:
    """Add `leas motion` and `leas simulate` to the `leas` parser."""
    motion = subparsers.add_parser(
        "motion",
        help="whole-body motion of a contact plan (100 Hz, checked)",
        description=(
            "Turn a contact plan into a whole-body Talos motion through its key postures: "
            "double-support CoM shifts, single-support swings, inverse dynamics; checks joint, "
            "velocity and torque limits and equilibrium at every sample. Exit 1 when a phase cannot be made."
        ),
    )
    motion.add_argument("plan", metavar="PLAN", help="contact plan file (.npz, `leas plan`)")
    motion.add_argument("--out", required=True, help="motion file to write (.npz)")
    motion.set_defaults(func=cmd_motion)

    sim = subparsers.add_parser(
        "simulate",
        help="run a motion in MuJoCo physics",
        description=(
            "Execute a motion file with Talos in MuJoCo (1 kHz, inverse-dynamics feed-forward + joint PD) "
            "and report per phase: falls, landing errors, slip, torque, other terrain contacts. "
            "Exit 1 when a phase fails."
        ),
    )
    sim.add_argument("motion", metavar="MOTION", help="motion file (.npz, `leas motion`)")
    sim.add_argument("--html", default=None, help="also write a 3D view of the simulated postures")
    sim.set_defaults(func=cmd_simulate)
