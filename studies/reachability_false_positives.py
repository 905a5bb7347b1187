"""Which poses does the reachability condition accept where the contact generator cannot stand or
walk, and what do they have in common?

The poses, ground truth and condition are those of studies/reachability_calibration.py
(same seed, same cache in .cache/, `--truth walking` by default: feasible = the generator
covers a 0.36 m straight guide from the pose). A false positive (FP) is a pose where
`reachability.valid` holds with the given configuration (default: the current
`ReachabilityConfig()`) and the generator fails; a true positive (TP) one where both hold.

Every pose gets host-side features (NumPy, world frame, raster of the terrain):
  - cell kind: the arena's cell (from the terrain file's `# cell ... : kind` comments);
  - height offset: root z - highest terrain within 0.15 m - 1.0 m (nominal);
  - leg clearance: z - highest solid terrain within `leg_radius` of each leg centre (min of both);
  - leg spread: max - min of the terrain within SOLE_RADIUS of each leg centre (max of both;
    +inf when that disk touches the void);
  - edge distance: from the root to the nearest height jump > EDGE_JUMP between neighbouring
    cells, and whether the heading points at it (within 45 degrees);
  - ahead: whether the condition holds at every pose of the 0.36 m guide (jitted, vmapped);
  - generator outcome of each FP (unless --no-generator): where the plan stops
    (`last_valid_index`: -1 = cannot even stand at the pose) and, for -1, whether no sole
    placement was found for a foot ("no foothold") or the double-support posture failed.

The FPs are then put in exclusive classes (first match, in the order of `CLASSES`), each
printed with the TPs that fall in the same class: a term removing a class costs those TPs.
Writes <out>/reachability_false_positives[_<truth>].json.

    python studies/reachability_false_positives.py [--truth walking] [--reuse] [--no-generator]

Results: --out (default benchmarks/results/); its classes led to the optional terms of
`leas_jax.env.reachability` (docs/results/2026-11-22-reachability-48000-poses).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import multiprocessing  # noqa: E402
import re  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "benchmarks")]  # the other studies, benchmarks/common.py

import reachability_calibration as rc  # noqa: E402

from leas_jax.feasibility.poses import ARENA, REFERENCE_RADIUS, cylinder_verdicts, sample_poses  # noqa: E402
from leas_jax.feasibility.walking_truth import WALK_SPEED, WALK_TIMESTEP, walking_guide  # noqa: E402
from leas_jax.stats import confusion  # noqa: E402

SOLE_RADIUS = 0.08  # m, disk of the leg spread (sole 0.20 x 0.13 m: inscribed 0.065, circumscribed 0.12)
EDGE_JUMP = 0.03  # m, a height jump between neighbouring cells that makes an edge
NEAR_EDGE = 0.20  # m, "near an edge"
LOW_OFFSET, HIGH_OFFSET = -0.10, 0.10  # m, root "low" / "high" about the nominal 1.0 m above the reference
UNEVEN = 0.02  # m, leg spread above which a leg disk is "uneven"

# Exclusive classes of the false positives, first match wins: (name, description).
CLASSES = (
    ("walks_into_invalid", "the condition fails at a later pose of the 0.36 m guide"),
    ("root_low", f"height offset < {LOW_OFFSET:+.2f} m"),
    ("root_high", f"height offset > {HIGH_OFFSET:+.2f} m"),
    ("uneven_leg", f"a leg disk (r {SOLE_RADIUS} m) spans > {UNEVEN} m or touches the void"),
    ("near_edge", f"root within {NEAR_EDGE} m of an edge"),
    ("slope", "on a slope cell"),
    ("other", "none of the above"),
)


def cell_kinds(terrain, xy: np.ndarray) -> np.ndarray:
    """[N] kind of the arena cell under each world point xy [N, 2] ("unknown" outside every cell)."""
    kinds = np.full(len(xy), "unknown", dtype=object)
    pattern = r"# cell \(\d+, \d+\) \[([\d.]+), ([\d.]+)\] x \[([\d.]+), ([\d.]+)\]: (\w+)"
    for m in re.finditer(pattern, terrain.text):
        x0, x1, y0, y1 = map(float, m.group(1, 2, 3, 4))
        inside = (xy[:, 0] >= x0) & (xy[:, 0] < x1) & (xy[:, 1] >= y0) & (xy[:, 1] < y1)
        kinds[inside] = m.group(5)
    return kinds.astype(str)


def features(terrain, poses: np.ndarray, config) -> dict:
    """Host features of poses [N, 4] (see the module docstring). Returns a dict of [N] arrays."""
    from scipy import ndimage

    from leas_jax.env.field import _solid, disk_filter

    heights = terrain.raster()
    res, void = terrain.resolution, terrain.void_height
    origin = np.asarray(terrain.bounds[0])
    shape = np.array(heights.shape)

    def index(xy):
        return np.clip(np.round((xy - origin) / res).astype(int), 0, shape - 1)

    def at(raster, xy):
        k = index(xy)
        return raster[k[..., 0], k[..., 1]]

    z, yaw = poses[:, 2], poses[:, 3]
    side = np.column_stack([-np.sin(yaw), np.cos(yaw)])
    legs = np.stack(
        [poses[:, :2] + config.leg_lateral_offset * side, poses[:, :2] - config.leg_lateral_offset * side],
        axis=1,
    )  # [N, 2 legs, 2]
    reference = disk_filter(heights, REFERENCE_RADIUS / res, "max", void)
    leg_highest = disk_filter(_solid(heights, void, -np.inf), config.leg_radius / res, "max", -np.inf)
    sole_highest = disk_filter(_solid(heights, void, np.inf), SOLE_RADIUS / res, "max", np.inf)
    sole_lowest = disk_filter(heights, SOLE_RADIUS / res, "min", void)
    edge = (disk_filter(heights, 1.0, "max", void) - disk_filter(heights, 1.0, "min", void)) > EDGE_JUMP
    distance, (ei, ej) = ndimage.distance_transform_edt(~edge, return_indices=True)
    k = index(poses[:, :2])
    to_edge = origin + np.column_stack([ei[k[:, 0], k[:, 1]], ej[k[:, 0], k[:, 1]]]) * res - poses[:, :2]
    bearing = np.arctan2(to_edge[:, 1], to_edge[:, 0]) - yaw
    facing = np.cos(bearing) > np.cos(np.pi / 4)
    return {
        "kind": cell_kinds(terrain, poses[:, :2]),
        "offset": z - at(reference, poses[:, :2]) - 1.0,
        "leg_clearance": np.min(z[:, None] - at(leg_highest, legs), axis=1),
        "leg_spread": np.max(at(sole_highest, legs) - at(sole_lowest, legs), axis=1),
        "edge_distance": distance[k[:, 0], k[:, 1]] * res,
        "facing_edge": facing & (distance[k[:, 0], k[:, 1]] > 0),
    }


def valid_ahead(terrain, poses: np.ndarray, config) -> np.ndarray:
    """[N] whether the condition holds at every pose of each pose's walking guide (`walking_truth.walking_guide`)."""
    guides = np.stack([walking_guide(p) for p in poses])  # [N, WALK_POSES, 4]
    return cylinder_verdicts(terrain, guides.reshape(-1, 4), config).reshape(len(poses), -1).all(axis=1)


