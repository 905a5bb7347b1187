"""Shared parts of the benchmark scripts: what a figure was measured on, and its JSON output.

Every benchmark's JSON carries the machine, the load average before and after the
measurement (this machine is shared: a figure without its load is not comparable)
and the git commit with a dirty flag. A script reads `load_average()` before it
starts measuring and passes it to `save`, which reads it again afterwards.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

from leas_jax.stats import newcombe_difference, wilson  # noqa: F401 (the benchmarks' statistics)

REPO = Path(__file__).resolve().parent.parent
RESULTS = Path(__file__).resolve().parent / "results"


def load_average() -> dict:
    """The host's 1-, 5- and 15-minute load averages (runnable processes, all cores together)."""
    one, five, fifteen = os.getloadavg()
    return {"1min": round(one, 2), "5min": round(five, 2), "15min": round(fifteen, 2)}


def cpu_times(stat: str | None = None) -> tuple[int, int] | None:
    """(busy, total) clock ticks of all CPUs together since boot, from /proc/stat's "cpu" line
    (`stat`: that file's text; default: read it); None where there is no such file.
    Busy is everything but idle and iowait."""
    if stat is None:
        try:
            stat = Path("/proc/stat").read_text()
        except OSError:
            return None
    fields = [int(v) for v in stat.splitlines()[0].split()[1:]]
    total = sum(fields[:8])  # user nice system idle iowait irq softirq steal (guest is inside user)
    return total - fields[3] - fields[4], total


def busy_fraction(before, after) -> float | None:
    """Share of the CPUs' time that was busy between two `cpu_times` readings (None without them)."""
    if before is None or after is None or after[1] == before[1]:
        return None
    return round((after[0] - before[0]) / (after[1] - before[1]), 3)


def git_state(repo: Path = REPO) -> dict:
    """Commit of `repo`'s checkout and whether its tracked files differ from it.

    Returns:
        {"commit": 40-hex str or None, "dirty": bool or None}; None when git or the
        repository is missing (a copy of the scripts outside a checkout).
    """
    try:
        commit = subprocess.run(
            ["git", "-C", str(repo), "rev-parse", "HEAD"], capture_output=True, text=True, check=True
        ).stdout.strip()
        status = subprocess.run(
            ["git", "-C", str(repo), "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
    except (OSError, subprocess.CalledProcessError):
        return {"commit": None, "dirty": None}
    return {"commit": commit, "dirty": bool(status.strip())}


# read when a benchmark starts (imports this module), so that the record names the code that ran
GIT_AT_START = git_state()


VECTOR_ISAS = ("avx512f", "avx2", "avx")  # widest first: the widest the CPU reports is recorded


def cpu_identity(cpuinfo: str) -> dict:
    """The first processor of a /proc/cpuinfo text: model name, family / model / stepping and
    the widest x86 vector extension it reports (`VECTOR_ISAS`, "none" if none).

    The host behind "the 2-core AMD EPYC" is not always the same: its model name alone does not
    tell a Zen 3 (family 25 model 1, AVX2, no AVX-512) from a Zen 4 (family 25 model 17,
    AVX-512), and the same commits ran 2-3 x slower on some days than on others
    (docs/results/2026-12-02-column-sampling). Comparing these fields says whether two figures
    came from the same kind of CPU. Missing fields are None.
    """
    fields: dict[str, str] = {}
    for line in cpuinfo.splitlines():
        if not line.strip():
            if fields:
                break  # end of the first processor's block
            continue
        key, _, value = line.partition(":")
        fields.setdefault(key.strip(), value.strip())
    flags = set(fields.get("flags", "").split())

    def as_int(key: str) -> int | None:
        return int(fields[key]) if fields.get(key, "").isdigit() else None

    return {
        "cpu": fields.get("model name"),
        "cpu_family": as_int("cpu family"),
        "cpu_model": as_int("model"),
        "cpu_stepping": as_int("stepping"),
        "vector_isa": next((isa for isa in VECTOR_ISAS if isa in flags), "none"),
    }


def cpu_summary(machine_record: dict) -> str:
    """One line naming a `machine()` record's CPU, e.g. "AMD EPYC, family 25 model 1, avx2, 2 cores"."""
    parts = [str(machine_record.get("cpu"))]
    if machine_record.get("cpu_family") is not None:
        parts.append(f"family {machine_record['cpu_family']} model {machine_record.get('cpu_model')}")
    if machine_record.get("vector_isa"):
        parts.append(machine_record["vector_isa"])
    parts.append(f"{machine_record.get('cores')} cores")
    return ", ".join(parts)


def machine() -> dict:
    """What the figures were measured on: CPU model and vector extensions (`cpu_identity`),
    cores, memory, JAX backend and versions."""
    import jax

    cpu = {"cpu": platform.processor() or platform.machine()}
    memory_gib = None
    try:
        cpu.update(
            {k: v for k, v in cpu_identity(Path("/proc/cpuinfo").read_text()).items() if v is not None}
        )
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal"):
                memory_gib = round(int(line.split()[1]) / 2**20, 1)
                break
    except OSError:
        pass
    device = jax.devices()[0]
    return {
        **cpu,
        "cores": os.cpu_count(),
        "memory_gib": memory_gib,
        "jax": jax.__version__,
        "backend": jax.default_backend(),
        "device_kind": getattr(device, "device_kind", str(device)),
        "python": platform.python_version(),
        "system": platform.platform(),
    }


def provenance(load_before: dict) -> dict:
    """What every benchmark record carries: the time, the machine, the git state when the
    benchmark started, and the load average before (`load_before`) and after (now)."""
    record = {
        "time": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "machine": machine(),
        "git": GIT_AT_START,
        "load_average_before": load_before,
        "load_average_after": load_average(),
    }
    package = sys.modules.get("leas_jax")
    if package is not None and package.__file__:
        # the code measured: another checkout's package when PYTHONPATH points there
        root = Path(package.__file__).resolve().parent.parent
        record["leas_jax"] = {"path": str(root), **git_state(root)}
    return record


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
    """{field: value} from `--set NAME=VALUE` arguments (VALUE a Python literal); a
    malformed one, or a name GeneratorConfig has not, ends the run naming it."""
    import ast
    import dataclasses

    from leas_jax.contacts.planner.config import GeneratorConfig

    fields = {f.name for f in dataclasses.fields(GeneratorConfig)}
    settings = {}
    for assignment in assignments:
        name, sep, text = assignment.partition("=")
        name = name.strip()
        if not sep or name not in fields:
            parser.error(f"--set {assignment!r}: expected NAME=VALUE with NAME a GeneratorConfig field")
        try:
            settings[name] = ast.literal_eval(text.strip())
        except (ValueError, SyntaxError):
            parser.error(f"--set {assignment!r}: VALUE must be a Python literal")
    return settings
