"""Environment throughput: random actions, every observation read, against a bare reference env.

Three programs run `--steps` steps of a batch of envs in one `lax.scan` on the
same heightfield and batch:
  - `plain_vmap`: `jax.vmap(env.reset)` and `jax.vmap(env.step)` of `LeasEnv`, as a
    Brax user writes them (no auto-reset: an env whose episode ended keeps stepping);
  - `wrapper`: `FreshResetVmap(LeasEnv)`, what PPO trains with (fresh random starts);
  - `reference`: `benchmarks/reference_env.py`, 77 bilinear heightmap samples and an
    8-point disk check per env and step.
Each step's observation, reward and done flag are summed into a checksum carried
out of the scan and printed: XLA removes work whose result nothing reads, even
inside a scan, so a program that did not return them would time less than the env.
`tests/test_benchmarks.py` checks that the checksum equals a Python loop's over a few
envs stepped one by one.

Compile time (lower + compile) is apart from run time; every timing ends with
`block_until_ready`. The repeats alternate between the programs, and the env's
throughput is also given as a ratio to the reference's in the same repeat (the
median over repeats), which the machine's load moves much less than steps/s; and
per CPU-second of the process (all its threads), with its ratio to the reference's.
Writes <out>/env_throughput.json.

    python benchmarks/env_throughput.py [--envs 256,1024,8192] [--steps 200] [--repeats 3] [--preset quick] [--condition learned]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402
from common import add_out_argument, load_average, save  # noqa: E402
from reference_env import ReferenceEnv  # noqa: E402

PROGRAMS = ("reference", "plain_vmap", "wrapper")
CHECKSUM_FIELDS = ("obs", "reward", "done")


def checksum(obs: jax.Array, reward: jax.Array, done: jax.Array) -> jax.Array:
    """[3] sums of a step's observations [B, 81], rewards [B] and done flags [B]."""
    return jnp.stack([obs.sum(), reward.sum(), done.sum()])


def batched_env(kind: str, field, config):
    """(reset, step) of one program on a (traced) heightfield.

    reset: keys [B, 2] -> batched state; step: (state, actions [B, 4]) -> state with
    `.obs` [B, 81], `.reward` [B] and `.done` [B].
    """
    from leas_jax.env import FreshResetVmap, LeasEnv

    if kind == "plain_vmap":
        env = LeasEnv(field, config)
        return jax.vmap(env.reset), jax.vmap(env.step)
    if kind == "wrapper":
        wrapped = FreshResetVmap(LeasEnv(field, config))
        return wrapped.reset, wrapped.step
    if kind == "reference":
        env = ReferenceEnv(field, config)
        return jax.vmap(env.reset), jax.vmap(env.step)
    raise ValueError(f"unknown program {kind!r}; choose from {PROGRAMS}")


def rollout_keys(key: jax.Array, num_envs: int, steps: int):
    """The keys of a rollout: reset keys [num_envs, 2] and per-step action keys [steps, 2]."""
    reset_key, action_key = jax.random.split(key)
    return jax.random.split(reset_key, num_envs), jax.random.split(action_key, steps)


def step_actions(key: jax.Array, num_envs: int) -> jax.Array:
    """Uniform random actions of one step: [num_envs, 4] in [-1, 1]."""
    return jax.random.uniform(key, (num_envs, 4), minval=-1.0, maxval=1.0)


def make_program(kind: str, config, num_envs: int, steps: int):
    """The timed program: (field, key) -> checksum [3] summed over the steps (see `checksum`)."""

    def run(field, key):
        reset, step = batched_env(kind, field, config)
        reset_keys, action_keys = rollout_keys(key, num_envs, steps)

        def body(carry, k):
            state, total = carry
            state = step(state, step_actions(k, num_envs))
            return (state, total + checksum(state.obs, state.reward, state.done)), None

        (_, total), _ = jax.lax.scan(body, (reset(reset_keys), jnp.zeros(3)), action_keys)
        return total

    return run


def compile_program(kind: str, field, config, num_envs: int, steps: int):
    """(compiled program, seconds to lower and compile it)."""
    t0 = time.perf_counter()
    compiled = (
        jax.jit(make_program(kind, config, num_envs, steps)).lower(field, jax.random.PRNGKey(0)).compile()
    )
    return compiled, time.perf_counter() - t0


def reference_steps_per_s(field, config, num_envs: int, steps: int = 200, repeats: int = 3) -> int:
    """Best steps/s of the reference env at `num_envs` (a yardstick of the machine's speed now)."""
    compiled, _ = compile_program("reference", field, config, num_envs, steps)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        compiled(field, jax.random.PRNGKey(1)).block_until_ready()
        times.append(time.perf_counter() - t0)
    return round(num_envs * steps / min(times))


