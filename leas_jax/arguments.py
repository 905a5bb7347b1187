"""Argument types and options shared by the command modules (`<package>.commands`).

Apart from `leas_jax.cli` so that the command modules need not import the parser that
imports them.
"""

from __future__ import annotations

import argparse
import math


def _integer_at_least(text: str, minimum: int, expected: str) -> int:
    """An integer >= `minimum` parsed from `text` (underscores allowed, as in 150_000), else an
    argparse error saying what was `expected`."""
    try:
        value = int(text.replace("_", ""))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}") from None
    if value < minimum:
        raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}")
    return value


def positive_int(text: str) -> int:
    """argparse type: an integer > 0 (underscores allowed, as in 150_000)."""
    return _integer_at_least(text, 1, "a positive integer")


def non_negative_int(text: str) -> int:
    """argparse type: an integer >= 0 (underscores allowed)."""
    return _integer_at_least(text, 0, "an integer >= 0")


def comma_floats(count: int, name: str):
    """argparse type of the argument `name`: `count` finite comma-separated numbers (X,Y,YAW)."""

    def parse(text: str) -> list[float]:
        try:
            values = [float(v) for v in text.split(",")]
        except ValueError:
            values = []
        if len(values) != count or not all(math.isfinite(v) for v in values):
            raise argparse.ArgumentTypeError(
                f"{name} expects {count} finite comma-separated numbers, got {text!r}"
            )
        return values

    return parse


def _finite_non_negative(text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected {what} >= 0, got {text!r}") from None
    if not (value >= 0.0 and value != float("inf")):
        raise argparse.ArgumentTypeError(f"expected a finite {what} >= 0, got {text!r}")
    return value


def non_negative_seconds(text: str) -> float:
    """argparse type: a finite number of seconds >= 0."""
    return _finite_non_negative(text, "number of seconds")


def non_negative_float(text: str) -> float:
    """argparse type: a finite number >= 0."""
    return _finite_non_negative(text, "number")


def add_allow_pickle_argument(parser, what: str) -> None:
    """`--allow-pickle`: read legacy pickle policies/checkpoints (they can run code when loaded)."""
    parser.add_argument(
        "--allow-pickle",
        action="store_true",
        help=f"also read {what} in the pickle format of earlier versions; unpickling a file can run "
        "code from it, so only for files you trust (a warning is printed)",
    )


def add_ray_address_argument(parser, use: str) -> None:
    """`--ray-address` of the commands that run the contact generator; `use` says what runs on Ray."""
    parser.add_argument(
        "--ray-address",
        metavar="ADDRESS",
        default=None,
        help=f"{use} on Ray instead of local processes (pip install 'leas-jax[cluster]'): "
        "ray://HOST:PORT (Ray client of a cluster), auto (the cluster this machine belongs "
        "to) or local (a new local Ray instance)",
    )


def add_policy_start_arguments(parser) -> None:
    """`--checkpoint`, `--allow-pickle`, `--terrain` and `--start X,Y,YAW`: the arguments of the
    commands that walk a policy from a start on a terrain (`leas rollout`, `leas navigate`)."""
    parser.add_argument("--checkpoint", required=True, metavar="DIR", help="run directory or policy.ckpt")
    add_allow_pickle_argument(parser, "a policy")
    parser.add_argument("--terrain", required=True, metavar="FILE", help="terrain file (TOML)")
    parser.add_argument(
        "--start",
        required=True,
        type=comma_floats(3, "--start"),
        metavar="X,Y,YAW",
        help="start position (m) and yaw (rad, or degrees with --degrees)",
    )
