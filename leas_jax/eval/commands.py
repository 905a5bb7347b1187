"""`leas evaluate`: the paper's experiments (Table II, Figs. 6-9) by one command."""

from __future__ import annotations

import argparse
from pathlib import Path

from leas_jax.errors import UsageError
from leas_jax.eval.scenarios import METHODS
from leas_jax.terrain.generate import SCENARIOS
from leas_jax.terrain.loader import MAX_STARTS

# Plans per scenario and method that `--motion` makes into motions and simulates by default.
MOTION_PLANS = 3


def _positive_int(name: str, allow_zero: bool = False, maximum: int | None = None):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} expects an integer, got {text!r}") from None
        if value < 0 or (value == 0 and not allow_zero):
            raise argparse.ArgumentTypeError(
                f"{name} expects an integer >= {0 if allow_zero else 1}, got {text!r}"
            )
        if maximum is not None and value > maximum:
            raise argparse.ArgumentTypeError(f"{name} expects an integer <= {maximum}, got {text!r}")
        return value

    return parse


def _positive_seconds(name: str):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} expects a number of seconds, got {text!r}") from None
        if not 0.0 < value < float("inf"):
            raise argparse.ArgumentTypeError(f"{name} expects a positive number of seconds, got {text!r}")
        return value

    return parse


def _checkpoint(args):
    """--checkpoint as given, or loaded here when --allow-pickle lets a legacy pickle policy in."""
    if args.checkpoint is None or not args.allow_pickle:
        return args.checkpoint
    from leas_jax.training.policy import load_policy

    return load_policy(args.checkpoint, allow_pickle=True)


def cmd_evaluate(args) -> int:
    from leas_jax.contacts.planner.config import motion_generator_config
    from leas_jax.eval.evaluate import evaluate, parse_methods
    from leas_jax.eval.tables import table_ii_markdown

    if args.terrain is not None and args.scenario is not None:
        raise UsageError("give either --scenario or --terrain, not both")
    if args.terrain is None and args.scenario is None:
        raise UsageError("one of --scenario or --terrain is required")
    if args.terrain is not None and not Path(args.terrain).is_file():
        raise UsageError(f"--terrain: no such file {args.terrain!r}")
    scenarios = None
    if args.scenario is not None:
        scenarios = [s.strip() for s in args.scenario.split(",") if s.strip()]
        unknown = [s for s in scenarios if s not in SCENARIOS + ("all",)]
        if unknown or not scenarios:
            raise UsageError(
                f"--scenario: unknown scenario {', '.join(unknown) or repr(args.scenario)} "
                f"(expected {'|'.join(SCENARIOS)}|all)"
            )
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {args.out!r} exists and is not a directory")
    if args.motion_plans is not None and not args.motion:
        raise UsageError("--motion-plans: give --motion too")
    motion_plans = (args.motion_plans or MOTION_PLANS) if args.motion else 0
    report = evaluate(
        scenarios,
        parse_methods(args.methods),
        _checkpoint(args),
        out,
        args.n_starts,
        args.workers,
        terrain_file=args.terrain,
        progress=not args.no_progress,
        address=args.ray_address,
        leas_stop_at_invalid=args.leas_stop_at_invalid,
        rbkino_timestep=args.rbkino_timestep,
        motion_plans=motion_plans,
        navigate_config=_navigate_config(args),
        generator_config=motion_generator_config() if args.motion else None,
    )
    if report.get("table_ii"):
        print(table_ii_markdown(report["table_ii"]))
    for row in report["rows"]:
        if row["cell"] == "all" or len(report["scenarios"][row["scenario"]]["cells"]) == 1:
            print(
                f"{row['scenario']:12s} {row['method']:11s} n={row['n']:3d} coverage {row['coverage']:5.1f}% "
                f"success {row['success']:5.1f}%"
            )
    for name, scenario in report["scenarios"].items():
        for method, s in scenario.get("motion", {}).get("summary", {}).items():
            worst = s["max_landing_position_m"]
            print(
                f"{name:12s} {method:11s} motions: {s['made']}/{s['n']} made, {s['without_fall']} without a fall, "
                f"{s['executed']} executed; max landing error "
                + ("-" if worst is None else f"{worst * 100:.2f} cm / {s['max_landing_angle_deg']:.2f} deg")
            )
    print(
        f"{report['seconds']:.1f} s -> {out}/results.json, table.md, table.csv, guides.npz, "
        + ", ".join(report.get("figures", []))
    )
    return 0


