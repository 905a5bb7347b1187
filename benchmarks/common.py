"""Shared parts of the benchmark and study scripts: what a figure was measured on, and its JSON output.

Every benchmark's JSON carries the machine, the load average before and after the
measurement (this machine is shared: a figure without its load is not comparable)
and the git commit with a dirty flag (`leas_jax.provenance`). A script reads `load_average()`
before it starts measuring and passes it to `save`, which reads it again afterwards. The
scripts of studies/ use these helpers too.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from leas_jax.provenance import (  # noqa: F401 (the benchmarks' record helpers)
    busy_fraction,
    cpu_identity,
    cpu_summary,
    cpu_times,
    git_state,
    load_average,
    machine,
)
from leas_jax.provenance import provenance as _provenance
from leas_jax.stats import newcombe_difference, wilson  # noqa: F401 (the benchmarks' statistics)

REPO = Path(__file__).resolve().parent.parent
RESULTS = Path(__file__).resolve().parent / "results"


# read when a benchmark starts (imports this module), so that the record names the code that ran
GIT_AT_START = git_state(REPO)


def provenance(load_before: dict) -> dict:
    """What every benchmark record carries (`leas_jax.provenance.provenance`), with the git state
    read when the benchmark started."""
    return _provenance(load_before, GIT_AT_START)


def add_out_argument(parser: argparse.ArgumentParser) -> None:
    """The `--out DIR` option every benchmark takes (default benchmarks/results/)."""
    parser.add_argument(
        "--out", type=Path, default=RESULTS, help=f"folder of the JSON output (default {RESULTS})"
    )


def save(name: str, payload: dict, load_before: dict, out: Path = RESULTS) -> Path:
    """Write `<out>/<name>.json` atomically and return its path.

    Args:
        name: benchmark name (the file's stem).
        payload: the figures (JSON-serialisable).
        load_before: `load_average()` read before the measurement started.
        out: folder (created if missing).

    The file holds the benchmark's name, its `provenance` and the payload.
    """
    record = {"benchmark": name, **provenance(load_before), **payload}
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{name}.json"
    partial = path.with_name(path.name + ".partial")
    partial.write_text(json.dumps(record, indent=2) + "\n")
    os.replace(partial, path)
    print(
        f"wrote {path} (load average {load_before['1min']} -> {record['load_average_after']['1min']}; "
        f"{cpu_summary(record['machine'])})"
    )
    return path


def add_generator_settings_argument(parser: argparse.ArgumentParser) -> None:
    """`--set NAME=VALUE` (repeatable): a GeneratorConfig field for the run (`generator_settings`)."""
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a GeneratorConfig field for this run, VALUE a Python literal "
        "(e.g. --set 'retry_settings=()' --set max_candidates=12); repeatable",
    )


def generator_settings(assignments: list[str], parser) -> dict:
    """{field: value} from `--set NAME=VALUE` arguments (VALUE a Python literal; for
    `transitions` a dict of `TransitionConfig` fields, `'transitions={}'` its defaults); a
    malformed one, or a name GeneratorConfig has not, ends the run naming it."""
    import ast
    import dataclasses

    from leas_jax.contacts.planner.config import GeneratorConfig, TransitionConfig

    fields = {f.name for f in dataclasses.fields(GeneratorConfig)}
    settings = {}
    for assignment in assignments:
        name, sep, text = assignment.partition("=")
        name = name.strip()
        if not sep or name not in fields:
            parser.error(f"--set {assignment!r}: expected NAME=VALUE with NAME a GeneratorConfig field")
        try:
            settings[name] = ast.literal_eval(text.strip())
            if name == "transitions" and isinstance(settings[name], dict):
                settings[name] = TransitionConfig(**settings[name])
        except (ValueError, SyntaxError, TypeError):
            parser.error(
                f"--set {assignment!r}: VALUE must be a Python literal (transitions: a dict of its fields)"
            )
    return settings
