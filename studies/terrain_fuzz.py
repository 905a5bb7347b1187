"""Does the terrain loader load or refuse with TerrainError every malformed file, in bounded time?

Seeded fuzzing: every mutant is loaded, and must either load or raise TerrainError.

Mutants are made from the committed terrain files (terrains/*.toml, tests/data/*.toml) by one to
three seeded text mutations each: a number replaced by an extreme one (5e-324, +-1e308, a
400-digit integer, nan, inf, 2**63 - 1, ...), a value nested 2 to 1000 arrays or inline tables
deep, a value replaced by another TOML type, a line deleted, duplicated or truncated, a key
renamed, a [[box]] block repeated up to 20 000 times, a hostile name, random bytes inserted.
An accepted mutant whose heightfield has at most RASTER_CELLS cells is also rasterised (the
work every command does next). Each mutant runs under a wall-clock limit (SIGALRM); one that
exceeds it counts as a hang.

    python studies/terrain_fuzz.py --mutants 2000 --seed 0 [--time-limit 20] [--out FILE]

Prints and writes (benchmarks/results/terrain_fuzz.json, or --out) the counts per outcome,
the exceptions that were not TerrainError and the hangs (with their mutations), and the
slowest mutant. Exit code 1 when any mutant raised something else or hung.

Results: docs/results/2026-12-01-terrain-fuzz.
"""

from __future__ import annotations

import argparse
import json
import re
import signal
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "benchmarks")]  # the package, benchmarks/common.py

from leas_jax.terrain import TerrainError, loads_terrain  # noqa: E402

RASTER_CELLS = 4_000_000  # accepted mutants up to this size are rasterised too (~0.1 s per 1 M cells)
EXTREME_NUMBERS = (
    "5e-324",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e30",
    "-1e30",
    "1e-30",
    "0",
    "-0.0",
    "nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "-9223372036854775808",
    "1" + "0" * 400,
    "-" + "9" * 400,
    "0.0000001",
    "123456789.0",
    "-1",
    "2",
)
OTHER_VALUES = ('"text"', "true", "1979-05-27T07:32:00Z", "[]", "{}", '[1, "a"]', "[[1.0, 2.0]]", "{ x = 1 }")
HOSTILE_NAMES = (
    '"<img src=x onerror=alert(1)>"',
    '"a\\nb"',
    '""',
    '"   "',
    '"' + "x" * 5000 + '"',
    '"\\u0000"',
)
NUMBER = re.compile(r"(?<![\w.])-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?(?![\w.])")
VALUE = re.compile(r"=\s*(.+)$", re.M)


class Hang(Exception):
    """The per-mutant time limit was reached."""


def _on_alarm(signum, frame):
    raise Hang()


def sources() -> list[tuple[str, str]]:
    """(name, text) of the committed terrain files."""
    files = sorted((ROOT / "terrains").glob("*.toml")) + sorted((ROOT / "tests" / "data").glob("*.toml"))
    return [(str(p.relative_to(ROOT)), p.read_text()) for p in files]


def _replace_number(text, rng):
    spots = list(NUMBER.finditer(text))
    if not spots:
        return text, "no number"
    m = spots[rng.integers(len(spots))]
    new = (
        EXTREME_NUMBERS[rng.integers(len(EXTREME_NUMBERS))]
        if rng.random() < 0.8
        else f"{rng.normal() * 1e3:.6g}"
    )
    return text[: m.start()] + new + text[m.end() :], f"number {m.group()} -> {new[:20]}"


def _nest(text, rng):
    spots = list(VALUE.finditer(text))
    if not spots:
        return text, "no value"
    m = spots[rng.integers(len(spots))]
    depth = int(rng.choice([2, 5, 17, 100, 330, 331, 400, 1000]))
    value = m.group(1)
    if rng.random() < 0.5:
        new = "[" * depth + value + "]" * depth
        kind = "arrays"
    else:
        new = "{ a = " * depth + value + " }" * depth
        kind = "inline tables"
    return text[: m.start(1)] + new + text[m.end(1) :], f"value nested {depth} {kind} deep"


def _retype(text, rng):
    spots = list(VALUE.finditer(text))
    if not spots:
        return text, "no value"
    m = spots[rng.integers(len(spots))]
    new = OTHER_VALUES[rng.integers(len(OTHER_VALUES))]
    return text[: m.start(1)] + new + text[m.end(1) :], f"value {m.group(1)[:20]} -> {new}"


def _lines(text, rng):
    lines = text.splitlines(keepends=True)
    k = int(rng.integers(len(lines)))
    action = rng.integers(3)
    if action == 0:
        del lines[k]
        return "".join(lines), f"line {k} deleted"
    if action == 1:
        lines.insert(k, lines[k])
        return "".join(lines), f"line {k} duplicated"
    cut = int(rng.integers(len(lines[k]) + 1))
    lines[k] = lines[k][:cut] + "\n"
    return "".join(lines), f"line {k} cut at {cut}"


def _rename_key(text, rng):
    keys = list(re.finditer(r"^(\w+)\s*=", text, re.M))
    if not keys:
        return text, "no key"
    m = keys[rng.integers(len(keys))]
    new = ["nam", "bounds2", "box", "scenario", "resolution", "rpy"][rng.integers(6)]
    return text[: m.start(1)] + new + text[m.end(1) :], f"key {m.group(1)} -> {new}"


