"""The `leas` command line.

Each sub-package adds its sub-commands with `register(subparsers)`; a command
is a function `args -> int | None` (exit code). Bad input raises a
`LeasError` (or an OSError on a file), printed here on one line with exit
code 2; argparse's own errors are one line too.
"""

from __future__ import annotations

import argparse
import sys

from leas_jax.errors import LeasError


class OneLineErrorParser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line on stderr and exit code 2 (no usage dump)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


def build_parser() -> argparse.ArgumentParser:
    from leas_jax import pipeline
    from leas_jax.contacts import commands as contacts_commands
    from leas_jax.eval import commands as eval_commands
    from leas_jax.navigate import commands as navigate_commands
    from leas_jax.steering import commands as steering_commands
    from leas_jax.terrain import commands as terrain_commands
    from leas_jax.training import commands as train_commands

    parser = OneLineErrorParser(prog="leas", description="LeaS: learn to steer a locomotion contact planner.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    train_commands.register(sub)
    pipeline.register(sub)
    steering_commands.register(sub)
    terrain_commands.register(sub)
    contacts_commands.register(sub)
    eval_commands.register(sub)
    navigate_commands.register(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        code = args.func(args)
    except LeasError as exc:
        print(f"leas {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"leas {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"leas {args.command}: interrupted", file=sys.stderr)
        return 130
    return int(code or 0)


if __name__ == "__main__":
    sys.exit(main())
