"""Contact-planner speed on one core: ms per 4 m path and per footstep (issue 3).

Three guides, built here, at 0.18 m/s with a 0.1 s timestep (paper Table I, §IV),
root NOMINAL_ROOT_HEIGHT above the ground:

  flat      4 m straight on flat ground (target <= 50 ms per path);
  uturn     4 m with a 180 deg turn: 1.19 m straight, a half circle at the paper's
            omega_max = pi/9 rad/s (1.62 m of arc, radius 0.52 m), 1.19 m back;
  stairs    6 steps of 0.10 m (0.30 m treads), root z ramping up with the flight.

Targets: <= 50 ms per flat path, <= 5 ms per footstep on average over the three.
The generator runs in-process; each guide is planned once to warm up (model,
database, collision objects), then `--runs` times; best and median are reported.
Times are the process's CPU time (`time.process_time`): on a shared machine it leaves
out the time spent waiting for a core, which wall-clock time (also saved, `wall_*`)
counts; the load average is saved with them.
BLAS/OpenMP pools are limited to one thread before NumPy is imported so that the
figures are single-core ones. Writes results/contact_planner_speed.json.

    python benchmarks/contact_planner_speed.py [--runs 20] [--profile flat]
"""

from __future__ import annotations

import os

# One core: these must be set before NumPy / Pinocchio / coal load their thread pools.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS",
             "VECLIB_MAXIMUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

from common import save  # noqa: E402
from leas_jax.contacts import NOMINAL_ROOT_HEIGHT, ContactGenerator, GeneratorConfig  # noqa: E402
from leas_jax.terrain import loads_terrain  # noqa: E402

DT = 0.1  # s, paper Table I
SPEED = 0.18  # m/s, paper §IV
OMEGA = math.pi / 9  # rad/s, omega_max (DESIGN §5)
HEAD = 'name = "{name}"\nbounds = [[-2.0, -3.0], [7.0, 3.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
PATH_TARGET_MS = 50.0
STEP_TARGET_MS = 5.0


def _box(center, size) -> str:
    return f"[[box]]\ncenter = {list(map(float, center))}\nsize = {list(map(float, size))}\n"


def _resample(points: np.ndarray) -> np.ndarray:
    """[N, 4] dense polyline (x, y, z, yaw) -> [T, 4] one pose every SPEED * DT of arc length."""
    seg = np.hypot(*np.diff(points[:, :2], axis=0).T)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    count = int(round(arc[-1] / (SPEED * DT))) + 1
    s = np.linspace(0.0, arc[-1], count)
    return np.stack([np.interp(s, arc, points[:, k]) for k in range(4)], axis=1)


def flat_case():
    """4 m straight along +x on a flat slab; guide [223, 4]."""
    terrain = loads_terrain(HEAD.format(name="flat") + _box([2.5, 0, -0.1], [9, 6, 0.2]))
    x = np.linspace(0.0, 4.0, 1000)
    guide = _resample(np.stack([x, np.zeros_like(x), np.full_like(x, NOMINAL_ROOT_HEIGHT), np.zeros_like(x)], 1))
    return terrain, guide


def uturn_case():
    """4 m: straight, a 180 deg left half circle at omega_max, straight back (yaw follows the path)."""
    terrain = loads_terrain(HEAD.format(name="uturn") + _box([2.5, 0, -0.1], [9, 6, 0.2]))
    arc_length = math.pi / OMEGA * SPEED  # 9 s at omega_max: 1.62 m
    radius = arc_length / math.pi
    leg = (4.0 - arc_length) / 2
    a = np.linspace(0.0, leg, 300)
    t = np.linspace(0.0, math.pi, 600)
    out = np.stack([a, np.zeros_like(a), np.zeros_like(a)], 1)
    turn = np.stack([leg + radius * np.sin(t), radius * (1 - np.cos(t)), t], 1)
    back = np.stack([leg - a, np.full_like(a, 2 * radius), np.full_like(a, math.pi)], 1)
    xyyaw = np.concatenate([out, turn[1:], back[1:]])
    points = np.stack([xyyaw[:, 0], xyyaw[:, 1], np.full(len(xyyaw), NOMINAL_ROOT_HEIGHT), xyyaw[:, 2]], 1)
    return terrain, _resample(points)


def stairs_case(rise: float = 0.10, steps: int = 6, tread: float = 0.30, start: float = 1.5):
    """6 x 0.10 m steps from x = 1.5 m, 3 m landing; 4.5 m guide, root rising with the flight."""
    text = HEAD.format(name="stairs") + _box([start - 1.75, 0, -0.1], [3.5, 6, 0.2])
    for k in range(steps):
        top = rise * (k + 1)
        text += _box([start + tread * (k + 0.5), 0, (top - 0.2) / 2], [tread, 6, top + 0.2])
    top = rise * steps
    text += _box([start + tread * steps + 1.5, 0, (top - 0.2) / 2], [3.0, 6, top + 0.2])
    x = np.linspace(0.0, 4.5, 1000)
    # Root z rises with the flight (tread * steps long), starting 0.15 m before it.
    z = NOMINAL_ROOT_HEIGHT + np.clip((x - start + 0.15) / (tread * steps) * top, 0.0, top)
    guide = _resample(np.stack([x, np.zeros_like(x), z, np.zeros_like(x)], 1))
    return loads_terrain(text), guide


