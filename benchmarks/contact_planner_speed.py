"""Contact-planner speed on one core: ms per 4 m path and per footstep.

Three guides, built here, at 0.18 m/s with a 0.1 s timestep (paper Table I, §IV),
root NOMINAL_ROOT_HEIGHT above the ground:

  flat      4 m straight on flat ground (target <= 50 ms per path);
  uturn     4 m with a 180 deg turn: 1.19 m straight, a half circle at the paper's
            omega_max = pi/9 rad/s (1.62 m of arc, radius 0.52 m), 1.19 m back;
  stairs    6 steps of 0.10 m (0.30 m treads), root z ramping up with the flight.

  arena     24 guides of 200 poses on terrains/training_arena.toml (545 boxes), like
            the guides planner-in-the-loop training validates (`arena_guides`): 12
            random walks (speed and yaw rate re-drawn every pose, <= 0.3 m/s and
            <= pi/9 rad/s), 12 straight lines or constant turns, all from seeded
            NumPy, starting where the generator can stand; most fail part-way.
            Reported as guide poses per CPU-second: all submitted guide poses
            (4800) / CPU time of planning the 24 guides (the training's view: every
            env step is a guide pose), and covered poses (up to last_valid_index).

Targets: <= 50 ms per flat path, <= 5 ms per footstep on average over the three.
The generator runs in-process; each guide is planned once to warm up (model,
database, collision objects), then `--runs` times; best and median are reported.
Times are the process's CPU time (`time.process_time`): on a shared machine it leaves
out the time spent waiting for a core, which wall-clock time (also saved, `wall_*`)
counts; the load average is saved with them.
BLAS/OpenMP pools are limited to one thread before NumPy is imported so that the
figures are single-core ones. Writes <out>/contact_planner_speed.json.

    python benchmarks/contact_planner_speed.py [--runs 20] [--cases flat,uturn,stairs,arena]
        [--arena-runs 3] [--profile flat|uturn|stairs|arena] [--set NAME=VALUE ...]

`--set NAME=VALUE` (repeatable) changes one GeneratorConfig field for the timed runs and the
profile, e.g. `--set 'retry_settings=()'` for the generator without its retries.

Plan identity across code changes: `--save-reference .cache/contact_parity/arena_reference.npz`
stores the arena guides and the plans of all cases (q, feet, guide_index,
last_valid_index, coverage); `--check-reference` re-plans and compares them exactly
(tests/test_contacts_speed_parity.py does it too when the file exists).
"""

from __future__ import annotations

import os

# One core: these must be set before NumPy / Pinocchio / coal load their thread pools.
for _var in (
    "OMP_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "MKL_NUM_THREADS",
    "NUMEXPR_NUM_THREADS",
    "VECLIB_MAXIMUM_THREADS",
):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402
from common import add_generator_settings_argument, add_out_argument, generator_settings, load_average, save  # noqa: E402

from leas_jax.contacts import NOMINAL_ROOT_HEIGHT, ContactGenerator, GeneratorConfig  # noqa: E402
from leas_jax.terrain import loads_terrain  # noqa: E402

DT = 0.1  # s, paper Table I
SPEED = 0.18  # m/s, paper §IV
OMEGA = math.pi / 9  # rad/s, omega_max (docs/design.md §5)
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
    guide = _resample(
        np.stack([x, np.zeros_like(x), np.full_like(x, NOMINAL_ROOT_HEIGHT), np.zeros_like(x)], 1)
    )
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
PLAN_ARRAYS = ("q", "feet", "guide_index", "last_valid_index", "coverage")

ARENA = Path(__file__).resolve().parent.parent / "terrains" / "training_arena.toml"
ARENA_SEED = 0
ARENA_MAX_SPEED = 0.3  # m/s, above the paper's 0.18 m/s (early-training policies)
ARENA_MAX_YAW_RATE = math.pi / 9  # rad/s, omega_max (docs/design.md §5)


def _arena_start(terrain, rng, pose_ok) -> np.ndarray:
    """A random (x, y, yaw) of the arena where the generator can stand (double support)."""
    lo, hi = terrain.bounds[0] + 0.5, terrain.bounds[1] - 0.5
    while True:
        x, y = rng.uniform(lo, hi)
        yaw = rng.uniform(-math.pi, math.pi)
        z = float(terrain.height_at(np.array([x, y]))) + NOMINAL_ROOT_HEIGHT
        pose = np.array([x, y, z, yaw])
        if pose_ok(pose):
            return pose


