"""Does the calibrated reachability condition hold on fresh poses, and how far could a richer one go?

studies/reachability_calibration.py fits the condition's parameters to 48 000 poses
of terrains/training_arena.toml (seed 0) and reports them on a held-out third. This
script draws an independent set (`--poses`, default 36 000, `--seed`, default 1; same
sampler, `reachability_calibration.sample_poses`), computes the contact generator's
ground truth there (cached in .cache/ like the calibration's), and reports:

1. **Validation**: sensitivity and specificity, with 95 % Wilson intervals, of the
   `ReachabilityConfig()` defaults, of the training presets' `TRAINING_REACHABILITY`
   and, with `--calibration-json`, of the best setting of that calibration run
   (`chosen_with_hands`), under each truth of `--truth` (static: a balanced
   double-support posture; walking: a plan covering a 0.36 m
   straight guide).
2. **Learned reference** (`--learned`, needs scikit-learn: `pip install -e '.[dev]'`):
   what a flexible classifier reading the same local terrain reaches. A gradient-boosted
   tree ensemble (scikit-learn's HistGradientBoostingClassifier) is fitted on the fresh
   poses' root-frame heightmaps (`local_heightmap`: 26 x 33 points 0.04 m apart,
   x -0.40..+0.60 m, y -0.64..+0.64 m, terrain height minus root z) and tested on the
   calibration's poses (`--calibration-poses`). Its threshold is set on a tenth of the
   fitting poses kept aside, for 95 % sensitivity there; the report gives the test figures at that
   threshold, and the specificity at the threshold that gives exactly 95 % sensitivity
   on the test poses (optimistic: chosen on them). Repeated for growing training sets
   (`--train-sizes`): whether the cylinders' gap is one of information (the heightfield
   near the root does not tell) or of form (the cylinders cannot express what it tells).

    python studies/reachability_validation.py [--poses 36000] [--truth static walking]
        [--learned] [--calibration-json docs/results/.../reachability_calibration.json] [--reuse]

Writes <out>/reachability_validation.json.

Results: docs/results/2026-11-22-reachability-48000-poses.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # the ground truth's workers are the parallelism

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "benchmarks")]  # the other studies, benchmarks/common.py

import reachability_calibration as rc  # noqa: E402

from leas_jax.feasibility.poses import ARENA, cylinder_verdicts, sample_poses  # noqa: E402
from leas_jax.stats import rates  # noqa: E402

TARGET_SENSITIVITY = rc.TARGET_SENSITIVITY
HEIGHTMAP_STEP = 0.04  # m, spacing of the learned reference's heightmap
HEIGHTMAP_X = (-0.40, 0.60)  # m, root frame: behind the heels to past the lookahead legs (+0.30 m)
HEIGHTMAP_Y = (-0.64, 0.64)  # m, root frame: past the hand disks (0.45 + 0.13 m)
HEIGHTMAP_CLIP = (-1.6, 0.4)  # m, heights relative to the root (the void is -2 m below the arena)
CALIBRATION_SEED = 0  # studies/reachability_calibration.py's default --seed
THRESHOLD_SPLIT = 0.1  # share of the fitting poses kept aside to set the classifier's threshold


def local_heightmap(
    terrain,
    poses: np.ndarray,
    step: float = HEIGHTMAP_STEP,
    x_range=HEIGHTMAP_X,
    y_range=HEIGHTMAP_Y,
    clip=HEIGHTMAP_CLIP,
) -> np.ndarray:
    """Terrain heights around each root, in its frame (nearest raster cell, host NumPy).

    Args:
        terrain: a leas_jax.terrain.Terrain.
        poses: [N, 4] (x, y, z, yaw), world.
        step: grid spacing (m); x_range, y_range: (lo, hi) of the grid in the root frame (m).
        clip: (lo, hi) of the returned heights (m).

    Returns:
        [N, nx * ny] float32: terrain height minus root z at root-frame points
        (x_k, y_l), x-major (k slow), clipped; points off the raster read the void height.
    """
    poses = np.asarray(poses, dtype=np.float64).reshape(-1, 4)
    gx = np.arange(x_range[0], x_range[1] + 1e-9, step)
    gy = np.arange(y_range[0], y_range[1] + 1e-9, step)
    lx, ly = (a.ravel() for a in np.meshgrid(gx, gy, indexing="ij"))
    cos, sin = np.cos(poses[:, 3:4]), np.sin(poses[:, 3:4])
    wx = poses[:, 0:1] + cos * lx - sin * ly
    wy = poses[:, 1:2] + sin * lx + cos * ly
    heights = terrain.raster()
    (x0, y0), res = terrain.bounds[0], terrain.resolution
    i = np.round((wx - x0) / res).astype(np.int64)
    j = np.round((wy - y0) / res).astype(np.int64)
    inside = (i >= 0) & (i < heights.shape[0]) & (j >= 0) & (j < heights.shape[1])
    z = np.where(
        inside,
        heights[np.clip(i, 0, heights.shape[0] - 1), np.clip(j, 0, heights.shape[1] - 1)],
        terrain.void_height,
    )
    return np.clip(z - poses[:, 2:3], *clip).astype(np.float32)


def learned_reference(
    train_x: np.ndarray,
    train_y: np.ndarray,
    test_x: np.ndarray,
    test_y: np.ndarray,
    sizes,
    seed: int = 0,
    target: float = TARGET_SENSITIVITY,
) -> list[dict]:
    """Gradient-boosted trees fitted on growing prefixes of a training set, tested on another.

    Args:
        train_x: [N, F] features, train_y: [N] bool truth (the fitting poses, shuffled).
        test_x: [M, F], test_y: [M] bool (the test poses).
        sizes: training set sizes (each <= N); the first THRESHOLD_SPLIT of each is kept
            aside to set the threshold, the rest fits the model.
        seed: the model's random_state.
        target: sensitivity the threshold is set for.

    Returns:
        one dict per size: poses, fitted, threshold_poses, iterations, test figures at the
        aside-set threshold (`rates`), and specificity_at_target (at the threshold giving
        `target` sensitivity on the test poses themselves).
    """
    from sklearn.ensemble import HistGradientBoostingClassifier

    rows = []
    for size in sizes:
        if size > len(train_x):
            raise ValueError(f"--train-sizes: {size} exceeds the {len(train_x)} fitting poses")
        aside = max(1, int(round(THRESHOLD_SPLIT * size)))
        model = HistGradientBoostingClassifier(
            max_iter=1500,
            learning_rate=0.08,
            max_leaf_nodes=31,
            l2_regularization=1.0,
            early_stopping=True,
            validation_fraction=0.1,
            random_state=seed,
        )
        start = time.perf_counter()
        model.fit(train_x[aside:size], train_y[aside:size])
        seconds = time.perf_counter() - start
        aside_p = model.predict_proba(train_x[:aside])[:, 1]
        aside_feasible = aside_p[train_y[:aside]]
        if len(aside_feasible) == 0:
            raise ValueError(f"no feasible pose among the {aside} kept aside to set the threshold")
        threshold = float(np.quantile(aside_feasible, 1.0 - target))
        test_p = model.predict_proba(test_x)[:, 1]
        oracle = float(np.quantile(test_p[test_y], 1.0 - target))
        rows.append(
            {
                "poses": int(size),
                "fitted": int(size - aside),
                "threshold_poses": aside,
                "iterations": int(model.n_iter_),
                "fit_seconds": seconds,
                "threshold": threshold,
                "test": rates(test_p >= threshold, test_y),
                "specificity_at_target": float(np.mean(test_p[~test_y] < oracle)),
            }
        )
    return rows


def _fmt(c: dict) -> str:
    (slo, shi), (plo, phi) = c["sensitivity_95ci"], c["specificity_95ci"]
    return (
        f"sens {100 * c['sensitivity']:5.1f} % [{100 * slo:4.1f}, {100 * shi:4.1f}]  "
        f"spec {100 * c['specificity']:5.1f} % [{100 * plo:4.1f}, {100 * phi:4.1f}]  "
        f"(tp {c['tp']}, fn {c['fn']}, fp {c['fp']}, tn {c['tn']})"
    )


def main(argv=None) -> None:
    from common import add_out_argument, load_average, save

    from leas_jax.env import ReachabilityConfig
    from leas_jax.terrain import load_terrain
    from leas_jax.training.config import TRAINING_REACHABILITY

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--poses", type=int, default=36000, help="fresh poses to validate on")
    parser.add_argument("--seed", type=int, default=1, help="their sampler's seed (the calibration uses 0)")
    parser.add_argument("--truth", nargs="+", choices=("static", "walking"), default=["static", "walking"])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--reuse", action="store_true", help="reuse cached ground truths when they match")
    parser.add_argument(
        "--calibration-json",
        default=None,
        help="a reachability_calibration JSON: also validate its chosen_with_hands setting",
    )
    parser.add_argument("--learned", action="store_true", help="fit the learned reference (scikit-learn)")
    parser.add_argument(
        "--train-sizes",
        default="8000,18000,36000",
        help="comma-separated training set sizes of the learned reference",
    )
    parser.add_argument(
        "--calibration-poses",
        type=int,
        default=48000,
        help="the calibration's pose count (seed 0): the learned reference's test set",
    )
    add_out_argument(parser)
    args = parser.parse_args(argv)
    load_before = load_average()
    if args.seed == CALIBRATION_SEED:
        parser.error("--seed 0 draws the calibration's own poses; validate on another seed")
    sizes = [int(s) for s in args.train_sizes.split(",")] if args.learned else []
    if args.learned:
        try:
            import sklearn  # noqa: F401
        except ImportError:
            parser.error("--learned needs scikit-learn: pip install -e '.[dev]'")
        if max(sizes) > args.poses:
            parser.error(f"--train-sizes: {max(sizes)} exceeds --poses {args.poses}")

    terrain = load_terrain(ARENA)
    configs = {"defaults": ReachabilityConfig(), "training": TRAINING_REACHABILITY}
    if args.calibration_json:
        path = Path(args.calibration_json)
        try:
            chosen = json.loads(path.read_text())["chosen_with_hands"]
        except (OSError, ValueError, KeyError) as error:
            parser.error(f"--calibration-json {path}: cannot read its chosen_with_hands ({error})")
        configs[f"chosen_with_hands of {path.name}"] = ReachabilityConfig(**chosen)
    poses = sample_poses(terrain, args.poses, args.seed)
    if args.learned:  # the same features for every truth: the fresh poses (shuffled) and the calibration's
        order = np.random.default_rng(args.seed).permutation(len(poses))
        train_x = local_heightmap(terrain, poses[order])
        test_poses = sample_poses(terrain, args.calibration_poses, CALIBRATION_SEED)
        test_x = local_heightmap(terrain, test_poses)
    report = {
        "poses": args.poses,
        "seed": args.seed,
        "terrain": f"terrains/{ARENA.name}",
        "configs": {name: dataclasses.asdict(cfg) for name, cfg in configs.items()},
        "truths": {},
    }
    for truth_name in args.truth:
        truth, seconds = rc.cached_ground_truth(
            terrain, poses, truth_name, args.workers, args.reuse, args.seed
        )
        print(
            f"\n{truth_name} truth: {len(poses)} fresh poses (seed {args.seed}), {int(truth.sum())} feasible, "
            f"{seconds:.0f} s with {args.workers} workers"
        )
        entry = {"feasible": int(truth.sum()), "ground_truth_seconds": seconds, "validation": {}}
        for name, cfg in configs.items():
            entry["validation"][name] = rates(cylinder_verdicts(terrain, poses, cfg), truth)
            print(f"  {name:40s} {_fmt(entry['validation'][name])}")
        if args.learned:
            test_truth, _ = rc.cached_ground_truth(
                terrain, test_poses, truth_name, args.workers, args.reuse, CALIBRATION_SEED
            )
            rows = learned_reference(train_x, truth[order], test_x, test_truth, sizes)
            test_set = f"the calibration's {len(test_poses)} poses (seed {CALIBRATION_SEED})"
            entry["learned_reference"] = {
                "test": test_set,
                "heightmap": {
                    "step_m": HEIGHTMAP_STEP,
                    "x_m": HEIGHTMAP_X,
                    "y_m": HEIGHTMAP_Y,
                    "clip_m": HEIGHTMAP_CLIP,
                },
                "rows": rows,
            }
            print(
                f"  learned reference (gradient-boosted trees on a {HEIGHTMAP_STEP} m root-frame heightmap), "
                f"tested on the calibration's {len(test_poses)} poses:"
            )
            for row in rows:
                print(
                    f"    {row['poses']:6d} training poses: {_fmt(row['test'])}; specificity at "
                    f"{100 * TARGET_SENSITIVITY:.0f} % test sensitivity {100 * row['specificity_at_target']:5.1f} %"
                )
        report["truths"][truth_name] = entry
    save("reachability_validation", report, load_before, args.out)


if __name__ == "__main__":
    main()