CASES = {"flat": flat_case, "uturn": uturn_case, "stairs": stairs_case}


def footsteps(plan) -> int:
    """Foot placements in a plan: one single-support posture (a NaN feet row) per step."""
    return int(np.isnan(plan.feet[:, :, 0]).any(axis=1).sum())


def measure(name: str, runs: int) -> dict:
    terrain, guide = CASES[name]()
    generator = ContactGenerator(terrain, GeneratorConfig())
    plan = generator.plan(guide, DT)  # warm-up: first calls build caches (faces, LP)
    wall, cpu = [], []
    for _ in range(runs):
        start, start_cpu = time.perf_counter(), time.process_time()
        again = generator.plan(guide, DT)
        wall.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
        # Deterministic: every run must return the warm-up plan.
        assert again.coverage == plan.coverage and np.array_equal(again.q, plan.q), name
    steps = footsteps(plan)
    best, median = 1e3 * min(cpu), 1e3 * statistics.median(cpu)
    return {"guide_poses": len(guide), "guide_length_m": float(np.hypot(*np.diff(guide[:, :2], axis=0).T).sum()),
            "postures": len(plan), "footsteps": steps, "coverage": float(plan.coverage),
            "best_ms": best, "median_ms": median,
            "best_ms_per_footstep": best / max(steps, 1), "median_ms_per_footstep": median / max(steps, 1),
            "wall_best_ms": 1e3 * min(wall), "wall_median_ms": 1e3 * statistics.median(wall), "runs": runs}


def profile(name: str, runs: int) -> None:
    import cProfile
    import pstats

    terrain, guide = CASES[name]()
    generator = ContactGenerator(terrain, GeneratorConfig())
    generator.plan(guide, DT)
    prof = cProfile.Profile()
    prof.enable()
    for _ in range(runs):
        generator.plan(guide, DT)
    prof.disable()
    pstats.Stats(prof).sort_stats("tottime").print_stats(25)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20, help="timed runs per guide after one warm-up (>= 20)")
    parser.add_argument("--profile", choices=sorted(CASES), help="print a cProfile of this guide instead")
    args = parser.parse_args(argv)
    if args.profile:
        profile(args.profile, args.runs)
        return
    load_before = os.getloadavg()[0]
    results = {name: measure(name, args.runs) for name in CASES}
    mean_step = statistics.mean(r["median_ms_per_footstep"] for r in results.values())
    print(f"CPU ms per path ((wall) = wall-clock median), load average {load_before:.2f} before, "
          f"{os.getloadavg()[0]:.2f} after")
    print(f"{'guide':8s} {'poses':>5s} {'steps':>5s} {'coverage':>8s} {'best ms':>8s} {'median ms':>9s} "
          f"{'(wall)':>7s} {'ms/step (median)':>16s}")
    for name, r in results.items():
        print(f"{name:8s} {r['guide_poses']:5d} {r['footsteps']:5d} {r['coverage']:8.3f} {r['best_ms']:8.1f} "
              f"{r['median_ms']:9.1f} {r['wall_median_ms']:7.1f} {r['median_ms_per_footstep']:16.2f}")
    flat = results["flat"]
    flat_ok = flat["median_ms"] <= PATH_TARGET_MS
    print(f"flat path (target <= {PATH_TARGET_MS:.0f} ms): best {flat['best_ms']:.1f} ms "
          f"({'met' if flat['best_ms'] <= PATH_TARGET_MS else 'MISSED'}), median {flat['median_ms']:.1f} ms "
          f"({'met' if flat_ok else 'MISSED'})")
    print(f"mean over guides: {mean_step:.2f} ms per footstep (target <= {STEP_TARGET_MS:.0f}): "
          f"{'met' if mean_step <= STEP_TARGET_MS else 'MISSED'}")
    save("contact_planner_speed", {
        "threads": 1, "clock": "process_time (CPU); wall_* perf_counter", "timestep_s": DT, "speed_m_s": SPEED, "load_average_1min_before": load_before,
        "targets": {"flat_path_ms": PATH_TARGET_MS, "ms_per_footstep": STEP_TARGET_MS},
        "cases": results, "mean_median_ms_per_footstep": mean_step,
        "flat_target_met": flat_ok, "flat_target_met_best": flat["best_ms"] <= PATH_TARGET_MS, "footstep_target_met": mean_step <= STEP_TARGET_MS})


if __name__ == "__main__":
    main()