def arena_guides(count: int = 24, seed: int = ARENA_SEED, length: int = 200, pose_ok=None):
    """Deterministic arena workload: (terrain, [guides [T, 4]]), DT between poses.

    The first half are random walks (speed and yaw rate re-drawn uniformly every
    pose in [0, ARENA_MAX_SPEED] and [-ARENA_MAX_YAW_RATE, ARENA_MAX_YAW_RATE], like a
    random policy), the second half straight lines or constant turns (speed 0.1-0.3
    m/s, yaw rate 0 for even guides, else a random constant); all `length` poses, root
    NOMINAL_ROOT_HEIGHT above `terrain.height_at`, starting where the generator can
    stand (`pose_ok(pose)`, default `ContactGenerator.double_support(pose) is not None`).
    Seeded NumPy: the same guides on every machine (given the same generator).
    """
    from leas_jax.terrain import load_terrain

    terrain = load_terrain(ARENA)
    rng = np.random.default_rng(seed)
    if pose_ok is None:
        generator = ContactGenerator(terrain, GeneratorConfig())
        pose_ok = lambda pose: generator.double_support(pose) is not None  # noqa: E731
    guides = []
    lo, hi = terrain.bounds[0], terrain.bounds[1]
    for k in range(count):
        start = _arena_start(terrain, rng, pose_ok)
        walk = k < count // 2
        if walk:
            speed = rng.uniform(0.0, ARENA_MAX_SPEED, length)
            omega = rng.uniform(-ARENA_MAX_YAW_RATE, ARENA_MAX_YAW_RATE, length)
        else:
            speed = np.full(length, rng.uniform(0.1, ARENA_MAX_SPEED))
            omega = np.full(
                length, 0.0 if k % 2 == 0 else rng.uniform(-ARENA_MAX_YAW_RATE, ARENA_MAX_YAW_RATE)
            )
        xyyaw = np.empty((length, 3))
        xyyaw[0] = start[[0, 1, 3]]
        for t in range(1, length):
            x, y, yaw = xyyaw[t - 1]
            yaw = yaw + omega[t] * DT
            xyyaw[t] = (x + speed[t] * DT * math.cos(yaw), y + speed[t] * DT * math.sin(yaw), yaw)
        xyyaw[:, :2] = np.clip(xyyaw[:, :2], lo, hi)
        z = terrain.height_at(xyyaw[:, :2]) + NOMINAL_ROOT_HEIGHT
        guides.append(np.stack([xyyaw[:, 0], xyyaw[:, 1], z, xyyaw[:, 2]], axis=1))
    return terrain, guides


def measure_arena(runs: int, config: GeneratorConfig) -> dict:
    """Arena workload: guide poses per CPU-second (all submitted poses / CPU time of planning them)."""
    terrain, guides = arena_guides()
    generator = ContactGenerator(terrain, config)
    plans = [generator.plan(g, DT) for g in guides]  # warm-up
    cpu, wall = [], []
    for _ in range(runs):
        start, start_cpu = time.perf_counter(), time.process_time()
        for guide, plan in zip(guides, plans):
            again = generator.plan(guide, DT)
            assert again.coverage == plan.coverage and np.array_equal(again.q, plan.q)
        wall.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    poses = sum(len(g) for g in guides)
    covered = sum(p.last_valid_index + 1 for p in plans)
    median = statistics.median(cpu)
    return {
        "guides": len(guides),
        "guide_poses": poses,
        "covered_poses": covered,
        "failed_guides": sum(p.last_valid_index < len(g) - 1 for p, g in zip(plans, guides)),
        "mean_coverage": float(np.mean([p.coverage for p in plans])),
        "best_s": min(cpu),
        "median_s": median,
        "wall_median_s": statistics.median(wall),
        "poses_per_cpu_s_median": poses / median,
        "poses_per_cpu_s_best": poses / min(cpu),
        "covered_poses_per_cpu_s_median": covered / median,
        "runs": runs,
    }


