"""`leas navigate`: a verified contact plan from a start to a goal (host; JAX inside the command).

    leas navigate --checkpoint DIR --terrain FILE --start X,Y,YAW --goal X,Y --out plan.npz
                  [--html view.html] [--via X,Y ...] [--workers N] [--max-replans K]
                  [--motion motion.npz]

Progress goes to stderr, one line per step; the summary to stdout. The plan file is the
docs/design.md §6 format (`ContactPlan.save`), so `leas verify` and `leas show` read it.
Exit code 0: the goal is reached; 1: it is not (the best partial plan is written when the
generator verified any posture); 2: bad input. With `--motion`, the generator also checks each
step's lift-off and landing as a motion takes them (`contacts.planner.transitions`), and a
reached plan is made into a whole-body motion and simulated in MuJoCo (`leas_jax.motion.execute`): one line gives
the verdict (fallen or not, worst landing error, slip, torque ratio) or the phase that cannot
be made and why; the exit code is 1 unless the motion is made and executes (as `leas motion`
and `leas simulate` say). Module-level imports stay light (no JAX):
the CLI imports every command module to build its parser.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

from leas_jax.arguments import add_policy_start_arguments, comma_floats
from leas_jax.errors import UsageError


def _check_output(argument: str, path, suffix: str) -> Path:
    path = Path(path)
    if not path.parent.is_dir():
        raise UsageError(f"{argument}: {path}: directory {path.parent} does not exist")
    if path.suffix != suffix:
        raise UsageError(f"{argument}: {path}: expected a {suffix} file")
    return path


def navigate_config(args):
    """`NavigateConfig` from the command's options."""
    import dataclasses

    from leas_jax.contacts.planner.config import motion_generator_config
    from leas_jax.navigate.loop import NavigateConfig

    config = NavigateConfig()
    if args.max_replans is not None and args.max_replans < 0:
        raise UsageError(f"--max-replans: expected an integer >= 0, got {args.max_replans}")
    if not args.resolution > 0:
        raise UsageError(f"--resolution: expected a positive number of metres, got {args.resolution}")
    return dataclasses.replace(
        config,
        # a plan made into a motion has its lift-offs and landings checked as it is made
        generator=motion_generator_config() if args.motion is not None else config.generator,
        max_replans=config.max_replans if args.max_replans is None else args.max_replans,
        path_fallback=not args.policy_only,
        lattice=dataclasses.replace(
            config.lattice,
            resolution=args.resolution,
            offer_doubtful=not args.confident_only,
            walkability=args.walkability,
        ),
    )


def _path_walks(result) -> str:
    """ ", N along the searched path" for the attempts whose searched path was walked itself, or ""."""
    walks = sum(attempt.kind == "path" for attempt in result.attempts)
    return f", {walks} along the searched path" if walks else ""


