"""What the compile settings of a test run save (tests/conftest.py).

The tests train the same tiny configs many times, each `train` call building and jitting
its own program. This script makes the same `train` call three times in one process,
under three settings, each in its own subprocess (so that none inherits another's
compiled programs), and reports the wall time of every call:

  without cache     no persistent compilation cache, XLA's default optimisation level;
  with cache        a fresh persistent cache: calls after the first load the program
                    instead of compiling it;
  test run          a fresh cache and the test run's `TEST_XLA_FLAG` (LLVM optimisation
                    level 0): the first call compiles faster.

    python benchmarks/compile_cache.py --out docs/results/2026-12-03-test-compile-level
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import common  # noqa: E402

CALLS = 3


def _calls() -> list[float]:
    """Wall time (s) of CALLS identical tiny `train` calls in this process (the tests' config)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from training_helpers import gap_field, tiny_config

    from leas_jax.training import train

    field = gap_field()
    config = tiny_config()
    times = []
    with tempfile.TemporaryDirectory() as out:
        for k in range(CALLS):
            start = time.perf_counter()
            train(config, Path(out) / str(k), progress=False, field=field)
            times.append(round(time.perf_counter() - start, 2))
    return times


def _run(cache_dir: str | None, xla_flags: str | None = None) -> list[float]:
    """`_calls` in a fresh subprocess with this cache directory and XLA_FLAGS (None: neither)."""
    env = {k: v for k, v in os.environ.items() if k not in ("JAX_COMPILATION_CACHE_DIR", "XLA_FLAGS")}
    if cache_dir is not None:
        env["JAX_COMPILATION_CACHE_DIR"] = cache_dir
    if xla_flags is not None:
        env["XLA_FLAGS"] = xla_flags
    done = subprocess.run(
        [sys.executable, __file__, "--child"], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    common.add_out_argument(parser)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(_calls()))
        return
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from conftest import TEST_XLA_FLAG

    load = common.load_average()
    without = _run(None)
    with tempfile.TemporaryDirectory() as cache:
        with_cache = _run(cache)
    with tempfile.TemporaryDirectory() as cache:
        test_run = _run(cache, TEST_XLA_FLAG)
    payload = {
        "calls": CALLS,
        "test_xla_flags": TEST_XLA_FLAG,
        "seconds_without_cache": without,
        "seconds_with_cache": with_cache,
        "seconds_test_run": test_run,
        "later_calls_ratio": round(sum(with_cache[1:]) / sum(without[1:]), 3),
        "first_call_ratio_test_flags": round(test_run[0] / with_cache[0], 3),
        "all_calls_ratio_test_run": round(sum(test_run) / sum(without), 3),
    }
    print(json.dumps(payload, indent=2))
    common.save("compile_cache", payload, load, args.out)


if __name__ == "__main__":
    main()
