"""`leas run`: the main job, geometric training, planner fine-tuning, then the report.

Outside `leas_jax.training` because it evaluates too: training imports no evaluation code.
"""

from __future__ import annotations

from pathlib import Path

from leas_jax.arguments import non_negative_int, positive_int
from leas_jax.errors import UsageError
from leas_jax.training.commands import add_training_arguments, config_from_args


def cmd_run(args) -> int:
    """Geometric training, planner-in-the-loop fine-tuning, evaluation report (each phase resumes)."""
    from leas_jax.eval.report import write_report
    from leas_jax.training.config import PLANNER_PRESETS, preset
    from leas_jax.training.loop import train

    out = Path(args.out)
    if args.mode != "geometric" or args.init is not None:
        raise UsageError("leas run trains both phases itself: drop --mode and --init")
    geometric = config_from_args(args)
    train(geometric, out / "geometric", progress=not args.no_progress, allow_pickle=args.allow_pickle)
    planner_steps = (
        PLANNER_PRESETS[args.preset]["num_timesteps"] if args.planner_steps is None else args.planner_steps
    )
    if planner_steps > 0:
        overrides = {
            "num_timesteps": planner_steps,
            "init_from": str(out / "geometric"),
            "terrain": geometric.terrain,
            "seed": geometric.seed,
            "env": geometric.env,
        }
        train(
            preset(args.preset, mode="planner", **overrides),
            out / "planner",
            progress=not args.no_progress,
            workers=args.workers,
            address=args.ray_address,
            allow_pickle=args.allow_pickle,
        )
    workers = 2 if args.workers is None else args.workers
    report = write_report(
        out,
        n_episodes=args.eval_episodes,
        compare_starts=args.compare_starts,
        baseline_starts=args.baseline_starts,
        workers=workers,
    )
    print(f"report: {report}")
    return 0


def register(subparsers) -> None:
    run = subparsers.add_parser(
        "run",
        help="the main job: train, fine-tune with the planner, evaluate",
        description="Geometric training (<out>/geometric), planner-in-the-loop "
        "fine-tuning (<out>/planner), then <out>/report.md: learning "
        "curves, rollouts, coverage before/after, Table II against the "
        "baselines. Each phase resumes if interrupted.",
    )
    add_training_arguments(run)
    run.add_argument(
        "--eval-episodes",
        type=positive_int,
        default=256,
        help="episodes per geometric evaluation metric (default 256)",
    )
    run.add_argument(
        "--planner-steps",
        type=non_negative_int,
        default=None,
        help="kept env steps of planner-in-the-loop fine-tuning (default: the preset's planner budget, "
        "`quick` 100 000; 0 skips it)",
    )
    run.add_argument(
        "--compare-starts",
        type=positive_int,
        default=24,
        help="starts per terrain for the before/after coverage comparison (default 24)",
    )
    run.add_argument(
        "--baseline-starts",
        type=positive_int,
        default=10,
        help="trajectories per Table II cell in the report (default 10; the paper: 60)",
    )
    run.set_defaults(func=cmd_run)
