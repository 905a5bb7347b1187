"""The `leas` command line.

Each sub-package adds its sub-commands with `register(subparsers)`; a command
is a function `args -> int | None` (exit code). Bad input raises a
`LeasError` (or an OSError on a file), printed here on one line with exit
code 2; argparse's own errors are one line too. A negative value after an option
(`--start -0.9,1.7,0`) is read as that option's value (`attach_negative_values`).
"""

from __future__ import annotations

import argparse
import re
import sys

from leas_jax.errors import LeasError

# A token that starts like a negative number: "-0.9,1.7,0", "-1,-2", "-.5,3,0", "-2".
_NEGATIVE_VALUE = re.compile(r"-\.?\d")
# A long option with no "=VALUE" attached: "--start".
_BARE_LONG_OPTION = re.compile(r"--[^=]+")


def attach_negative_values(argv: list[str]) -> list[str]:
    """`argv` with each negative value joined to the long option before it: `--start
    -0.9,1.7,0` becomes `--start=-0.9,1.7,0`; the tokens after a bare `--` are kept as given.

    argparse takes a token that starts with "-" for an option unless it is a plain negative
    number (`-2`, `-.5`), so a comma-separated list such as `-0.9,1.7,0` or `-1,-2` reached
    the option before it as nothing ("expected one argument"). No `leas` option starts with
    a digit, so such a token is always a value; the `--opt=value` spelling is argparse's own
    way to pass a value that starts with "-", and the option's type then checks it (a bad
    value still gets that type's one-line error).
    """
    joined: list[str] = []
    for index, token in enumerate(argv):
        if token == "--":
            return joined + list(argv[index:])
        if joined and _NEGATIVE_VALUE.match(token) and _BARE_LONG_OPTION.fullmatch(joined[-1]):
            joined[-1] = f"{joined[-1]}={token}"
        else:
            joined.append(token)
    return joined


class OneLineErrorParser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line on stderr and exit code 2 (no usage dump), and
    that reads negative values after options (`attach_negative_values`)."""

    def parse_known_args(self, args=None, namespace=None):
        """argparse's `parse_known_args` on `attach_negative_values(args)` (default: sys.argv[1:])."""
        tokens = sys.argv[1:] if args is None else list(args)
        return super().parse_known_args(attach_negative_values(tokens), namespace)

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


def build_parser() -> argparse.ArgumentParser:
    from leas_jax import pipeline
    from leas_jax.contacts import commands as contacts_commands
    from leas_jax.eval import commands as eval_commands
    from leas_jax.feasibility import commands as feasibility_commands
    from leas_jax.motion import commands as motion_commands
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
    motion_commands.register(sub)
    feasibility_commands.register(sub)
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
