"""At which root heights does the contact generator walk? (sets ReachabilityConfig.trunk_bottom)

The reachability calibration (reachability_calibration.py) labels a pose feasible
when the generator finds one static double-support posture there; Talos can crouch
to about 0.53 m above its soles for that. Walking is stricter. This script plans
straight guides at a fixed root height h above the ground and reports the
generator's coverage for each h, with what the environment's reachability
condition (EnvConfig defaults) says about the same poses:

  flat      3.6 m along +x on terrains/eval_ground.toml, z = ground + h;
  stairs    3.6 m along +x on terrains/eval_stairs.toml from x = 2.5 (flat ground,
            then the 0.12 m flight, then the platform), z = the highest ground
            within `--radius` (0.15 m) of the root + h.

200 poses per guide (0.18 m/s, 0.1 s timestep), yaw 0. Writes
<out>/walking_height.json.

    python studies/walking_height.py [--heights 0.8,0.85,...] [--radius 0.15]

Results: docs/results/2026-11-22-benchmarks-crouched-walking, 2026-11-22-benchmarks-sole-margins.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "benchmarks")]  # the other studies, benchmarks/common.py

from common import add_out_argument, load_average, save  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
CASES = {
    "flat": (
        "terrains/eval_ground.toml",
        3.0,
        4.0,
        0.0,
    ),  # terrain, x0, y0, radius override (0: under the root)
    "stairs": ("terrains/eval_stairs.toml", 2.5, 3.0, None),
}
POSES = 200
LENGTH_M = 3.6


def highest_ground(terrain, xy: np.ndarray, radius: float) -> np.ndarray:
    """[T] highest terrain height within `radius` of each of the [T, 2] world points (7 x 7 probe grid)."""
    if radius <= 0:
        return terrain.height_at(xy)
    grid = np.linspace(-radius, radius, 7)
    offsets = np.array(
        [(dx, dy) for dx in grid for dy in grid if dx * dx + dy * dy <= radius * radius + 1e-12]
    )
    return np.array([terrain.height_at(p + offsets).max() for p in xy])


def straight_guide(terrain, x0: float, y0: float, height: float, radius: float) -> np.ndarray:
    """[POSES, 4] (x, y, z, yaw) world: along +x at `height` above the highest ground within `radius`."""
    xy = np.stack([np.linspace(x0, x0 + LENGTH_M, POSES), np.full(POSES, y0)], 1)
    z = highest_ground(terrain, xy, radius) + height
    return np.concatenate([xy, z[:, None], np.zeros((POSES, 1))], 1)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--heights",
        default="0.80,0.85,0.90,0.95,1.00,1.05,1.10,1.15",
        help="root heights above the ground, m (comma-separated)",
    )
    parser.add_argument(
        "--radius", type=float, default=0.15, help="stairs: ground = highest within this radius, m"
    )
    add_out_argument(parser)
    args = parser.parse_args(argv)
    heights = [float(h) for h in args.heights.split(",")]
    load_before = load_average()

    import jax

    from leas_jax.contacts.planner.generator import plan_contacts
    from leas_jax.env import EnvConfig, heightfield_from_terrain
    from leas_jax.env.reachability import valid
    from leas_jax.terrain import load_terrain

    env = EnvConfig()
    check = jax.jit(jax.vmap(valid, in_axes=(None, 0, None)), static_argnums=2)
    rows = []
    for case, (path, x0, y0, radius) in CASES.items():
        terrain = load_terrain(REPO / path)
        field = heightfield_from_terrain(terrain, env)
        for height in heights:
            guide = straight_guide(terrain, x0, y0, height, args.radius if radius is None else radius)
            plan = plan_contacts(terrain, guide, env.timestep)
            condition = np.asarray(check(field, guide.astype(np.float32), env.reachability))
            row = {
                "case": case,
                "height_m": height,
                "coverage": round(float(plan.coverage), 4),
                "last_valid_x_m": round(float(guide[max(plan.last_valid_index, 0), 0]), 3),
                "condition_valid_fraction": round(float(condition.mean()), 4),
            }
            rows.append(row)
            print(
                f"{case:7s} h {height:.2f} m: generator coverage {row['coverage']:.3f} "
                f"(stops at x {row['last_valid_x_m']:.2f}), reachability condition valid on "
                f"{row['condition_valid_fraction']:.0%} of the poses"
            )
    save(
        "walking_height",
        {
            "poses_per_guide": POSES,
            "length_m": LENGTH_M,
            "stairs_radius_m": args.radius,
            "reachability": env.reachability.__dict__,
            "rows": rows,
        },
        load_before,
        args.out,
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
