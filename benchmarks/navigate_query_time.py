"""Navigate query time for 10 m queries, split into search, policy rollout and contact planning.

eval_ground (flat, 12 x 8 m): `--queries` seeded queries from (1, y) to (11, y), y uniform in
[2.5, 5.5] m, start yaw uniform in +-30 deg, at rest. Model loading is excluded: the policy,
the contact generator (Talos, its sample database: one in-process `ValidationPool`) and the
terrain's lattice (built once per terrain, reported apart) are ready before the clock starts;
one warm-up query compiles the rollout first. Each query then runs alone
(`Navigator.run([query])`). Reference in the same run: the contact generator on one fixed
straight 10 m guide (`plan_contacts`), so that loaded-machine figures can be scaled.

    python benchmarks/navigate_query_time.py [--queries 20] [--seed 0]

Writes <out>/navigate_query_time.json.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from common import add_out_argument, load_average, save

PARTS = ("search", "rollout", "contact_planning")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--queries", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    add_out_argument(parser)
    args = parser.parse_args()

    from leas_jax.contacts import plan_contacts
    from leas_jax.contacts.validation.pool import ValidationPool
    from leas_jax.navigate.loop import Navigator
    from leas_jax.terrain import load_terrain
    from leas_jax.training import load_policy

    load_before = load_average()
    policy = load_policy("checkpoints/leas_talos")
    terrain = load_terrain("terrains/eval_ground.toml")
    rng = np.random.default_rng(args.seed)
    navigator = Navigator(policy, terrain)
    _ = navigator.lattice
    lattice_s = navigator.lattice_seconds
    straight = np.column_stack(
        [np.linspace(1.0, 11.0, 556), np.full(556, 4.0), np.full(556, 1.0), np.zeros(556)]
    )
    plan_contacts(terrain, straight[:5], 0.1)  # loads the generator
    began = time.perf_counter()
    plan_contacts(terrain, straight, 0.1)
    reference = time.perf_counter() - began
    rows = []
    with ValidationPool(terrain, workers=0, return_plans=True) as pool:
        warm = navigator.query((1.0, 4.0, 0.0), (11.0, 4.0))
        began = time.perf_counter()
        navigator.run([warm], pool=pool)
        warm_s = time.perf_counter() - began
        for _ in range(args.queries):
            y = float(rng.uniform(2.5, 5.5))
            yaw = math.radians(float(rng.uniform(-30.0, 30.0)))
            query = navigator.query((1.0, y, yaw), (11.0, y))
            began = time.perf_counter()
            (result,) = navigator.run([query], pool=pool)
            wall = time.perf_counter() - began
            rows.append(
                {
                    "y": y,
                    "yaw": yaw,
                    "wall_s": wall,
                    **{f"{p}_s": result.seconds[p] for p in PARTS},
                    "success": result.success,
                    "reason": result.reason,
                    "replans": result.replans,
                    "guide_poses": 0 if result.guide is None else len(result.guide),
                }
            )
            print(rows[-1], flush=True)

    def stats(key):
        values = np.array([r[key] for r in rows])
        return {"median": float(np.median(values)), "p95": float(np.percentile(values, 95))}

    report = {
        "queries": args.queries,
        "seed": args.seed,
        "lattice_s": lattice_s,
        "warm_up_query_s": warm_s,
        "reference_plan_contacts_10m_s": reference,
        "wall": stats("wall_s"),
        **{p: stats(f"{p}_s") for p in PARTS},
        "wall_over_reference_median": float(np.median([r["wall_s"] for r in rows]) / reference),
        "success": int(sum(r["success"] for r in rows)),
        "replans": int(sum(r["replans"] for r in rows)),
        "rows": rows,
    }
    print({k: v for k, v in report.items() if k != "rows"})
    save("navigate_query_time", report, load_before, args.out)


if __name__ == "__main__":
    main()