def footsteps(plan) -> int:
    """Foot placements in a plan: one single-support posture (a NaN feet row) per step."""
    return int(np.isnan(plan.feet[:, :, 0]).any(axis=1).sum())


def measure(name: str, runs: int, config: GeneratorConfig) -> dict:
    terrain, guide = CASES[name]()
    generator = ContactGenerator(terrain, config)
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
    return {
        "guide_poses": len(guide),
        "guide_length_m": float(np.hypot(*np.diff(guide[:, :2], axis=0).T).sum()),
        "postures": len(plan),
        "footsteps": steps,
        "coverage": float(plan.coverage),
        "best_ms": best,
        "median_ms": median,
        "best_ms_per_footstep": best / max(steps, 1),
        "median_ms_per_footstep": median / max(steps, 1),
        "wall_best_ms": 1e3 * min(wall),
        "wall_median_ms": 1e3 * statistics.median(wall),
        "runs": runs,
    }


def profile(name: str, runs: int, config: GeneratorConfig) -> None:
    import cProfile
    import pstats

    if name == "arena":
        terrain, guides = arena_guides()
    else:
        terrain, guide = CASES[name]()
        guides = [guide]
    generator = ContactGenerator(terrain, config)
    for guide in guides:
        generator.plan(guide, DT)
    prof = cProfile.Profile()
    prof.enable()
    for _ in range(runs):
        for guide in guides:
            generator.plan(guide, DT)
    prof.disable()
    stats = pstats.Stats(prof)
    stats.sort_stats("tottime").print_stats(25)
    stats.sort_stats("cumulative").print_stats(30)


