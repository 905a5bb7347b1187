"""`leas walkability`: build the walkability model (data, fit, report) in one command."""

from __future__ import annotations

from pathlib import Path

from leas_jax.arguments import non_negative_int, positive_int
from leas_jax.errors import UsageError


def _scenes(patterns: list[str]):
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


def cmd_walkability(args) -> int:
    """Label, fit, write the weights and the report; print the report's table."""
    import dataclasses

    from leas_jax.feasibility.families import FAMILIES
    from leas_jax.feasibility.walkability import WalkabilityConfig, build, report_table

    out = Path(args.out)
    if out.suffix != ".npz":
        raise UsageError(f"--out: expected a .npz file, got {args.out}")
    held = tuple(f for f in args.held_out.split(",") if f)
    unknown = [f for f in held if f not in FAMILIES]
    if unknown:
        raise UsageError(f"--held-out: unknown families {', '.join(unknown)} (known: {', '.join(FAMILIES)})")
    config = dataclasses.replace(
        WalkabilityConfig(),
        train_families=tuple(f for f in FAMILIES if f not in held),
        held_out_families=held,
        terrains_per_family=args.terrains_per_family,
        test_terrains_per_family=args.test_terrains_per_family,
        poses_per_terrain=args.poses_per_terrain,
    )
    scenes = _scenes(args.scenes or [])
    report = build(out, config, scenes, cache=Path(args.cache), workers=args.workers)
    print(report_table(report), end="")
    print(
        f"wrote {out}, {out.parent / 'walkability.json'}, {out.parent / 'walkability.md'} ({report['seconds']} s)"
    )
    return 0


def register(subparsers) -> None:
    """Add `walkability` to the `leas` parser."""
    from leas_jax.feasibility.walkability import HELD_OUT, WEIGHTS

    parser = subparsers.add_parser(
        "walkability",
        help="build the walkability model of rough ground (data, fit, report)",
        description="Draw terrains of the procedural families, label plausible root poses on them with "
        "the contact generator's walking truth (cached in --cache, resumable), fit the network on the "
        "training families and report sensitivity and specificity (95 %% intervals) on unseen terrains "
        "of those families, on the held-out families and on --scenes, against the calibrated cylinders.",
    )
    parser.add_argument(
        "--out", default=WEIGHTS, metavar="WEIGHTS.npz", help=f"weights file (default {WEIGHTS})"
    )
    parser.add_argument(
        "--held-out",
        default=",".join(HELD_OUT),
        metavar="LIST",
        help=f"families kept out of the fit (default {','.join(HELD_OUT)})",
    )
    parser.add_argument(
        "--terrains-per-family", type=positive_int, default=6, help="fitting terrains (default 6)"
    )
    parser.add_argument(
        "--test-terrains-per-family",
        type=positive_int,
        default=3,
        help="test terrains per family (default 3)",
    )
    parser.add_argument(
        "--poses-per-terrain", type=positive_int, default=300, help="pose draws (default 300)"
    )
    parser.add_argument(
        "--scenes", nargs="*", metavar="GLOB", help="terrain files whose poses test the model too"
    )
    parser.add_argument("--workers", type=non_negative_int, default=2, help="generator processes (default 2)")
    parser.add_argument(
        "--cache", default=".cache", metavar="DIR", help="label cache folder (default .cache)"
    )
    parser.set_defaults(func=cmd_walkability)
