"""`leas terrain ...` sub-commands: generate, show, export.

`leas_jax.cli` calls `register(subparsers)`; each sub-command parser carries
`func(args)`. Bad input raises UsageError or TerrainError (one line); the CLI prints it.
Host code.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from leas_jax.errors import UsageError
from leas_jax.terrain.export import EXPORT_EXTENSIONS, export_terrain
from leas_jax.terrain.loader import load_terrain


def register(subparsers) -> None:
    """Add `terrain` with sub-commands generate, curriculum, show and export to an argparse sub-parser set."""
    parser = subparsers.add_parser(
        "terrain",
        help="generate, show and export terrain files",
        description="Generate, show and export terrain files (TOML, format v1; v2 adds [[mesh]] and [elevation]).",
    )
    commands = parser.add_subparsers(dest="terrain_command", metavar="COMMAND", required=True)

    gen = commands.add_parser(
        "generate",
        help="write the seeded training arena or the evaluation terrains",
        description="Write the training arena of a seed (to --out or stdout), "
        "or the evaluation terrains into --eval-dir.",
    )
    gen.add_argument("--seed", type=int, default=0, help="arena seed (default 0)")
    gen.add_argument("--out", metavar="FILE", help="output TOML file (default: stdout)")
    gen.add_argument("--eval-dir", metavar="DIR", help="write eval_*.toml into DIR instead of the arena")
    gen.set_defaults(func=cmd_generate)

    curriculum = commands.add_parser(
        "curriculum",
        help="write a seeded curriculum arena (rows of difficulty x terrain families)",
        description="Write a curriculum arena: tiles of procedural terrain families (columns along y) "
        "in rows of growing difficulty (along x), with its [curriculum] table (to --out or stdout).",
    )
    curriculum.add_argument("--seed", type=int, default=0, help="arena seed (default 0)")
    curriculum.add_argument("--levels", type=int, default=None, help="rows of difficulty (default 8)")
    curriculum.add_argument(
        "--families",
        default=None,
        help="comma-separated families of the columns (default: all ten, flat first)",
    )
    curriculum.add_argument(
        "--ceiling",
        action="append",
        default=[],
        metavar="FAMILY=D",
        help="the top row of FAMILY at difficulty D in [0, 1] of its range (repeatable; default: "
        "where the generalist preset's termination still lets straight walks across, "
        "CURRICULUM_CEILINGS; FAMILY=1 for its whole range)",
    )
    curriculum.add_argument("--out", metavar="FILE", help="output TOML file (default: stdout)")
    curriculum.set_defaults(func=cmd_curriculum)

    show = commands.add_parser(
        "show",
        help="draw a terrain's heightmap as a PNG",
        description="Top-down heightmap with colour bar and the scenario (start region, target, waypoints).",
    )
    show.add_argument("file", metavar="FILE", help="terrain TOML file")
    show.add_argument("--out", metavar="PNG", required=True, help="output image (.png)")
    show.set_defaults(func=cmd_show)

    export = commands.add_parser(
        "export",
        help="export a terrain to MJCF or a mesh",
        description="Export by extension: .xml (MuJoCo MJCF), .glb, .obj, .stl.",
    )
    export.add_argument("file", metavar="FILE", help="terrain TOML file")
    export.add_argument("--out", metavar="PATH", required=True, help="output file (.xml, .glb, .obj, .stl)")
    export.set_defaults(func=cmd_export)


def cmd_generate(args: argparse.Namespace) -> None:
    """Write the training arena of `args.seed` to `args.out` (or stdout), or the evaluation
    terrains to `args.eval_dir`."""
    from leas_jax.terrain.generate import generate_eval_terrains, generate_training_arena

    if args.eval_dir is not None:
        if args.out is not None:
            raise UsageError("terrain generate: give either --out or --eval-dir, not both")
        directory = Path(args.eval_dir)
        if not directory.is_dir():
            raise UsageError(f"terrain generate: --eval-dir {args.eval_dir}: not a directory")
        for name, text in generate_eval_terrains().items():
            path = directory / f"{name}.toml"
            _write(path, text)
            print(f"wrote {path}")
        return
    if args.seed < 0:
        raise UsageError(f"terrain generate: --seed {args.seed}: must be >= 0")
    text = generate_training_arena(args.seed)
    _emit(text, args.out)


def cmd_curriculum(args: argparse.Namespace) -> None:
    """Write the curriculum arena of `args.seed` to `args.out` (or stdout)."""
    from leas_jax.terrain.curriculum import (
        CURRICULUM_CEILINGS,
        CURRICULUM_FAMILIES,
        CURRICULUM_LEVELS,
        curriculum_terrain,
    )
    from leas_jax.terrain.families import ALL_FAMILIES

    if args.seed < 0:
        raise UsageError(f"terrain curriculum: --seed {args.seed}: must be >= 0")
    levels = CURRICULUM_LEVELS if args.levels is None else args.levels
    if levels < 1:
        raise UsageError(f"terrain curriculum: --levels {levels}: must be >= 1")
    families = CURRICULUM_FAMILIES
    if args.families is not None:
        families = tuple(f.strip() for f in args.families.split(",") if f.strip())
        unknown = [f for f in families if f not in ALL_FAMILIES]
        if unknown or not families:
            raise UsageError(
                f"terrain curriculum: --families {args.families}: unknown {', '.join(unknown) or 'empty list'} "
                f"(known: {', '.join(ALL_FAMILIES)})"
            )
    ceilings = {**CURRICULUM_CEILINGS, **_ceilings(args.ceiling, families)}
    text = curriculum_terrain(args.seed, levels, families, ceilings=ceilings)
    _emit(text, args.out)


def _ceilings(items: list[str], families) -> dict:
    """{family: difficulty} of `--ceiling FAMILY=D` arguments; UsageError naming a bad one."""
    ceilings = {}
    for item in items:
        family, _, value = item.partition("=")
        try:
            ceiling = float(value)
        except ValueError:
            ceiling = None
        if family not in families or ceiling is None or not 0.0 <= ceiling <= 1.0:
            raise UsageError(
                f"terrain curriculum: --ceiling {item}: expected FAMILY=D with FAMILY one of the arena's "
                f"columns ({', '.join(families)}) and D in [0, 1]"
            )
        ceilings[family] = ceiling
    return ceilings


def cmd_show(args: argparse.Namespace) -> None:
    """Draw the heightmap of `args.file` into the PNG `args.out`."""
    out = Path(args.out)
    if out.suffix.lower() != ".png":
        raise UsageError(f"terrain show: --out {args.out}: the image must be a .png file")
    from leas_jax.plotting import terrain_figure

    figure = terrain_figure(load_terrain(args.file))
    try:
        figure.savefig(out, dpi=150)
    except OSError as err:
        raise UsageError(f"terrain show: --out {args.out}: cannot write: {err.strerror or err}") from None
    print(f"wrote {out}")


def cmd_export(args: argparse.Namespace) -> None:
    """Export `args.file` to `args.out` (format by extension)."""
    out = Path(args.out)
    if out.suffix.lower() not in EXPORT_EXTENSIONS:
        raise UsageError(
            f"terrain export: --out {args.out}: unknown format "
            f"{out.suffix or '(no extension)'!r}, use one of {', '.join(EXPORT_EXTENSIONS)}"
        )
    export_terrain(load_terrain(args.file), out)
    print(f"wrote {out}")


def _emit(text: str, out: str | None) -> None:
    """Write `text` to the file `out`, or to stdout when `out` is None."""
    if out is None:
        sys.stdout.write(text)
    else:
        _write(Path(out), text)
        print(f"wrote {out}")


def _write(path: Path, text: str) -> None:
    try:
        path.write_text(text, encoding="utf-8")
    except OSError as err:
        raise UsageError(f"cannot write {path}: {err.strerror or err}") from None