def cmd_navigate(args) -> int:
    """Run one navigate query; write the plan (and the HTML view). Returns the exit code."""
    out = _check_output("--out", args.out, ".npz")
    html = None if args.html is None else _check_output("--html", args.html, ".html")
    motion_out = None if args.motion is None else _check_output("--motion", args.motion, ".npz")
    if args.workers < 0:
        raise UsageError(f"--workers: expected an integer >= 0, got {args.workers}")
    config = navigate_config(args)
    from leas_jax.terrain import load_terrain

    terrain = load_terrain(args.terrain)
    if not Path(args.checkpoint).exists():
        raise UsageError(f"--checkpoint: {args.checkpoint}: no such file or directory")
    from leas_jax.training import load_policy

    policy = load_policy(args.checkpoint, allow_pickle=args.allow_pickle)
    v_max = policy.config.env.v_max
    if not 0.0 <= args.speed <= v_max:
        raise UsageError(f"--speed {args.speed:g}: expected a speed in [0, {v_max:g}] m/s (the env's v_max)")
    x, y, yaw = args.start
    start = (x, y, math.radians(yaw) if args.degrees else yaw)

    def say(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    from leas_jax.navigate.loop import navigate

    result = navigate(
        policy,
        terrain,
        start,
        args.goal,
        config,
        speed=args.speed,
        via=args.via,
        workers=args.workers,
        progress=say,
    )
    seconds = result.seconds
    split = ", ".join(f"{k} {seconds[k]:.2f} s" for k in ("lattice", "search", "rollout", "contact_planning"))
    if result.plan is not None:
        result.plan.save(out)
    status = "reached" if result.success else f"not reached ({result.reason})"
    print(f"navigate: {status}: {result.message}")
    if result.plan is None:
        print(f"no verified posture: {out} not written")
    else:
        print(
            f"{out}: {len(result.plan)} postures, coverage {result.plan.coverage:.3f}, "
            f"final distance {result.final_distance:.2f} m, {result.replans} replans{_path_walks(result)}"
        )
    print(f"time {seconds['total']:.2f} s ({split})")
    if html is not None and result.plan is not None:
        from leas_jax.contacts.viewer import write_html

        write_html(result.plan, html)
        print(f"wrote {html}")
    if motion_out is None:
        return 0 if result.success else 1
    return _execute(result, motion_out)


def _execute(result, motion_out: Path) -> int:
    """Make and simulate the motion of a reached plan; one line on stdout; the exit code."""
    if not result.success:
        print(f"{motion_out}: no motion: the goal is not reached")
        return 1
    from leas_jax.motion.execute import execute_plan

    execution = execute_plan(result.plan)
    if execution.motion is not None:
        execution.motion.save(motion_out)
    print(f"{motion_out}: {execution.line()}")
    return 0 if execution.success else 1


def register(subparsers) -> None:
    """Add `navigate` to the `leas` parser."""
    parser = subparsers.add_parser(
        "navigate",
        help="verified contact plan from a start to a goal",
        description="Search the terrain's valid root poses (a lattice of positions x headings) for a "
        "path to the goal, let the LeaS policy walk it, plan and verify contacts along the "
        "guide, and search again around where the contact generator fails. Writes the "
        "contact plan (docs/design.md §6 format; `leas verify` checks it). Exit code 0: "
        "goal reached; 1: not reached (the best partial plan is written); 2: bad input.",
    )
    add_policy_start_arguments(parser)
    parser.add_argument(
        "--goal", required=True, type=comma_floats(2, "--goal"), metavar="X,Y", help="goal (m)"
    )
    parser.add_argument(
        "--via",
        type=comma_floats(2, "--via"),
        action="append",
        metavar="X,Y",
        help="a point to pass before the goal (repeat, in order)",
    )
    parser.add_argument("--out", required=True, metavar="PLAN.npz", help="contact plan file")
    parser.add_argument("--html", metavar="VIEW.html", help="also write the 3D view of the plan")
    parser.add_argument(
        "--motion",
        metavar="MOTION.npz",
        help="plan with the transitions a motion needs checked (lift-offs, landings), make the reached "
        "plan's whole-body motion, simulate it in MuJoCo and write it here (exit 1 when it cannot be made "
        "or does not execute)",
    )
    parser.add_argument("--degrees", action="store_true", help="YAW of --start is in degrees")
    parser.add_argument("--speed", type=float, default=0.0, help="initial speed along the heading (m/s)")
    parser.add_argument(
        "--workers", type=int, default=1, help="contact-generator processes (0: in this process; default 1)"
    )
    parser.add_argument(
        "--max-replans",
        type=int,
        default=None,
        help="searches after the first that the policy walks (default 5, NavigateConfig; a searched "
        "path walked itself where the generator stopped on the policy's guide is not counted)",
    )
    parser.add_argument(
        "--policy-only",
        action="store_true",
        help="the policy walks every search (default: where the generator stops on the policy's guide, "
        "the searched path itself is walked first)",
    )
    parser.add_argument("--resolution", type=float, default=0.05, help="lattice cell size, m (default 0.05)")
    parser.add_argument(
        "--walkability",
        metavar="WEIGHTS.npz",
        default=None,
        help="the walkability model (`leas feasibility walkability`) judges which plausible ground is confident "
        "(default: the policy's reachability condition)",
    )
    parser.add_argument(
        "--confident-only",
        action="store_true",
        help="search only ground the reachability condition accepts (default: also doubtful ground, "
        "tilted tiles, blocks and stair edges, at a cost, judged by the contact generator)",
    )
    parser.set_defaults(func=cmd_navigate)