def _outcome_chunk(poses: np.ndarray) -> np.ndarray:
    """[n, 2] (last_valid_index, posture_failed) of the walking plan from each pose (pool worker)."""
    generator = rc._WORKER["generator"]
    out = np.zeros((len(poses), 2), dtype=np.int64)
    for n, pose in enumerate(poses):
        plan = generator.plan(walking_guide(pose), WALK_TIMESTEP)
        out[n, 0] = plan.last_valid_index
        if plan.last_valid_index < 0:  # which part of the initial stance failed
            feet = [None, None]
            for s in (0, 1):
                target, yaw = generator.footholds.nominal_placement(pose, s)
                feet[s] = generator.footholds.first_candidate(s, pose, target, yaw, feet[1 - s])
                if feet[s] is None:
                    break
            out[n, 1] = feet[0] is not None and feet[1] is not None
    return out


def generator_outcomes(terrain, poses: np.ndarray, workers: int = 2, chunk: int = 50) -> np.ndarray:
    """[N, 2] (last_valid_index, posture_failed) of the walking plans from poses [N, 4]."""
    parts = [poses[k : k + chunk] for k in range(0, len(poses), chunk)]
    if workers <= 1:
        rc._init_worker(terrain.text)
        results = [_outcome_chunk(p) for p in parts]
    else:
        with multiprocessing.get_context("spawn").Pool(
            workers, initializer=rc._init_worker, initargs=(terrain.text,)
        ) as pool:
            results = pool.map(_outcome_chunk, parts)
    return np.concatenate(results) if results else np.zeros((0, 2), dtype=np.int64)