def _repeat_box(text, rng):
    m = re.search(r"\[\[box\]\][^\[]*", text)
    if m is None:
        return text, "no box"
    count = int(rng.choice([10, 1000, 5000, 20_000]))
    block = m.group()
    return text[: m.end()] + block * count + text[m.end() :], f"box block repeated {count} times"


def _hostile_name(text, rng):
    new = HOSTILE_NAMES[rng.integers(len(HOSTILE_NAMES))]
    return re.sub(r"^name\s*=.*$", lambda _: f"name = {new}", text, count=1, flags=re.M), f"name = {new[:30]}"


def _truncate(text, rng):
    cut = int(rng.integers(len(text) + 1))
    return text[:cut], f"file cut at {cut} of {len(text)}"


def _garbage(text, rng):
    at = int(rng.integers(len(text) + 1))
    junk = "".join(chr(int(c)) for c in rng.integers(1, 0x2FF, size=int(rng.integers(1, 8))))
    return text[:at] + junk + text[at:], f"{len(junk)} random characters at {at}"


MUTATIONS = (
    _replace_number,
    _replace_number,
    _replace_number,
    _nest,
    _retype,
    _lines,
    _rename_key,
    _repeat_box,
    _hostile_name,
    _truncate,
    _garbage,
)


def mutant(texts: list[tuple[str, str]], seed: int) -> tuple[str, str, list[str]]:
    """(source name, mutated text, mutation descriptions) of mutant `seed`."""
    rng = np.random.default_rng(seed)
    name, text = texts[int(rng.integers(len(texts)))]
    done = []
    for _ in range(int(rng.integers(1, 4))):
        text, what = MUTATIONS[int(rng.integers(len(MUTATIONS)))](text, rng)
        done.append(what)
    return name, text, done


def run_one(text: str, source: str, time_limit: float) -> tuple[str, str, float]:
    """(outcome, detail, seconds): outcome 'accepted', 'TerrainError', 'hang' or another exception's name."""
    signal.signal(signal.SIGALRM, _on_alarm)
    signal.setitimer(signal.ITIMER_REAL, time_limit)
    start = time.perf_counter()
    try:
        terrain = loads_terrain(text, source=source)
        nx, ny = terrain.shape
        if nx * ny <= RASTER_CELLS:
            terrain.raster()
        outcome, detail = "accepted", f"{len(terrain.boxes)} boxes, raster {nx} x {ny}"
    except TerrainError as err:
        outcome, detail = "TerrainError", str(err)
        if "\n" in detail:
            outcome = "multi-line TerrainError"
    except Hang:
        outcome, detail = "hang", f"over {time_limit} s"
    except BaseException as err:  # noqa: BLE001 (counting what escapes is the point)
        outcome, detail = type(err).__name__, str(err)[:300]
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
    return outcome, detail, time.perf_counter() - start


def fuzz(mutants: int, seed: int, time_limit: float) -> dict:
    """Run `mutants` seeded mutants (seeds seed .. seed + mutants - 1); the summary dict."""
    texts = sources()
    counts: Counter = Counter()
    failures, slowest = [], (0.0, None)
    start = time.perf_counter()
    for k in range(seed, seed + mutants):
        name, text, done = mutant(texts, k)
        outcome, detail, seconds = run_one(text, f"{name}~{k}", time_limit)
        counts[outcome] += 1
        if outcome not in ("accepted", "TerrainError"):
            failures.append(
                {"seed": k, "source": name, "mutations": done, "outcome": outcome, "detail": detail}
            )
        if seconds > slowest[0]:
            slowest = (seconds, {"seed": k, "source": name, "mutations": done, "outcome": outcome})
    return {
        "mutants": mutants,
        "seed": seed,
        "time_limit_s": time_limit,
        "sources": [n for n, _ in texts],
        "counts": dict(counts),
        "non_terrain_errors": sum(
            v for k, v in counts.items() if k not in ("accepted", "TerrainError", "hang")
        ),
        "hangs": counts.get("hang", 0),
        "failures": failures[:50],
        "slowest_s": round(slowest[0], 3),
        "slowest": slowest[1],
        "seconds": round(time.perf_counter() - start, 1),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mutants", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--time-limit", type=float, default=20.0, help="seconds per mutant (default 20)")
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        help="JSON file, ending in .json (default benchmarks/results/terrain_fuzz.json)",
    )
    args = parser.parse_args(argv)
    if args.out is not None and args.out.suffix != ".json":
        parser.error(f"--out {args.out}: give a file name ending in .json")
    from common import RESULTS, load_average, save

    load_before = load_average()
    report = fuzz(args.mutants, args.seed, args.time_limit)
    print(
        json.dumps(
            {
                k: report[k]
                for k in ("mutants", "counts", "non_terrain_errors", "hangs", "slowest_s", "seconds")
            }
        )
    )
    out = RESULTS / "terrain_fuzz.json" if args.out is None else args.out
    save(out.stem, report, load_before, out.parent)
    return 1 if report["non_terrain_errors"] or report["hangs"] else 0


if __name__ == "__main__":
    sys.exit(main())
