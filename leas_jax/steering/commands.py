"""`leas rollout`: a guide path from a trained policy, as a guide file and a plot."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from leas_jax.arguments import add_policy_start_arguments, comma_floats
from leas_jax.contacts.plan import MAX_GUIDE_POSES
from leas_jax.errors import UsageError

# Longest horizon `leas rollout` accepts: its guide (horizon + 1 poses) is one `leas plan` and
# `leas show` accept (MAX_GUIDE_POSES, 2 000 s at the paper's 0.1 s step).
MAX_ROLLOUT_STEPS = MAX_GUIDE_POSES - 1


def _horizon(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer number of steps, got {text!r}") from None
    if not 1 <= value <= MAX_ROLLOUT_STEPS:
        raise argparse.ArgumentTypeError(f"expected 1 to {MAX_ROLLOUT_STEPS} steps, got {text!r}")
    return value


def _finite(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not np.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def save_guide(path: Path, guide: np.ndarray, timestep: float, terrain_text: str, target) -> None:
    """Write a guide file (docs/design.md §6): guide [T, 4], timestep, terrain text, target [2]; atomic."""
    import io

    from leas_jax.training.checkpoint import atomic_write_bytes

    buffer = io.BytesIO()
    np.savez(
        buffer,
        guide=np.asarray(guide, np.float64),
        timestep=np.float64(timestep),
        terrain=np.array(terrain_text),
        target=np.asarray(target, np.float64),
    )
    atomic_write_bytes(path, buffer.getvalue())


def cmd_rollout(args) -> int:
    from leas_jax.plotting import plot_paths
    from leas_jax.steering.leas import rollout
    from leas_jax.terrain import load_terrain
    from leas_jax.training.policy import load_policy

    out = Path(args.out)
    if out.suffix != ".npz":
        raise UsageError(f"--out must end in .npz, got {args.out!r}")
    policy = load_policy(args.checkpoint, allow_pickle=args.allow_pickle)
    v_max = policy.config.env.v_max
    if not 0.0 <= args.speed <= v_max:
        raise UsageError(f"--speed {args.speed:g}: expected a speed in [0, {v_max:g}] m/s (the env's v_max)")
    terrain = load_terrain(args.terrain)
    x, y, yaw = args.start
    (xmin, ymin), (xmax, ymax) = terrain.bounds
    for name, (px, py) in (("--start", (x, y)), ("--target", tuple(args.target))):
        if not (xmin <= px <= xmax and ymin <= py <= ymax):
            raise UsageError(f"{name} ({px:g}, {py:g}) lies outside the terrain bounds of {args.terrain}")
    guide = rollout(
        policy,
        terrain,
        (x, y, np.deg2rad(yaw) if args.degrees else yaw),
        args.target,
        speed=args.speed,
        max_steps=args.max_steps,
    )
    save_guide(out, guide, policy.config.env.timestep, terrain.text, args.target)
    png = out.with_suffix(".png")
    plot_paths(terrain, [guide], png, title=f"LeaS rollout: {len(guide)} poses", target=args.target)
    distance = float(np.linalg.norm(guide[-1, :2] - np.asarray(args.target)))
    print(
        f"guide: {len(guide)} poses, {len(guide) * policy.config.env.timestep:.1f} s, "
        f"ends {distance:.2f} m from the target -> {out}, {png}"
    )
    if args.plan:
        from leas_jax.contacts import plan_contacts

        plan = plan_contacts(terrain, guide, policy.config.env.timestep)
        plan.save(args.plan)
        print(
            f"contact plan: coverage {plan.coverage:.3f}, last valid index {plan.last_valid_index} -> {args.plan}"
        )
    return 0


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "rollout",
        help="guide path of a trained policy",
        description="Roll a trained LeaS policy from a start to a target; write the "
        "guide file (.npz, docs/design.md §6) and a top-down PNG beside it.",
    )
    add_policy_start_arguments(parser)
    parser.add_argument(
        "--target", required=True, type=comma_floats(2, "--target"), metavar="X,Y", help="target (m)"
    )
    parser.add_argument(
        "--speed", type=_finite, default=0.0, help="initial speed along the heading (m/s, in [0, v_max])"
    )
    parser.add_argument(
        "--max-steps",
        type=_horizon,
        default=None,
        help=f"horizon in steps, 1 to {MAX_ROLLOUT_STEPS} (default: the policy's episode length, 400)",
    )
    parser.add_argument("--degrees", action="store_true", help="YAW of --start is in degrees")
    parser.add_argument("--out", required=True, metavar="PATH.npz", help="guide file; the PNG goes beside it")
    parser.add_argument("--plan", metavar="PLAN.npz", help="also run the contact generator and save its plan")
    parser.set_defaults(func=cmd_rollout)