def same_array(a, b) -> bool:
    """Exact equality of two arrays (same shape, dtype kind, values; NaN equals NaN)."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        return False
    if a.dtype.kind == "f" or b.dtype.kind == "f":
        return bool(np.array_equal(a, b, equal_nan=True))
    return bool(np.array_equal(a, b))


def save_reference(path: str) -> None:
    """Save the arena guides and their plans (PLAN_ARRAYS) to an .npz."""
    terrain, guides = arena_guides()
    generator = ContactGenerator(terrain, GeneratorConfig())
    arrays = {}
    for k, guide in enumerate(guides):
        plan = generator.plan(guide, DT)
        arrays[f"guide_{k}"] = guide
        for key in PLAN_ARRAYS:
            arrays[f"{key}_{k}"] = np.asarray(getattr(plan, key))
    for name, case in CASES.items():
        case_terrain, guide = case()
        plan = ContactGenerator(case_terrain, GeneratorConfig()).plan(guide, DT)
        for key in PLAN_ARRAYS:
            arrays[f"{key}_{name}"] = np.asarray(getattr(plan, key))
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    np.savez(path, count=len(guides), **arrays)
    print(f"saved {len(guides)} guides and plans to {path}")


def check_reference(path: str) -> bool:
    """Plan the saved guides again; compare every PLAN_ARRAYS entry exactly. True if all equal."""
    from leas_jax.terrain import load_terrain

    data = np.load(path)
    generator = ContactGenerator(load_terrain(ARENA), GeneratorConfig())
    same = True
    for k in range(int(data["count"])):
        plan = generator.plan(data[f"guide_{k}"], DT)
        for key in PLAN_ARRAYS:
            if not same_array(getattr(plan, key), data[f"{key}_{k}"]):
                print(f"guide {k}: {key} differs")
                same = False
    for name, case in CASES.items():
        case_terrain, guide = case()
        plan = ContactGenerator(case_terrain, GeneratorConfig()).plan(guide, DT)
        for key in PLAN_ARRAYS:
            if f"{key}_{name}" in data and not same_array(getattr(plan, key), data[f"{key}_{name}"]):
                print(f"case {name}: {key} differs")
                same = False
    print(
        f"{int(data['count'])} arena guides and {len(CASES)} cases: {'identical' if same else 'DIFFERENT'} plans"
    )
    return same


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20, help="timed runs per guide after one warm-up (>= 20)")
    parser.add_argument(
        "--profile", choices=sorted([*CASES, "arena"]), help="print a cProfile of this guide instead"
    )
    parser.add_argument(
        "--cases",
        default=",".join([*CASES, "arena"]),
        help="comma-separated cases to time (flat, uturn, stairs, arena)",
    )
    parser.add_argument("--arena-runs", type=int, default=3, help="timed runs of the arena workload")
    parser.add_argument("--save-reference", metavar="NPZ", help="save the arena guides and plans, then exit")
    parser.add_argument(
        "--check-reference", metavar="NPZ", help="re-plan saved arena guides, compare, then exit"
    )
    add_generator_settings_argument(parser)
    add_out_argument(parser)
    args = parser.parse_args(argv)
    settings = generator_settings(args.set, parser)
    config = GeneratorConfig(**settings)
    if args.save_reference:
        save_reference(args.save_reference)
        return
    if args.check_reference:
        sys.exit(0 if check_reference(args.check_reference) else 1)
    if args.profile:
        profile(args.profile, args.runs, config)
        return
    names = [n.strip() for n in args.cases.split(",") if n.strip()]
    unknown = sorted(set(names) - {*CASES, "arena"})
    if unknown:
        parser.error(f"unknown case(s) {unknown}; choose from {[*CASES, 'arena']}")
    load_before = load_average()
    results = {name: measure(name, args.runs, config) for name in CASES if name in names}
    arena = measure_arena(args.arena_runs, config) if "arena" in names else None
    print(
        f"CPU ms per path ((wall) = wall-clock median), load average {load_before['1min']:.2f} before, "
        f"{load_average()['1min']:.2f} after"
    )
    summary = {}
    if results:
        mean_step = statistics.mean(r["median_ms_per_footstep"] for r in results.values())
        print(
            f"{'guide':8s} {'poses':>5s} {'steps':>5s} {'coverage':>8s} {'best ms':>8s} {'median ms':>9s} "
            f"{'(wall)':>7s} {'ms/step (median)':>16s}"
        )
        for name, r in results.items():
            print(
                f"{name:8s} {r['guide_poses']:5d} {r['footsteps']:5d} {r['coverage']:8.3f} {r['best_ms']:8.1f} "
                f"{r['median_ms']:9.1f} {r['wall_median_ms']:7.1f} {r['median_ms_per_footstep']:16.2f}"
            )
        summary["mean_median_ms_per_footstep"] = mean_step
        summary["footstep_target_met"] = mean_step <= STEP_TARGET_MS
        if "flat" in results:
            flat = results["flat"]
            flat_ok = flat["median_ms"] <= PATH_TARGET_MS
            print(
                f"flat path (target <= {PATH_TARGET_MS:.0f} ms): best {flat['best_ms']:.1f} ms "
                f"({'met' if flat['best_ms'] <= PATH_TARGET_MS else 'MISSED'}), median {flat['median_ms']:.1f} ms "
                f"({'met' if flat_ok else 'MISSED'})"
            )
            summary["flat_target_met"] = flat_ok
            summary["flat_target_met_best"] = flat["best_ms"] <= PATH_TARGET_MS
        print(
            f"mean over guides: {mean_step:.2f} ms per footstep (target <= {STEP_TARGET_MS:.0f}): "
            f"{'met' if mean_step <= STEP_TARGET_MS else 'MISSED'}"
        )
    if arena is not None:
        print(
            f"arena: {arena['guides']} guides ({arena['failed_guides']} fail part-way, mean coverage "
            f"{arena['mean_coverage']:.3f}), {arena['guide_poses']} guide poses: "
            f"{arena['poses_per_cpu_s_median']:.0f} guide poses per CPU-second (median of {arena['runs']}; "
            f"best {arena['poses_per_cpu_s_best']:.0f}; {arena['covered_poses_per_cpu_s_median']:.0f} covered poses "
            f"per CPU-second), {arena['median_s']:.2f} s CPU per workload"
        )
        results["arena"] = arena
    save(
        "contact_planner_speed",
        {
            "threads": 1,
            "clock": "process_time (CPU); wall_* perf_counter",
            "timestep_s": DT,
            "speed_m_s": SPEED,
            "targets": {"flat_path_ms": PATH_TARGET_MS, "ms_per_footstep": STEP_TARGET_MS},
            "generator_settings": {name: repr(value) for name, value in settings.items()},
            "cases": results,
            **summary,
        },
        load_before,
        args.out,
    )


if __name__ == "__main__":
    main()
