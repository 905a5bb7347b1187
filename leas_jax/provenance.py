"""What a measurement was made on: the machine, its load and the code's git state. Host only.

Every benchmark's JSON (benchmarks/common.py) and the learned condition's report (`leas
feasibility condition`) carry the machine, the load average before and after the measurement
(the machines are shared: a figure without its load is not comparable) and the git commit with
a dirty flag. Read `load_average()` and `git_state()` before measuring, pass them to
`provenance` afterwards.
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
import time
from pathlib import Path

from leas_jax.files import REPO_ROOT


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


def git_state(repo: Path = REPO_ROOT) -> dict:
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


def provenance(load_before: dict, git: dict) -> dict:
    """What every measurement record carries: the time, the machine, the git state when the
    measurement started (`git`, a `git_state()` read then), and the load average before
    (`load_before`, a `load_average()` read then) and after (now)."""
    record = {
        "time": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "machine": machine(),
        "git": git,
        "load_average_before": load_before,
        "load_average_after": load_average(),
    }
    package = sys.modules.get("leas_jax")
    if package is not None and package.__file__:
        # the code measured: another checkout's package when PYTHONPATH points there
        root = Path(package.__file__).resolve().parent.parent
        record["leas_jax"] = {"path": str(root), **git_state(root)}
    return record