def measure(field, config, num_envs: int, steps: int, repeats: int) -> dict:
    """Times the three programs at one batch size, repeats alternating between them."""
    compiled, compile_s = {}, {}
    for kind in PROGRAMS:
        compiled[kind], compile_s[kind] = compile_program(kind, field, config, num_envs, steps)
    key = jax.random.PRNGKey(1)
    times = {kind: [] for kind in PROGRAMS}
    cpu = {kind: [] for kind in PROGRAMS}
    sums = {kind: [] for kind in PROGRAMS}
    for _ in range(repeats):
        for kind in PROGRAMS:
            t0, c0 = time.perf_counter(), time.process_time()
            total = compiled[kind](field, key).block_until_ready()
            times[kind].append(time.perf_counter() - t0)
            cpu[kind].append(time.process_time() - c0)
            sums[kind].append([float(v) for v in total])
    row = {"num_envs": num_envs, "steps": steps, "programs": {}}
    for kind in PROGRAMS:
        best = min(times[kind])
        row["programs"][kind] = {
            "compile_s": round(compile_s[kind], 3),
            "run_s": [round(t, 4) for t in times[kind]],
            "steps_per_s_best": round(num_envs * steps / best),
            "steps_per_s_median": round(num_envs * steps / statistics.median(times[kind])),
            # CPU time of all the process's threads: the work done, less moved by other jobs than wall time
            "cpu_s": [round(t, 4) for t in cpu[kind]],
            "steps_per_cpu_s_median": round(num_envs * steps / statistics.median(cpu[kind])),
            "checksum": dict(zip(CHECKSUM_FIELDS, sums[kind][0])),
            "checksum_repeatable": all(s == sums[kind][0] for s in sums[kind]),
        }
    for kind in ("plain_vmap", "wrapper"):
        # the reference's time over the env's in the same repeat: the env's throughput as a fraction of it
        ratios = [ref / env for ref, env in zip(times["reference"], times[kind])]
        row["programs"][kind]["ratio_to_reference"] = round(statistics.median(ratios), 4)
        cpu_ratios = [ref / env for ref, env in zip(cpu["reference"], cpu[kind])]
        row["programs"][kind]["ratio_to_reference_cpu"] = round(statistics.median(cpu_ratios), 4)
    return row


def main(argv=None) -> None:
    from leas_jax.env import EnvConfig, heightfield_from_terrain
    from leas_jax.files import resolve_data_path
    from leas_jax.terrain import load_terrain
    from leas_jax.training.config import learned_condition_env, preset

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--terrain", default="terrains/training_arena.toml")
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--envs", default="256,1024,8192", help="comma-separated batch sizes")
    parser.add_argument(
        "--preset", default=None, help="the env configuration of this training preset (default: EnvConfig())"
    )
    parser.add_argument(
        "--condition",
        choices=("cylinders", "learned"),
        default="cylinders",
        help="termination condition: the configuration's cylinders or the learned network "
        "(`learned_condition_env`, the shipped weights)",
    )
    add_out_argument(parser)
    args = parser.parse_args(argv)
    config = EnvConfig() if args.preset is None else preset(args.preset).env
    if args.condition == "learned":
        config = learned_condition_env(config)
    field = heightfield_from_terrain(load_terrain(resolve_data_path(args.terrain)), config)
    load_before = load_average()
    rows = []
    print(
        f"{'envs':>6s} {'program':10s} {'steps/s best':>13s} {'median':>11s} {'/ reference':>11s} "
        f"{'per CPU-s':>11s} {'/ ref CPU':>9s} {'compile s':>9s}  checksum (obs, reward, done)"
    )
    for n in [int(v) for v in args.envs.split(",")]:
        row = measure(field, config, n, args.steps, args.repeats)
        rows.append(row)
        for kind, p in row["programs"].items():
            ratio = f"{p.get('ratio_to_reference', 1.0):11.3f}"
            cpu_ratio = f"{p.get('ratio_to_reference_cpu', 1.0):9.3f}"
            c = p["checksum"]
            print(
                f"{n:6d} {kind:10s} {p['steps_per_s_best']:13,} {p['steps_per_s_median']:11,} {ratio} "
                f"{p['steps_per_cpu_s_median']:11,} {cpu_ratio} {p['compile_s']:9.1f}  "
                f"({c['obs']:.6g}, {c['reward']:.6g}, {c['done']:.6g})"
                + ("" if p["checksum_repeatable"] else "  NOT REPEATABLE"),
                flush=True,
            )
    save(
        "env_throughput",
        {
            "terrain": args.terrain,
            "env_config": "EnvConfig()" if args.preset is None else f"preset({args.preset!r}).env",
            "condition": args.condition,
            "programs": {
                "reference": "benchmarks/reference_env.py, jax.vmap",
                "plain_vmap": "jax.vmap(LeasEnv.reset), jax.vmap(LeasEnv.step), no auto-reset",
                "wrapper": "FreshResetVmap(LeasEnv), fresh random starts (PPO's)",
            },
            "checksum": "per program, the sums over all steps and envs of the observation, reward and done flag",
            "ratio_to_reference": "median over repeats of reference time / env time in the same repeat",
            "ratio_to_reference_cpu": "the same with the process's CPU times",
            "rows": rows,
        },
        load_before,
        args.out,
    )


if __name__ == "__main__":
    main()