def cmd_hole_sweep(args) -> int:
    from leas_jax.eval.evaluate import parse_methods
    from leas_jax.eval.sweeps import DEFAULT_METHODS, hole_width_sweep, markdown, parse_widths

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {args.out!r} exists and is not a directory")
    report = hole_width_sweep(
        parse_widths(args.widths),
        parse_methods(args.methods) or DEFAULT_METHODS,
        _checkpoint(args),
        args.n_starts,
        args.workers,
        out,
        progress=not args.no_progress,
    )
    print(markdown(report), end="")
    print(f"{report['seconds']:.1f} s -> {out}/hole_sweep.json, hole_sweep.md, hole_sweep.png")
    return 0


def cmd_arena_check(args) -> int:
    from leas_jax.eval.arena_check import arena_check, markdown, parse_seeds

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {args.out!r} exists and is not a directory")
    if args.terrain is not None and not Path(args.terrain).is_file():
        raise UsageError(f"--terrain: no such file {args.terrain!r}")
    report = arena_check(
        _checkpoint(args), args.episodes, parse_seeds(args.seeds), terrain_file=args.terrain, out=out
    )
    print(markdown(report), end="")
    print(f"{report['seconds']:.1f} s -> {out}/arena_check.json, arena_check.md, arena_failures.png")
    return 0


