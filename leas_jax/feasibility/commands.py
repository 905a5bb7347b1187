"""`leas feasibility`: build a learned feasibility model (data, fit, report) in one command.

Two targets: `condition`, the env's learned termination condition on the training arena
(`condition_build`), and `walkability`, the walkability model of rough ground that navigate's
lattice reads (`walkability`, on procedural terrain families).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from leas_jax.arguments import non_negative_float, non_negative_int, positive_int
from leas_jax.errors import UsageError


def scene_terrains(patterns: list[str]):
    """Terrains of the scene files the globs match (sorted), each once; UsageError when a glob
    matches no file."""
    from glob import glob

    from leas_jax.terrain import load_terrain

    files = []
    for pattern in patterns:
        matched = sorted(glob(pattern))
        if not matched:
            raise UsageError(f"--scenes: {pattern!r} matches no file")
        files += [f for f in matched if f not in files]
    return [load_terrain(f) for f in files]


def _condition_options(args):
    """The `ConditionBuild` of the `condition` target's arguments (an option per field;
    --no-mirror for `mirror`).

    Raises:
        UsageError: a --compare-weights file is missing, --weights is no .npz, or a validation
            seed is its training seed (the validation poses must be fresh).
    """
    import dataclasses

    from leas_jax.feasibility.condition_build import ConditionBuild
    from leas_jax.files import resolve_data_path

    for other in args.compare_weights:
        if not resolve_data_path(other).is_file():
            raise UsageError(f"--compare-weights {other}: no such file")
    if Path(args.weights).suffix != ".npz":
        raise UsageError(f"--weights: expected a .npz file, got {args.weights}")
    if args.train_seed == args.test_seed or args.policy_train_seed == args.policy_seed:
        raise UsageError("the training and validation seeds must differ (the validation poses must be fresh)")
    given = {
        f.name: getattr(args, f.name)
        for f in dataclasses.fields(ConditionBuild)
        if f.name not in ("mirror", "compare_weights")
    }
    return ConditionBuild(**given, mirror=not args.no_mirror, compare_weights=tuple(args.compare_weights))


def cmd_condition(args) -> int:
    """Label, fit, write the weights and the report of the learned condition (into --out, by
    default the weights' folder)."""
    from leas_jax.feasibility.condition_build import build
    from leas_jax.files import resolve_data_path

    options = _condition_options(args)
    out = Path(args.out) if args.out else resolve_data_path(args.weights).parent
    build(options, out)
    print(f"wrote {out / 'feasibility_condition.json'} and {out / 'feasibility_condition.md'}")
    return 0


def cmd_walkability(args) -> int:
    """Label, fit, write the weights and the report; print the report's table."""
    import dataclasses

    from leas_jax.feasibility.walkability import (
        HELD_OUT,
        WEIGHTS,
        WalkabilityConfig,
        build,
        build_seeds,
        report_table,
    )
    from leas_jax.terrain.families import FAMILIES

    out = Path(WEIGHTS if args.out is None else args.out)
    if out.suffix != ".npz":
        raise UsageError(f"--out: expected a .npz file, got {args.out}")
    held = HELD_OUT if args.held_out is None else tuple(f for f in args.held_out.split(",") if f)
    unknown = [f for f in held if f not in FAMILIES]
    if unknown:
        raise UsageError(f"--held-out: unknown families {', '.join(unknown)} (known: {', '.join(FAMILIES)})")
    given = {
        name: getattr(args, name)
        for name in (
            "terrains_per_family",
            "test_terrains_per_family",
            "poses_per_terrain",
            "test_poses_per_terrain",
            "held_out_terrains_per_family",
            "held_out_poses_per_terrain",
            "jittered_terrains_per_family",
            "root_height_jitter",
            "footing",
        )
        if getattr(args, name) is not None
    }
    config = dataclasses.replace(
        WalkabilityConfig(),
        train_families=tuple(f for f in FAMILIES if f not in held),
        held_out_families=held,
        **given,
    )
    try:
        build_seeds(config)
    except ValueError as error:
        raise UsageError(f"--terrains-per-family, --jittered-terrains-per-family: {error}") from None
    scenes = scene_terrains(args.scenes or [])
    report = build(out, config, scenes, cache=Path(args.cache), workers=args.workers)
    print(report_table(report), end="")
    print(
        f"wrote {out}, {out.parent / 'walkability.json'}, {out.parent / 'walkability.md'} ({report['seconds']} s)"
    )
    return 0


def register(subparsers) -> None:
    """Add `feasibility` with its targets `condition` and `walkability` to the `leas` parser."""
    parser = subparsers.add_parser(
        "feasibility",
        help="build a learned feasibility model: the env's condition or navigate's walkability",
        description="Label root poses with the contact generator's walking truth (cached, resumable), "
        "fit the network and report it against the cylinders. Targets: condition (the env's learned "
        "termination condition on the training arena) and walkability (rough ground, for navigate).",
    )
    targets = parser.add_subparsers(dest="feasibility_target", metavar="TARGET", required=True)
    _register_condition(targets)
    _register_walkability(targets)


def _register_condition(targets) -> None:
    """Add `condition`: the options of `condition_build.ConditionBuild`."""
    from leas_jax.feasibility.condition_build import DEFAULT_WEIGHTS, ConditionBuild

    d = ConditionBuild()
    parser = targets.add_parser(
        "condition",
        help="the env's learned termination condition on the training arena (data, fit, report)",
        description="Label fresh arena poses and poses of a policy's arena guides with the contact "
        "generator's walking truth (cached in --cache, rebuilt when the terrain, the generator's settings "
        "or its code change), fit the learned condition, write its weights and report sensitivity and "
        "specificity (95 % intervals) on other fresh and policy poses against the cylinders, and its "
        "cost per env step. Relabel after a change to the generator (about 20 min on 2 cores).",
    )
    for name, what in (
        ("train-poses", "fresh poses of the fit"),
        ("test-poses", "fresh poses of the validation"),
    ):
        default = getattr(d, name.replace("-", "_"))
        parser.add_argument(
            f"--{name}", type=positive_int, default=default, help=f"{what} (default {default})"
        )
    for name, what in (
        ("policy-train-poses", "poses of the policy's guides in the fit, 0: none"),
        ("policy-poses", "poses of the policy's guides in the validation, 0: none"),
        ("train-seed", "seed of the fit's fresh poses"),
        ("policy-train-seed", "seed of the fit's policy poses"),
        ("test-seed", "seed of the validation's fresh poses"),
        ("policy-seed", "seed of the validation's policy poses"),
    ):
        default = getattr(d, name.replace("-", "_"))
        parser.add_argument(
            f"--{name}", type=non_negative_int, default=default, help=f"{what} (default {default})"
        )
    parser.add_argument(
        "--policy", default=d.policy, help=f"the policy whose guides give poses (default {d.policy})"
    )
    parser.add_argument(
        "--workers", type=non_negative_int, default=d.workers, help="generator processes (default 2)"
    )
    parser.add_argument(
        "--steps", type=positive_int, default=d.steps, help="Adam steps of the fit (default: FitConfig's)"
    )
    parser.add_argument("--no-mirror", action="store_true", help="do not add the mirrored poses")
    parser.add_argument(
        "--weights",
        default=DEFAULT_WEIGHTS,
        metavar="FILE.npz",
        help=f"weights file (default {DEFAULT_WEIGHTS})",
    )
    parser.add_argument(
        "--compare-weights",
        action="append",
        default=[],
        metavar="FILE",
        help="other learned-condition weights to validate on the same poses (a row each; repeatable), "
        "e.g. the weights a policy was trained with (its run's condition.npz)",
    )
    parser.add_argument(
        "--cost-envs",
        type=non_negative_int,
        default=d.cost_envs,
        help="envs of the cost measurement (0: skip)",
    )
    parser.add_argument(
        "--cost-steps", type=positive_int, default=d.cost_steps, help="env steps per timed call"
    )
    parser.add_argument(
        "--cost-repeats", type=positive_int, default=d.cost_repeats, help="timed calls per condition"
    )
    parser.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="folder of the JSON and markdown report (default: the weights' folder)",
    )
    parser.add_argument(
        "--cache", default=d.cache, metavar="DIR", help=f"label cache folder (default {d.cache})"
    )
    parser.set_defaults(func=cmd_condition)


