"""Planner-in-the-loop training throughput (env steps per second, validation included).

Runs `--iterations` planner-mode iterations on the training arena (from a
geometric run with `--init`, else from scratch) with local contact workers,
and reports kept and rolled env steps per second and the fraction of time the
learner waited for validation. Writes <out>/planner_training_throughput.json.

    python benchmarks/planner_training_throughput.py [--init runs/quick/geometric] [--iterations 8] [--workers 2]
        [--set NAME=VALUE ...]

`--set NAME=VALUE` (repeatable) changes one GeneratorConfig field of the workers' contact
generator, e.g. `--set 'retry_settings=()'` to see what its retries cost.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402
from common import add_generator_settings_argument, add_out_argument, generator_settings, load_average, save  # noqa: E402


def main() -> None:
    from leas_jax.contacts import GeneratorConfig
    from leas_jax.training import preset, train

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--init", default=None, help="geometric run directory to start from")
    parser.add_argument("--iterations", type=int, default=8)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--num-envs", type=int, default=64, help="episodes per batch")
    add_generator_settings_argument(parser)
    add_out_argument(parser)
    args = parser.parse_args()
    settings = generator_settings(args.set, parser)
    load_before = load_average()
    overrides = dict(num_timesteps=10**9, num_envs=args.num_envs)
    if args.init:
        overrides["init_from"] = args.init
    else:
        overrides["pretrain"] = ""  # from scratch, not the preset's geometric pretraining
    config = preset("quick", mode="planner", **overrides)
    records = []
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        train(
            config,
            out,
            progress=False,
            workers=args.workers,
            on_log=records.append,
            stop_after_iterations=args.iterations,
            pool_options={"config": GeneratorConfig(**settings)},
        )
        wall = time.perf_counter() - t0
    steady = records[1:] or records  # the first iteration includes compilation and worker start-up
    kept = sum(r["kept_steps"] for r in steady)
    rolled = sum(r["rolled_steps"] for r in steady)
    span = steady[-1]["wall_s"] - (records[0]["wall_s"] if len(records) > 1 else 0.0)
    row = {
        "iterations": len(records),
        "workers": args.workers,
        "episodes_per_batch": args.num_envs,
        "init": args.init,
        "generator_settings": {name: repr(value) for name, value in settings.items()},
        "wall_s_total": round(wall, 1),
        "kept_steps_per_s": round(kept / span, 1),
        "rolled_steps_per_s": round(rolled / span, 1),
        "wait_fraction": round(float(np.mean([r["wait_fraction"] for r in steady])), 3),
        "discarded_fraction": round(float(np.mean([r["discarded_fraction"] for r in steady])), 3),
        "mean_coverage": round(float(np.mean([r["mean_coverage"] for r in steady])), 3),
    }
    for k, v in row.items():
        print(f"{k:22s} {v}")
    save("planner_training_throughput", row, load_before, args.out)


if __name__ == "__main__":
    main()
