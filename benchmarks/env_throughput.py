"""Environment throughput: random actions, fresh resets, num_envs 256 to 32 768.

Compile time is reported apart from run time; every timing ends with
`block_until_ready`. Writes results/env_throughput.json.

    python benchmarks/env_throughput.py [--terrain FILE] [--steps 200] [--repeats 3]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import jax  # noqa: E402
from common import save  # noqa: E402


def measure(field, num_envs: int, steps: int, repeats: int) -> dict:
    from leas_jax.env import FreshResetVmap, LeasEnv

    env = LeasEnv(field)

    @jax.jit
    def run(field, key):
        wrapped = FreshResetVmap(env.with_field(field))
        state = wrapped.reset(jax.random.split(key, num_envs))

        def body(state, k):
            actions = jax.random.uniform(k, (num_envs, 4), minval=-1.0, maxval=1.0)
            state = wrapped.step(state, actions)
            return state, state.done.sum()

        state, dones = jax.lax.scan(body, state, jax.random.split(key, steps))
        return dones.sum()

    t0 = time.perf_counter()
    run(field, jax.random.PRNGKey(0)).block_until_ready()
    compile_s = time.perf_counter() - t0
    times = []
    for r in range(repeats):
        t0 = time.perf_counter()
        episodes = int(run(field, jax.random.PRNGKey(r + 1)).block_until_ready())
        times.append(time.perf_counter() - t0)
    best = min(times)
    return {
        "num_envs": num_envs,
        "steps": steps,
        "compile_s": round(compile_s, 3),
        "run_s": round(best, 4),
        "steps_per_s": round(num_envs * steps / best),
        "episodes_ended": episodes,
    }


def main() -> None:
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.terrain import load_terrain
    from leas_jax.training.config import resolve_data_path

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--terrain", default="terrains/training_arena.toml")
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--envs", default="256,1024,4096,8192,32768")
    args = parser.parse_args()
    field = heightfield_from_terrain(load_terrain(resolve_data_path(args.terrain)))
    rows = []
    for n in [int(v) for v in args.envs.split(",")]:
        row = measure(field, n, args.steps, args.repeats)
        rows.append(row)
        print(
            f"num_envs {n:6d}: {row['steps_per_s']:>12,} steps/s  (compile {row['compile_s']:.1f} s)",
            flush=True,
        )
    best = max(rows, key=lambda r: r["steps_per_s"])
    save(
        "env_throughput",
        {
            "terrain": args.terrain,
            "rows": rows,
            "best_steps_per_s": best["steps_per_s"],
            "best_num_envs": best["num_envs"],
        },
    )


if __name__ == "__main__":
    main()