def _register_walkability(targets) -> None:
    """Add `walkability`: the options of `walkability.WalkabilityConfig` and the build. The defaults
    of --out and --held-out (`walkability.WEIGHTS`, `walkability.HELD_OUT`) are read when the
    command runs: that module imports JAX, which `leas --help` does not."""
    parser = targets.add_parser(
        "walkability",
        help="build the walkability model of rough ground (data, fit, report)",
        description="Draw terrains of the procedural families, label plausible root poses on them with "
        "the contact generator's walking truth (cached in --cache, resumable), fit the network on the "
        "training families and report sensitivity and specificity (95 % intervals) on unseen terrains "
        "of those families, on the held-out families and on --scenes, against the calibrated cylinders.",
    )
    parser.add_argument(
        "--out", default=None, metavar="WEIGHTS.npz", help="weights file (default: the shipped model's)"
    )
    parser.add_argument(
        "--held-out",
        default=None,
        metavar="LIST",
        help="families kept out of the fit, comma-separated (default: the shipped model's)",
    )
    parser.add_argument(
        "--terrains-per-family",
        type=positive_int,
        default=None,
        help="fitting terrains per training family (default: the shipped model's, 120)",
    )
    parser.add_argument(
        "--test-terrains-per-family",
        type=positive_int,
        default=None,
        help="test terrains per family (default 2)",
    )
    parser.add_argument(
        "--poses-per-terrain",
        type=positive_int,
        default=None,
        help="pose draws per fitting terrain (default 25)",
    )
    parser.add_argument(
        "--test-poses-per-terrain",
        type=positive_int,
        default=None,
        help="pose draws per test terrain and scene (default 250)",
    )
    parser.add_argument(
        "--held-out-terrains-per-family",
        type=positive_int,
        default=None,
        help="terrains of each held-out family, seeds 200.. (default 30)",
    )
    parser.add_argument(
        "--held-out-poses-per-terrain",
        type=positive_int,
        default=None,
        help="pose draws per held-out terrain (default 50)",
    )
    parser.add_argument(
        "--jittered-terrains-per-family",
        type=non_negative_int,
        default=None,
        help="more fitting terrains per training family whose root heights are jittered (default 40)",
    )
    parser.add_argument(
        "--root-height-jitter",
        type=non_negative_float,
        default=None,
        metavar="M",
        help="largest move of a jittered root height from the lattice's, m (default 0.10; 0: no jittered test)",
    )
    parser.add_argument(
        "--footing",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the model reads the footing shares at the guide's footstep places: ground a sole "
        "stands on within the generator's friction limit (default: the shipped model's, with)",
    )
    parser.add_argument(
        "--scenes", nargs="*", metavar="GLOB", help="terrain files whose poses test the model too"
    )
    parser.add_argument("--workers", type=non_negative_int, default=2, help="generator processes (default 2)")
    parser.add_argument(
        "--cache", default=".cache", metavar="DIR", help="label cache folder (default .cache)"
    )
    parser.set_defaults(func=cmd_walkability)
