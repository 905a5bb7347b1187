"""`leas motion` and `leas simulate`: whole-body motions of contact plans, run in MuJoCo (host-only).

    leas motion PLAN.npz --out MOTION.npz     # exit 0: made and checked, 1: a phase cannot be made
    leas simulate MOTION.npz [--html view.html]   # exit 0: executed, 1: a phase fails or Talos falls
    leas simulate MOTION.npz --video talos.gif    # also an animated GIF (offscreen OpenGL: EGL or OSMesa)

Bad input (missing or malformed files) raises `UsageError`, printed by `leas_jax.cli.main`
on one line with exit code 2.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from leas_jax.errors import UsageError


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
    video = _video_options(args)
    try:
        motion = Motion.load(args.motion)
    except MotionError as exc:
        raise UsageError(f"MOTION: {exc}") from None
    if video is not None:
        from leas_jax.motion.video import VideoError, ensure_gl

        try:
            ensure_gl()  # before simulating: no GL, no minutes of simulation for nothing
        except VideoError as exc:
            raise UsageError(f"--video: {exc}") from None
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
    if video is not None:
        from leas_jax.motion.video import write_video

        size = write_video(motion, rollout, args.video, **video)
        print(f"wrote {args.video} ({size / 1000:.0f} kB)")
    if not rollout.success:
        print(f"{args.motion}: {rollout.message}", file=sys.stderr)
        return 1
    return 0


def _video_options(args) -> dict | None:
    """`write_video`'s keyword arguments from --video*, None without --video (UsageError naming
    the bad option)."""
    if args.video is None:
        for name in ("video_speed", "video_fps", "video_size", "video_window"):
            if getattr(args, name) is not None:
                raise UsageError(f"--{name.replace('_', '-')}: give --video too")
        return None
    if not str(args.video).lower().endswith(".gif"):
        raise UsageError(
            f"--video: {args.video}: only .gif is written (Pillow); .mp4 would need ffmpeg, which this installation lacks"
        )
    out = {}
    for name, key in (("video_speed", "speed"), ("video_fps", "fps")):
        value = getattr(args, name)
        if value is not None:
            if not value > 0 or value != value:
                raise UsageError(f"--{name.replace('_', '-')}: expected a positive number, got {value}")
            out[key] = value
    if args.video_size is not None:
        try:
            width, height = (int(part) for part in args.video_size.lower().split("x"))
        except ValueError:
            raise UsageError(f"--video-size: expected WIDTHxHEIGHT, got {args.video_size!r}") from None
        if not (16 <= width <= 1920 and 16 <= height <= 1080):
            raise UsageError(f"--video-size: {width}x{height} outside 16x16 .. 1920x1080")
        out["size"] = (width, height)
    if args.video_window is not None:
        try:
            start, end = (float(part) for part in args.video_window.split(","))
        except ValueError:
            raise UsageError(f"--video-window: expected START,END in s, got {args.video_window!r}") from None
        if not 0.0 <= start < end:
            raise UsageError(f"--video-window: expected 0 <= START < END, got {args.video_window}")
        out["window"] = (start, end)
    return out


def write_rollout_html(motion, rollout, path) -> None:
    """3D HTML view that animates the planned motion and the simulated rollout together.

    The planned motion is a translucent blue ghost, the simulated robot is drawn
    solid in its own colours, both on one time slider (play, pause, speed), 25
    frames per second; after a fall the simulated robot holds its last recorded
    posture. The footprints are the plan's sole placements; the green line is the
    simulated root path.
    """
    from leas_jax.contacts.viewer import write_motion_html

    summary = rollout.summary()
    outcome = "success" if rollout.success else ("fell" if rollout.fallen else "failed")
    write_motion_html(
        path,
        motion.terrain,
        motion.plan_feet,
        [("planned (ghost)", motion.q, (0.35, 0.6, 1.0, 0.35)), ("simulated", rollout.q, None)],
        motion.dt,
        title="LeaS simulated motion",
        line=rollout.q[:, :3],
        subtitle=(
            f"planned motion (ghost) and simulated rollout, {motion.duration:.1f} s, "
            f"{outcome}, {summary['phases_reached']}/{summary['phases']} phases"
        ),
    )


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
    sim.add_argument(
        "--html",
        default=None,
        help="also write a 3D view that plays the planned motion (ghost) and the simulated rollout",
    )
    sim.add_argument(
        "--video",
        default=None,
        metavar="OUT.gif",
        help="also render the simulated postures offscreen into an animated GIF (MuJoCo with EGL or "
        "OSMesa; exit 2 when no OpenGL backend renders)",
    )
    sim.add_argument("--video-speed", type=float, default=None, help="motion s per video s (default 10)")
    sim.add_argument("--video-fps", type=float, default=None, help="frames per s (default 10)")
    sim.add_argument("--video-size", default=None, help="WIDTHxHEIGHT px (default 320x240)")
    sim.add_argument("--video-window", default=None, help="START,END s of the motion shown (default all)")
    sim.set_defaults(func=cmd_simulate)