def _add_run_arguments(parser, methods_default: str, starts_per: str, workers_more: str = "") -> None:
    """--methods, --checkpoint, --allow-pickle, --n-starts, --workers, --no-progress and --out of the
    commands that run scenarios."""
    from leas_jax.arguments import add_allow_pickle_argument

    parser.add_argument(
        "--methods",
        metavar="LIST",
        help=f"comma-separated subset of {','.join(METHODS)} (default: {methods_default})",
    )
    parser.add_argument(
        "--checkpoint", metavar="DIR", help="run directory or policy.ckpt (for leas, leas_rrt)"
    )
    add_allow_pickle_argument(parser, "a policy")
    parser.add_argument(
        "--n-starts",
        type=_positive_int("--n-starts", maximum=MAX_STARTS),
        default=None,
        metavar="N",
        help=f"starts per {starts_per}, at most {MAX_STARTS} (default: the scenario table's n_starts, 60)",
    )
    parser.add_argument(
        "--workers",
        type=_positive_int("--workers", allow_zero=True),
        default=None,
        metavar="N",
        help=f"contact-generator and RRT processes (default one per CPU; 0: in-process){workers_more}",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    parser.add_argument("--out", required=True, metavar="DIR", help="output directory")


def _navigate_config(args):
    """The navigate method's `NavigateConfig`: its defaults, with the walkability model given and
    the searched path's fallback off where asked."""
    if args.navigate_walkability is None and not args.navigate_policy_only:
        return None
    import dataclasses

    from leas_jax.navigate.loop import NavigateConfig

    config = NavigateConfig()
    return dataclasses.replace(
        config,
        path_fallback=not args.navigate_policy_only,
        lattice=dataclasses.replace(config.lattice, walkability=args.navigate_walkability),
    )


def register(subparsers) -> None:
    from leas_jax.arguments import add_ray_address_argument

    parser = subparsers.add_parser(
        "evaluate",
        help="baselines and LeaS on the paper's scenarios (Table II, Figs. 6-9)",
        description="Draw seeded starts from each scenario's [scenario] table, build guide paths with each steering "
        "method, validate them with the contact generator in parallel and write results.json, table.md, "
        "table.csv, guides.npz and one PNG per scenario. `ground` runs Table II (3 yaw ranges x 3 "
        "initial speeds).",
    )
    parser.add_argument(
        "--scenario", metavar="NAME", help=f"{'|'.join(SCENARIOS)}|all, or a comma-separated list"
    )
    parser.add_argument(
        "--terrain", metavar="FILE", help="any terrain file with a [scenario] table (instead of --scenario)"
    )
    _add_run_arguments(
        parser,
        "the paper's methods for each scenario",
        "cell",
        ", or Ray actors with --ray-address (default: the cluster's CPUs)",
    )
    add_ray_address_argument(parser, "run the contact generator")
    parser.add_argument(
        "--leas-stop-at-invalid",
        action="store_true",
        help="end LeaS paths before the first pose the reachability condition rejects, as training "
        "episodes end (default: the policy rolls on and the contact generator alone judges its "
        "paths, as it judges the baselines' paths)",
    )
    parser.add_argument(
        "--rbkino-timestep",
        type=_positive_seconds("--rbkino-timestep"),
        default=None,
        metavar="S",
        help="s between the poses of RBKino's and RBKino+RRT's paths handed to the contact generator "
        "(default 0.01, as HPP's generator samples a path; 0.1, the env's, costs about a third of the "
        "contact planning but the generator then cannot follow RBKino's turns from starts turned away)",
    )
    parser.add_argument(
        "--navigate-walkability",
        metavar="WEIGHTS.npz",
        default=None,
        help="the navigate method's lattice judges confident ground with this walkability model "
        "(`leas feasibility walkability`; default: the policy's reachability condition)",
    )
    parser.add_argument(
        "--navigate-policy-only",
        action="store_true",
        help="the navigate method's policy walks every search (default: where the generator stops on "
        "the policy's guide, the searched path itself is walked first)",
    )
    parser.add_argument(
        "--motion",
        action="store_true",
        help="also make a few of each scenario's LeaS and navigate plans that cover their guide into "
        "whole-body motions and simulate them in MuJoCo (results.json's `motion`, table.md); every "
        "method's plans then have the transitions a motion needs checked as they are made",
    )
    parser.add_argument(
        "--motion-plans",
        type=_positive_int("--motion-plans"),
        default=None,
        metavar="N",
        help=f"plans per scenario and method that --motion executes (default {MOTION_PLANS})",
    )
    parser.set_defaults(func=cmd_evaluate)

    from leas_jax.eval.sweeps import DEFAULT_METHODS, DEFAULT_WIDTHS

    sweep = subparsers.add_parser(
        "hole-sweep",
        help="the hole scenario with holes of several widths (how wide a hole LeaS walks round)",
        description="Run eval_hole's scenario on copies of its terrain whose hole has each given width across the "
        "line to the target, and write hole_sweep.json, hole_sweep.md, hole_sweep.png (success against "
        "width) and one scenario figure per width.",
    )
    sweep.add_argument(
        "--widths",
        default=",".join(f"{w:g}" for w in DEFAULT_WIDTHS),
        metavar="LIST",
        help="comma-separated hole widths in m, each in (0, 7] (default: %(default)s)",
    )
    _add_run_arguments(sweep, ",".join(DEFAULT_METHODS), "width")
    sweep.set_defaults(func=cmd_hole_sweep)

    from leas_jax.arguments import add_allow_pickle_argument

    check = subparsers.add_parser(
        "arena-check",
        help="speed on eval_ground, safety on the training arena, and why episodes end invalid",
        description="The foundation's acceptance figures of a policy (deterministic): mean speed along the target "
        "direction on eval_ground, the fraction of random arena episodes without an invalid pose per "
        "evaluation seed, and for the others the failed reachability term, where the offending terrain "
        "lies around the root and the speed at the failure. Writes arena_check.json, arena_check.md and "
        "arena_failures.png.",
    )
    check.add_argument("--checkpoint", required=True, metavar="DIR", help="run directory or policy.ckpt")
    add_allow_pickle_argument(check, "a policy")
    check.add_argument(
        "--episodes",
        type=_positive_int("--episodes"),
        default=2048,
        metavar="N",
        help="arena episodes per seed (default: %(default)s)",
    )
    check.add_argument(
        "--seeds", default="0,1", metavar="LIST", help="evaluation seeds (default: %(default)s)"
    )
    check.add_argument("--terrain", metavar="FILE", help="the arena (default: the policy's training terrain)")
    check.add_argument("--out", required=True, metavar="DIR", help="output directory")
    check.set_defaults(func=cmd_arena_check)
