"""Geometric PPO throughput (env steps per second, learning included).

For each preset and termination condition (`--conditions`: "cylinders", the preset's own
condition, which is the cylinders except for `generalist`'s walkability model; "learned", the
arena-fitted network of `EnvConfig(condition="learned")`), each judge of the clearance
term's probe poses (`--clearance-conditions`, learned condition only: the network itself or
the cylinders, `EnvConfig.clearance_condition`), and optional overrides, compiles one
training call, then times `--calls` calls. The bare reference env
(`benchmarks/reference_env.py`) is timed at the preset's batch right before and after, and
the training rate is also given as a ratio to the reference's (the mean of the two), which
the machine's load moves less than env steps/s. Writes <out>/train_throughput.json.

    python benchmarks/train_throughput.py [--presets quick,paper] [--conditions cylinders,learned]
        [--clearance-conditions condition,cylinders] [--calls 5]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import jax  # noqa: E402
from common import add_out_argument, busy_fraction, cpu_times, load_average, save  # noqa: E402
from env_throughput import reference_steps_per_s  # noqa: E402


def measure(config, field, calls: int) -> dict:
    from leas_jax.training.ppo import init_state, make_train_call

    state = init_state(config, field)
    call = make_train_call(config)
    t0 = time.perf_counter()
    state, metrics = call(state, field)
    jax.block_until_ready(metrics)
    compile_s = time.perf_counter() - t0
    load_before = os.getloadavg()[0]
    reference = [reference_steps_per_s(field, config.env, config.num_envs)]
    t0, ticks = time.perf_counter(), cpu_times()
    for _ in range(calls):
        state, metrics = call(state, field)
    jax.block_until_ready(metrics)
    run_s, busy = time.perf_counter() - t0, busy_fraction(ticks, cpu_times())
    reference.append(reference_steps_per_s(field, config.env, config.num_envs))
    load_after = os.getloadavg()[0]
    steps = calls * config.iterations_per_call * config.batch_size
    return {
        "preset": config.preset,
        "condition": config.env.condition,
        "clearance_condition": config.env.clearance_condition,
        "num_envs": config.num_envs,
        "unroll_length": config.unroll_length,
        "num_minibatches": config.num_minibatches,
        "num_epochs": config.num_epochs,
        "compile_s": round(compile_s, 2),
        "run_s": round(run_s, 3),
        "env_steps": steps,
        "env_steps_per_s": round(steps / run_s),
        "minutes_for_80M_steps": round(80e6 / (steps / run_s) / 60, 1),
        "reference_steps_per_s": reference,
        "ratio_to_reference": round(steps / run_s / statistics.mean(reference), 4),
        # 1-minute load average before and after the timed calls: other jobs on the machine slow it down
        "load_average_1min": [round(load_before, 2), round(load_after, 2)],
        # share of all CPUs' time busy during the timed calls (this process and any other):
        # near 1, training is bound by the cores' compute, not by waiting
        "cpu_busy_fraction": busy,
        "cpus": os.cpu_count(),
    }


def variants(name: str, conditions: list[str], judges: list[str], epochs: list[int]):
    """(label, [TrainConfig]) per condition and clearance-probe judge of preset `name`: the
    preset's config, then one per `epochs` value. "cylinders" keeps the preset's own condition
    and is labelled with it. The judges apply to the learned condition
    where the preset has a clearance term (elsewhere the probes are not evaluated)."""
    from leas_jax.training.config import learned_condition_env, preset

    for condition in conditions:
        base = [preset(name)] + [preset(name, num_epochs=e) for e in epochs]
        if condition == "cylinders":
            yield base[0].env.condition, base
            continue
        probed = base[0].env.rewards.clearance != 0.0
        for judge in judges if probed else [judges[0]]:
            env = dataclasses.replace(learned_condition_env(base[0].env), clearance_condition=judge)
            yield (
                (f"learned (probes: {judge})" if probed else "learned"),
                [dataclasses.replace(c, env=env) for c in base],
            )


def main() -> None:
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.env.config import CLEARANCE_CONDITIONS
    from leas_jax.terrain import load_terrain

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presets", default="quick,paper")
    parser.add_argument("--calls", type=int, default=5)
    parser.add_argument("--epochs", default="", help="also measure these num_epochs values, e.g. 10,4")
    parser.add_argument(
        "--conditions", default="cylinders", help="comma-separated: cylinders (the preset's own), learned"
    )
    parser.add_argument(
        "--clearance-conditions",
        default="condition",
        help="comma-separated judges of the learned condition's clearance probes: condition, cylinders",
    )
    add_out_argument(parser)
    args = parser.parse_args()
    load_before = load_average()
    rows = []
    conditions = [c for c in args.conditions.split(",") if c]
    if not conditions or set(conditions) - {"cylinders", "learned"}:
        parser.error(
            f"--conditions: expected a comma-separated subset of cylinders,learned, got {args.conditions!r}"
        )
    judges = [c for c in args.clearance_conditions.split(",") if c]
    if not judges or set(judges) - set(CLEARANCE_CONDITIONS):
        parser.error(
            f"--clearance-conditions: expected a comma-separated subset of {','.join(CLEARANCE_CONDITIONS)}, "
            f"got {args.clearance_conditions!r}"
        )
    for name in args.presets.split(","):
        for label, configs in variants(
            name, conditions, judges, [int(e) for e in args.epochs.split(",") if e]
        ):
            field = heightfield_from_terrain(load_terrain(configs[0].terrain_path()), configs[0].env)
            for variant in configs:
                row = measure(variant, field, args.calls)
                rows.append(row)
                print(
                    f"{name:6s} {label:28s} epochs {variant.num_epochs:2d} minibatches {variant.num_minibatches:2d}: "
                    f"{row['env_steps_per_s']:>10,} env steps/s ({row['ratio_to_reference']:.3f} of the reference env's), "
                    f"80 M steps in {row['minutes_for_80M_steps']} min "
                    f"(compile {row['compile_s']} s, load average {row['load_average_1min'][0]} -> "
                    f"{row['load_average_1min'][1]} on {row['cpus']} CPUs, busy {row['cpu_busy_fraction']})",
                    flush=True,
                )
    save("train_throughput", {"rows": rows}, load_before, args.out)


if __name__ == "__main__":
    main()
