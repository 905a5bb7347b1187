"""How often and how fast does the global layer's lattice search find a path from the evaluation
scenarios' starts, against RBKino+RRT?

For each scenario's seeded starts (the same draws as `leas evaluate`), in one process:
  - the lattice search (`leas_jax.navigate`): the valid set over 0.05 m cells x 16 headings,
    built once per terrain (timed apart), then one Dijkstra per start to the target;
  - the RBKino+RRT (`leas_jax.steering.rrt.plan_rrt`, its default budget, seed = start index,
    as `leas evaluate` runs it).
Reports, per planner, how many starts get a path (with 95 % Wilson intervals) and the
median / p95 seconds per start, and their ratio. Geometric planners only: what the contact
generator makes of the paths is `leas evaluate --methods ...,navigate`'s question.

    python studies/navigate_search.py [--scenarios bridge hole] [--n-starts 60] [--rrt-starts N]

Writes <out>/navigate_search.json.

Results: docs/results/2026-12-01-navigate.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))  # benchmarks/common.py

from common import add_out_argument, load_average, save, wilson  # noqa: E402


def summary(found: list[bool], seconds: list[float]) -> dict:
    k, n = int(sum(found)), len(found)
    return {
        "n": n,
        "found": k,
        "percent": 100.0 * k / n if n else float("nan"),
        "wilson95": tuple(100 * x for x in wilson(k, n)),
        "median_s": float(np.median(seconds)),
        "p95_s": float(np.percentile(seconds, 95)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenarios", nargs="+", default=["bridge", "hole"])
    parser.add_argument("--n-starts", type=int, default=60)
    parser.add_argument("--rrt-starts", type=int, default=None, help="RRT on the first N starts only")
    add_out_argument(parser)
    args = parser.parse_args()

    from leas_jax.env import heightfield_from_terrain
    from leas_jax.eval.scenarios import cells_for, draw_starts
    from leas_jax.navigate.lattice import build_lattice
    from leas_jax.navigate.search import SearchConfig, graph, search
    from leas_jax.steering.baselines import BaselineConfig
    from leas_jax.steering.rrt import RRTConfig, plan_rrt
    from leas_jax.terrain import load_terrain
    from leas_jax.terrain.generate import scenario_file
    from leas_jax.training import load_policy

    policy = load_policy("checkpoints/leas_talos")
    env = policy.config.env
    config = BaselineConfig.from_env(env)
    load_before = load_average()
    report = {"scenarios": {}}
    for name in args.scenarios:
        terrain = load_terrain(scenario_file(name))
        scenario = terrain.scenario
        field = heightfield_from_terrain(terrain, env)
        (cell,) = cells_for(name, scenario)
        starts = draw_starts(
            scenario, cell, args.n_starts, scenario.seed, field, config.nominal_root_height, env.reachability
        )
        target = np.asarray(scenario.target, np.float64)
        began = time.perf_counter()
        lattice = build_lattice(field, terrain.bounds, env.nominal_root_height, env.reachability)
        first = time.perf_counter() - began  # includes the jitted check's compilation
        began = time.perf_counter()
        lattice = build_lattice(field, terrain.bounds, env.nominal_root_height, env.reachability)
        adjacency = graph(lattice, None, SearchConfig())
        build = time.perf_counter() - began
        lat_found, lat_s, lengths = [], [], []
        for pose in starts.poses:
            began = time.perf_counter()
            found = search(lattice, pose[[0, 1, 3]], target, adjacency=adjacency)
            lat_s.append(time.perf_counter() - began)
            lat_found.append(bool(found.reached))
            lengths.append(found.length)
        rrt_found, rrt_s = [], []
        n_rrt = args.rrt_starts or len(starts.poses)
        for k, (pose, speed) in enumerate(zip(starts.poses[:n_rrt], starts.speeds[:n_rrt])):
            began = time.perf_counter()
            plan = plan_rrt(
                field, pose, target, float(speed), terrain.bounds, config, RRTConfig(seed=k), env.reachability
            )
            rrt_s.append(time.perf_counter() - began)
            rrt_found.append(bool(plan.success))
            print(
                f"{name} start {k}: lattice {lat_found[k]} {lat_s[k]:.2f} s, rrt {plan.success} {rrt_s[-1]:.1f} s",
                flush=True,
            )
        lat = summary(lat_found, lat_s)
        lat_same = summary(lat_found[:n_rrt], lat_s[:n_rrt])
        rrt = summary(rrt_found, rrt_s)
        report["scenarios"][name] = {
            "lattice_shape": list(lattice.shape),
            "lattice_build_s": build,
            "lattice_first_build_s_with_compile": first,
            "lattice": lat,
            "lattice_on_rrt_starts": lat_same,
            "lattice_path_length_median_m": float(np.median(lengths)),
            "rrt": rrt,
            "rrt_over_lattice_median_time": rrt["median_s"] / lat_same["median_s"],
        }
        print(name, report["scenarios"][name], flush=True)
    save("navigate_search", report, load_before, args.out)


if __name__ == "__main__":
    main()