def classify(f: dict, ahead: np.ndarray) -> np.ndarray:
    """[N] exclusive class name (CLASSES) of every pose from its features, first match wins."""
    tests = {
        "walks_into_invalid": ~ahead,
        "root_low": f["offset"] < LOW_OFFSET,
        "root_high": f["offset"] > HIGH_OFFSET,
        "uneven_leg": ~(f["leg_spread"] <= UNEVEN),
        "near_edge": f["edge_distance"] < NEAR_EDGE,
        "slope": f["kind"] == "slope",
    }
    out = np.full(len(ahead), "other", dtype=object)
    for name, _ in reversed(CLASSES[:-1]):
        out[tests[name]] = name
    return out.astype(str)


def _band_rows(values: np.ndarray, edges, fp: np.ndarray, tp: np.ndarray) -> list[dict]:
    rows = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        band = (values >= lo) & (values < hi)
        rows.append(
            {"from": float(lo), "to": float(hi), "fp": int((band & fp).sum()), "tp": int((band & tp).sum())}
        )
    return rows


def main(argv=None) -> None:
    from common import add_out_argument, load_average, save

    from leas_jax.env import ReachabilityConfig
    from leas_jax.terrain import load_terrain

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--poses", type=int, default=48000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--terrain", default=str(ARENA))
    parser.add_argument("--truth", choices=("static", "walking"), default="walking")
    parser.add_argument("--reuse", action="store_true", help="reuse the cached ground truth if it matches")
    parser.add_argument("--no-generator", action="store_true", help="skip the generator outcome of each FP")
    add_out_argument(parser)
    args = parser.parse_args(argv)
    load_before = load_average()

    terrain = load_terrain(args.terrain)
    config = ReachabilityConfig()
    poses = sample_poses(terrain, args.poses, args.seed)
    truth, _ = rc.cached_ground_truth(terrain, poses, args.truth, args.workers, args.reuse, args.seed)
    predicted = cylinder_verdicts(terrain, poses, config)
    fp, tp = predicted & ~truth, predicted & truth
    figures = confusion(predicted, truth)
    f = features(terrain, poses, config)
    ahead = valid_ahead(terrain, poses, config)
    cls = classify(f, ahead)
    print(f"{len(poses)} poses, truth {args.truth}, condition {rc._describe(config)}")
    print(
        f"sensitivity {100 * figures['sensitivity']:.1f} %, specificity {100 * figures['specificity']:.1f} %: "
        f"{figures['fp']} false positives, {figures['tp']} true positives\n"
    )

    print(f"{'class (first match)':20s} {'FP':>5s} {'TP':>5s}  {'FP share':>8s}  description")
    class_rows = []
    for name, description in CLASSES:
        n_fp, n_tp = int((fp & (cls == name)).sum()), int((tp & (cls == name)).sum())
        class_rows.append({"class": name, "description": description, "fp": n_fp, "tp": n_tp})
        print(f"{name:20s} {n_fp:5d} {n_tp:5d}  {100 * n_fp / max(fp.sum(), 1):7.1f} %  {description}")

    outcome_rows, outcomes = [], None
    if not args.no_generator:
        outcomes = generator_outcomes(terrain, poses[fp], args.workers)
        labels = np.where(
            outcomes[:, 0] >= 0,
            np.char.add(
                "stops after ",
                (np.maximum(outcomes[:, 0], 0) * WALK_SPEED * WALK_TIMESTEP).round(2).astype(str),
            ),
            np.where(outcomes[:, 1] == 1, "cannot stand: posture", "cannot stand: no foothold"),
        )
        names = [name for name, _ in CLASSES]
        print(
            "\ngenerator outcome of the FPs (rows; plan stops after that many m of the 0.36 m guide) "
            "by class (columns):"
        )
        print(f"{'outcome':26s} {'FP':>5s} " + " ".join(f"{n[:10]:>10s}" for n in names))
        for label in sorted(set(labels.tolist())):
            sel = labels == label
            counts = {n: int((cls[fp][sel] == n).sum()) for n in names}
            outcome_rows.append({"outcome": label, "fp": int(sel.sum()), "by_class": counts})
            print(f"{label:26s} {int(sel.sum()):5d} " + " ".join(f"{counts[n]:10d}" for n in names))

    kinds = sorted(set(f["kind"].tolist()))
    print(f"\nby cell kind:\n{'kind':14s} {'FP':>5s} {'TP':>5s} {'TN':>5s} {'FN':>5s} {'spec %':>6s}")
    kind_rows = []
    for kind in kinds:
        sel = f["kind"] == kind
        c = confusion(predicted[sel], truth[sel])
        kind_rows.append({"kind": kind, **c})
        print(f"{kind:14s} {c['fp']:5d} {c['tp']:5d} {c['tn']:5d} {c['fn']:5d} {100 * c['specificity']:6.1f}")

    bands = {
        "offset_m": (f["offset"], np.round(np.arange(-0.25, 0.2501, 0.05), 3)),
        "leg_clearance_m": (f["leg_clearance"], np.round(np.arange(0.80, 1.2001, 0.05), 3)),
        "leg_spread_m": (
            np.nan_to_num(f["leg_spread"], posinf=9.0),
            np.array([0, 0.005, 0.02, 0.05, 0.1, 0.3, 10]),
        ),
        "edge_distance_m": (f["edge_distance"], np.array([0, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0, 30])),
    }
    band_rows = {}
    for name, (values, edges) in bands.items():
        band_rows[name] = _band_rows(values, edges, fp, tp)
        print(
            f"\nby {name}: "
            + ", ".join(f"[{r['from']:g}, {r['to']:g}) FP {r['fp']} TP {r['tp']}" for r in band_rows[name])
        )
    facing = {
        "near_edge_facing": {
            "fp": int((fp & f["facing_edge"] & (f["edge_distance"] < 0.5)).sum()),
            "tp": int((tp & f["facing_edge"] & (f["edge_distance"] < 0.5)).sum()),
        },
        "near_edge_not_facing": {
            "fp": int((fp & ~f["facing_edge"] & (f["edge_distance"] < 0.5)).sum()),
            "tp": int((tp & ~f["facing_edge"] & (f["edge_distance"] < 0.5)).sum()),
        },
    }
    print(
        f"\nwithin 0.5 m of an edge: heading at it (45 deg) FP {facing['near_edge_facing']['fp']} "
        f"TP {facing['near_edge_facing']['tp']}; not FP {facing['near_edge_not_facing']['fp']} "
        f"TP {facing['near_edge_not_facing']['tp']}"
    )
    print(
        f"condition valid along the whole guide: FP {int((fp & ahead).sum())} of {int(fp.sum())}, "
        f"TP {int((tp & ahead).sum())} of {int(tp.sum())}"
    )

    save(
        f"reachability_false_positives_{args.truth}",
        {
            "truth": args.truth,
            "poses": len(poses),
            "seed": args.seed,
            "config": dataclasses.asdict(config),
            "figures": figures,
            "thresholds": {
                "sole_radius_m": SOLE_RADIUS,
                "edge_jump_m": EDGE_JUMP,
                "near_edge_m": NEAR_EDGE,
                "low_offset_m": LOW_OFFSET,
                "high_offset_m": HIGH_OFFSET,
                "uneven_m": UNEVEN,
            },
            "classes": class_rows,
            "generator_outcomes": outcome_rows,
            "by_kind": kind_rows,
            "bands": band_rows,
            "edge_heading": facing,
            "valid_along_guide": {"fp": int((fp & ahead).sum()), "tp": int((tp & ahead).sum())},
        },
        load_before,
        args.out,
    )


if __name__ == "__main__":
    main()
