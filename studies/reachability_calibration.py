"""Which cylinder parameters make the reachability condition (docs/design.md §5) agree best with
the contact generator?

Ground truth: a root pose (x, y, z, yaw) is *feasible* when the contact generator
finds a balanced, collision-free double-support posture there
(`leas_jax.contacts.planner.generator.double_support_posture`: what it does for the first
posture of a plan, root offsets included). The condition is
`leas_jax.env.reachability.valid` (jitted, vmapped) on the Heightfield of the
terrain. Figures: sensitivity = P(condition | feasible), specificity =
P(not condition | infeasible) (the contact-planner literature reports 97 % / 92.5 %).

Poses (seeded) on `terrains/training_arena.toml`: x, y uniform over the arena (70 %)
or near obstacles (30 %: grid points whose 0.35 m neighbourhood spans more than
5 cm of height, away from the raster border, jittered), yaw uniform, z = reference height + the nominal root height
(EnvConfig, 1.0 m) + an offset uniform in [-0.55, +0.35] m. The reference height is
the highest terrain point within 0.15 m (the ground a foot would stand on, so that
poses beside holes stand over the ground). The offset range is wider than +-0.3 m
below the nominal so that it brackets both ends of the generator's flat-ground range
(root 0.53 to 1.18 m above the soles).

The ground truth is computed once (multiprocessing, `--workers` processes, one
ContactGenerator each); a grid search then re-evaluates only the condition over the
cylinder parameters. The condition only reads three rasters at three points per pose:
trunk_max at the root, leg_max and leg_min at the two leg centres (rasters depend on
the radii, the centres on leg_lateral_offset), so for each radius pair those values
are sampled once (jitted) and the thresholds (trunk_bottom, leg_bottom, leg_top) are
compared in NumPy. trunk_top plays no part: a heightfield has no overhang, so the
trunk cylinder is free iff the terrain under it stays below its bottom. The old and
the chosen defaults are also evaluated with `reachability.valid` itself on
`heightfield_from_terrain(terrain, EnvConfig(reachability=cfg))`, and must agree.

Optional terms (studies/reachability_false_positives.py): a second
search (`TERMS_GRID`) adds the lookahead leg cylinders (`leg_forward`) and the foothold
flatness term (`foothold_radius`, `foothold_search`, `foothold_spread`) of
`leas_jax.env.reachability` to the thresholds above, on fewer radii (they cost a
raster per setting); both bests are reported, and the NumPy form of each is checked
against the jitted condition. A third search (`HANDS_GRID`) adds the hands term
(`hand_radius`, `hand_bottom`: the half-sitting grippers beside the trunk cylinder) to
the radii and foothold the second one chose, over every lookahead of `TERMS_GRID`, with
the same thresholds grid. Its best is the ReachabilityConfig default.

Selection: parameters that keep a root at 1.0 m and at NOMINAL_ROOT_HEIGHT (1.019 m)
above flat ground valid with >= 2 cm margins (the environment's spawn logic needs it);
among those with sensitivity >= 95 % and specificity >= 90 % on the fitting two
thirds of the poses, the largest Youden index (sensitivity + specificity - 1); if none
meets both, the best specificity among those with sensitivity >= 95 %; if none, the
largest Youden index. Near-ties go to the closest to the old defaults. Figures are
reported on the held-out third and on all poses. Writes <out>/reachability_calibration.json
(and caches the ground truth in .cache/reachability_ground_truth_<truth>_seed<seed>_<poses>.npz
at the repository root, reused with --reuse when the poses and the fingerprint of the
contact generator's sources, leas_jax/contacts/**/*.py, match).

Default: 48 000 poses (the walking truth's held-out third then holds ~4 400 feasible
poses, +-0.6 % on a sensitivity at 95 %; with the 12 000 used before commit 797a783,
the chosen setting's 95.8 % fitting sensitivity was 94.9 % on fresh poses). On 2 cores:
~2.5 min of ground truth (walking; ~1.5 min static) and ~20 min of search.

    python studies/reachability_calibration.py [--poses 48000] [--workers 2] [--reuse]

Results: docs/results/2026-11-22-reachability-48000-poses; earlier calibrations in
2026-11-21-benchmarks-generator-speed-ups and the 2026-11-22-benchmarks-* folders.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # the workers are the parallelism

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import hashlib  # noqa: E402
import itertools  # noqa: E402
import multiprocessing  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from leas_jax.feasibility.poses import (  # noqa: E402
    ARENA,
    NEAR_FRACTION,
    REFERENCE_RADIUS,
    Z_OFFSETS,
    cylinder_verdicts,
    sample_poses,
)
from leas_jax.feasibility.walking_truth import (  # noqa: E402
    WALK_POSES,
    WALK_SPEED,
    WALK_TIMESTEP,
    walking_guide,
)
from leas_jax.stats import confusion  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "benchmarks")]  # the other studies, benchmarks/common.py

REPO = Path(__file__).resolve().parent.parent
FLAT_HEIGHTS = (1.0, 1.01927)  # m: EnvConfig.nominal_root_height and contacts.NOMINAL_ROOT_HEIGHT
FLAT_MARGIN = 0.02  # m, margin those must keep from every threshold
TARGET_SENSITIVITY = 0.95
TARGET_SPECIFICITY = 0.90

# Grid of the search (m). trunk_top is not searched: no effect on a heightfield. leg_top goes
# down to -0.95 (it stopped at -0.70 before the optional terms): with the walking truth the
# lowest ground under a leg must be ~0.9 m below the root, and -0.95 still keeps the
# flat-ground margins (FLAT_MARGIN).
GRID = {
    "trunk_radius": (0.15, 0.20, 0.25, 0.30, 0.35, 0.40),
    "leg_radius": (0.05, 0.08, 0.10, 0.15, 0.20, 0.25, 0.30),
    "trunk_bottom": tuple(np.round(np.arange(-0.40, -0.9751, -0.025), 3)),
    "leg_bottom": tuple(np.round(np.arange(-1.05, -1.3001, -0.025), 3)),
    "leg_top": tuple(np.round(np.arange(-0.40, -0.9501, -0.025), 3)),
}
# Grid of the optional terms, searched with the thresholds of GRID on fewer radii (the two
# trunk radii the search above prefers, the smallest leg radius). foothold: None (off) or
# (foothold_radius, foothold_search) in m, each with every foothold_spread (m).
TERMS_GRID = {
    "trunk_radius": (0.20, 0.30),
    "leg_radius": (0.05,),
    "leg_forward": (0.0, 0.06, 0.12, 0.18, 0.24, 0.30, 0.36),
    "foothold": (None, (0.065, 0.10), (0.08, 0.10), (0.10, 0.10)),
    "foothold_spread": (0.01, 0.02, 0.04),
}
# Grid of the hands term (`hand_radius`, `hand_bottom`; hand centres at the defaults of
# ReachabilityConfig, from the model's grippers), searched with the thresholds of GRID on
# the radii and foothold chosen by the search with TERMS_GRID and every lookahead of
# TERMS_GRID (the best lookahead with the hands is not the best without them: 0.30 against
# 0.24 m). None: term off.
HANDS_GRID = {
    "hand": (None, 0.10, 0.13, 0.16, 0.20, 0.24),
    "hand_bottom": (-0.45, -0.40, -0.35, -0.30, -0.25),
}


# ------------------------------------------------------------------ ground truth

_WORKER = {}


def _init_worker(terrain_text: str) -> None:
    from leas_jax.contacts.planner.generator import ContactGenerator
    from leas_jax.terrain import loads_terrain

    _WORKER["generator"] = ContactGenerator(loads_terrain(terrain_text, source="<calibration>"))


def _feasible_one(generator, pose, truth: str) -> bool:
    if truth == "static":
        return generator.double_support(pose) is not None
    return generator.plan(walking_guide(pose), WALK_TIMESTEP).coverage >= 1.0


def _feasible_chunk(job) -> np.ndarray:
    poses, truth = job
    generator = _WORKER["generator"]
    return np.array([_feasible_one(generator, pose, truth) for pose in poses], dtype=bool)


def ground_truth(
    terrain, poses: np.ndarray, workers: int = 2, chunk: int = 100, truth: str = "static"
) -> np.ndarray:
    """[N] whether the contact generator stands at each pose [N, 4] (truth "static": a
    double-support posture; "walking": a plan covering a short straight guide from it).

    Host-only. workers <= 1 runs in this process; otherwise a `spawn` pool (JAX may
    already hold threads here, which `fork` would copy half-initialised) with one
    ContactGenerator per worker; results keep the order of `poses`.
    """
    poses = np.asarray(poses, dtype=np.float64).reshape(-1, 4)
    chunks = [(poses[k : k + chunk], truth) for k in range(0, len(poses), chunk)]
    if workers <= 1:
        _init_worker(terrain.text)
        parts = [_feasible_chunk(c) for c in chunks]
    else:
        ctx = multiprocessing.get_context("spawn")
        with ctx.Pool(workers, initializer=_init_worker, initargs=(terrain.text,)) as pool:
            parts = pool.map(_feasible_chunk, chunks)
    return np.concatenate(parts) if parts else np.zeros(0, dtype=bool)


def generator_fingerprint(truth: str) -> str:
    """sha256 of the contact generator's sources (leas_jax/contacts/**/*.py) and of the truth's
    settings: a cached ground truth is reused only if nothing it depends on changed."""
    digest = hashlib.sha256(f"{truth} {WALK_POSES} {WALK_SPEED} {WALK_TIMESTEP}".encode())
    contacts = REPO / "leas_jax" / "contacts"
    for path in sorted(contacts.rglob("*.py")):
        digest.update(path.relative_to(contacts).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def cache_path(truth: str, seed: int, count: int) -> Path:
    """.cache/reachability_ground_truth_<truth>_seed<seed>_<count>.npz at the repository root
    (git-ignored): one file per pose set (`sample_poses(terrain, count, seed)`), so that
    runs on other sets (studies/reachability_validation.py) keep each other's."""
    return REPO / ".cache" / f"reachability_ground_truth_{truth}_seed{seed}_{count}.npz"


def cached_ground_truth(
    terrain, poses: np.ndarray, truth: str = "static", workers: int = 2, reuse: bool = True, seed: int = 0
) -> tuple[np.ndarray, float]:
    """`ground_truth` of poses [N, 4] (drawn with `seed`), from the cache
    (`cache_path(truth, seed, N)`) when `reuse` and it holds the same poses and generator
    fingerprint; otherwise computed and cached. Returns (truth [N] bool, seconds it took
    to compute)."""
    cache = cache_path(truth, seed, len(poses))
    fingerprint = generator_fingerprint(truth)
    if reuse and cache.is_file():
        with np.load(cache) as data:
            same_poses = data["poses"].shape == poses.shape and np.array_equal(data["poses"], poses)
            same_generator = "generator" in data.files and str(data["generator"]) == fingerprint
            if same_poses and same_generator:
                print(f"reused the ground truth of {cache}")
                return data["truth"], float(data["seconds"])
            print(
                f"not reusing {cache}: " + ("the contact generator changed" if same_poses else "other poses")
            )
    start = time.perf_counter()
    result = ground_truth(terrain, poses, workers, truth=truth)
    seconds = time.perf_counter() - start
    cache.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(cache, poses=poses, truth=result, seconds=seconds, generator=fingerprint)
    return result, seconds


# ------------------------------------------------------------------ condition


def raster_samples(
    terrain,
    poses: np.ndarray,
    trunk_radius: float,
    leg_radius: float,
    leg_lateral_offset: float,
    leg_forward: float = 0.0,
    foothold=None,
    hand_radius=None,
) -> dict:
    """What the condition reads, per pose, for one set of radii (jitted, vmapped).

    Args:
        terrain: a leas_jax.terrain.Terrain; poses: [N, 4] (x, y, z, yaw), world.
        trunk_radius, leg_radius, leg_lateral_offset, leg_forward: ReachabilityConfig fields, m.
        foothold: None (term off) or (foothold_radius, foothold_search), m.
        hand_radius: None (term off) or the hands term's radius, m (centres: ReachabilityConfig's).

    Returns:
        dict of float32 arrays: z [N], trunk [N] (trunk_max at the root), leg_max and
        leg_min [N, L] (at the leg centres of `reachability.all_leg_centers`: left, right,
        then left and right ahead when leg_forward != 0, L = 2 or 4), with the
        foothold term, foothold [N, L] (the foothold raster at those centres) and, with
        the hands term, hand [N, 2] (hand_max at the left and right hand centres).
    """
    import jax
    import jax.numpy as jnp

    from leas_jax.env import EnvConfig, ReachabilityConfig
    from leas_jax.env.field import heightfield_from_raster, sample_nearest
    from leas_jax.env.reachability import all_leg_centers, hand_centers

    extra = (
        {}
        if foothold is None
        else {"foothold_radius": foothold[0], "foothold_search": foothold[1], "foothold_spread": 0.0}
    )  # any value: builds the raster
    config = ReachabilityConfig(
        trunk_radius=trunk_radius,
        leg_radius=leg_radius,
        leg_lateral_offset=leg_lateral_offset,
        leg_forward=leg_forward,
        hand_radius=hand_radius,
        **extra,
    )
    # The environment's own rasters (the void is no floor for the legs); spawn points are
    # not needed here, and the grid visits radii where there may be none.
    field = heightfield_from_raster(
        terrain.raster(),
        terrain.bounds[0],
        terrain.resolution,
        terrain.void_height,
        EnvConfig(reachability=config),
        require_spawn=False,
    )

    def one(f, pose):
        legs = all_leg_centers(pose, config)
        return (
            sample_nearest(f, f.trunk_max, pose[:2]),
            sample_nearest(f, f.leg_max, legs, outside=-jnp.inf),
            sample_nearest(f, f.leg_min, legs, outside=jnp.inf),
            sample_nearest(f, f.foothold, legs, outside=jnp.inf) if foothold is not None else jnp.zeros(0),
            sample_nearest(f, f.hand_max, hand_centers(pose, config), outside=-jnp.inf)
            if hand_radius is not None
            else jnp.zeros(0),
        )

    poses32 = jnp.asarray(poses, dtype=jnp.float32)
    trunk, leg_max, leg_min, flat, hand = jax.jit(jax.vmap(one, in_axes=(None, 0)))(field, poses32)
    out = {
        "z": np.asarray(poses32[:, 2]),
        "trunk": np.asarray(trunk),
        "leg_max": np.asarray(leg_max),
        "leg_min": np.asarray(leg_min),
    }
    if foothold is not None:
        out["foothold"] = np.asarray(flat)
    if hand_radius is not None:
        out["hand"] = np.asarray(hand)
    return out


def thresholds(
    samples: dict, trunk_bottom, leg_bottom, leg_top, foothold_spread=None, hand_bottom=None
) -> np.ndarray:
    """The condition of `reachability.terms` from `raster_samples`, for many thresholds at once.

    Args:
        samples: raster_samples output (N poses, L leg centres).
        trunk_bottom, leg_bottom, leg_top: [...] broadcastable threshold arrays, m.
        foothold_spread: None (term off) or a scalar, m (needs samples["foothold"]).
        hand_bottom: None (term off) or a scalar, m (needs samples["hand"]).

    Returns:
        [..., N] bool (float32 arithmetic, as in the jitted condition).
    """
    z = samples["z"]
    f = np.float32
    tb, lb, lt = (np.asarray(v, dtype=f)[..., None] for v in (trunk_bottom, leg_bottom, leg_top))
    result = samples["trunk"] < z + tb
    for k in range(samples["leg_max"].shape[1]):  # every leg cylinder touches
        result = result & (samples["leg_max"][:, k] >= z + lb) & (samples["leg_min"][:, k] <= z + lt)
    if foothold_spread is not None:
        result = result & np.all(samples["foothold"] <= f(foothold_spread), axis=1)
    if hand_bottom is not None:
        result = result & np.all(samples["hand"] < (z + f(hand_bottom))[:, None], axis=1)
    return result


def flat_ground_ok(trunk_bottom, leg_bottom, leg_top, heights=FLAT_HEIGHTS, margin: float = FLAT_MARGIN):
    """[...] whether roots at `heights` above flat ground stay valid with `margin` (m) to spare.

    On flat ground at 0 with the root at h: trunk free iff 0 < h + trunk_bottom, legs
    touch iff h + leg_bottom <= 0 <= h + leg_top.
    """
    lo, hi = min(heights), max(heights)
    return (
        (np.asarray(trunk_bottom) + lo >= margin)
        & (np.asarray(leg_bottom) + hi <= -margin)
        & (np.asarray(leg_top) + lo >= margin)
    )


# ------------------------------------------------------------------ search


def grid_search(
    terrain,
    poses: np.ndarray,
    truth: np.ndarray,
    fit: np.ndarray,
    base_config,
    grid: dict = GRID,
    terms_grid: dict | None = None,
) -> dict:
    """Best cylinder parameters over `grid` (see the module docstring).

    Args:
        poses: [N, 4]; truth: [N] ground truth; fit: [N] bool, poses used for choosing.
        base_config: ReachabilityConfig giving the unsearched fields and the tie-break origin.
        grid: thresholds (trunk_bottom, leg_bottom, leg_top) and radii (trunk_radius,
            leg_radius) to search.
        terms_grid: None (the optional terms keep base_config's values), or a dict like
            TERMS_GRID whose radii replace grid's and whose leg_forward, foothold and
            foothold_spread values are searched too, and the hands term's `hand` (radius
            or None) and `hand_bottom` values when it has them (else base_config's).

    Returns:
        dict: config (the chosen ReachabilityConfig), met (targets met on the fitting
        poses), sensitive, candidates (number searched), fit_figures, table (the best
        thresholds per setting of the radii and terms, in search order).
    """
    tb, lb, lt = np.meshgrid(grid["trunk_bottom"], grid["leg_bottom"], grid["leg_top"], indexing="ij")
    tb, lb, lt = tb.ravel(), lb.ravel(), lt.ravel()
    allowed = flat_ground_ok(tb, lb, lt)
    tb, lb, lt = tb[allowed], lb[allowed], lt[allowed]
    hands = (
        (base_config.hand_radius,)
        if terms_grid is None
        else terms_grid.get("hand", (base_config.hand_radius,))
    )
    hand_bottoms = (
        (base_config.hand_bottom,)
        if terms_grid is None
        else terms_grid.get("hand_bottom", (base_config.hand_bottom,))
    )
    if terms_grid is None:
        radii = itertools.product(
            grid["trunk_radius"],
            grid["leg_radius"],
            (base_config.leg_forward,),
            (
                None
                if base_config.foothold_spread is None
                else (base_config.foothold_radius, base_config.foothold_search),
            ),
            hands,
        )
        spreads = (base_config.foothold_spread,)
    else:
        radii = itertools.product(
            terms_grid["trunk_radius"],
            terms_grid["leg_radius"],
            terms_grid["leg_forward"],
            terms_grid["foothold"],
            hands,
        )
        spreads = terms_grid["foothold_spread"]
    best, table = None, []
    base = np.array(
        [
            base_config.trunk_radius,
            base_config.leg_radius,
            base_config.trunk_bottom,
            base_config.leg_bottom,
            base_config.leg_top,
        ]
    )
    for trunk_radius, leg_radius, leg_forward, foothold, hand in radii:
        samples = raster_samples(
            terrain,
            poses[fit],
            trunk_radius,
            leg_radius,
            base_config.leg_lateral_offset,
            leg_forward,
            foothold,
            hand,
        )
        for spread, hand_bottom in itertools.product(
            (None,) if foothold is None else spreads, (None,) if hand is None else hand_bottoms
        ):
            figures = confusion(thresholds(samples, tb, lb, lt, spread, hand_bottom), truth[fit])
            sens, spec = figures["sensitivity"], figures["specificity"]
            youden = sens + spec - 1
            sensitive = sens >= TARGET_SENSITIVITY
            met = sensitive & (spec >= TARGET_SPECIFICITY)
            score = np.round(np.where(met, youden, np.where(sensitive, spec, youden)), 4)
            params = np.column_stack(
                [np.full(len(tb), trunk_radius), np.full(len(tb), leg_radius), tb, lb, lt]
            )
            # tie-break: closest to the old defaults, and an optional term counts as 0.1 m away
            distance = (
                np.abs(params - base).sum(axis=1)
                + abs(leg_forward - base_config.leg_forward)
                + 0.1 * (spread is not None)
                + 0.1 * (hand is not None)
            )
            # Rank: both targets met (then the best Youden index); else the sensitivity
            # target met (then the best specificity: a false negative ends episodes the
            # generator could have walked, for good, while a false positive is caught by
            # the generator in the planner-in-the-loop mode); else the best Youden index.
            # Scores are rounded so that near-ties go to the parameters closest to the old defaults.
            key = np.lexsort((distance, -score, ~sensitive, ~met))
            k = int(key[0])
            row = {
                "trunk_radius": trunk_radius,
                "leg_radius": leg_radius,
                "trunk_bottom": float(tb[k]),
                "leg_bottom": float(lb[k]),
                "leg_top": float(lt[k]),
                "leg_forward": float(leg_forward),
                "foothold_radius": None if spread is None else float(foothold[0]),
                "foothold_search": None if spread is None else float(foothold[1]),
                "foothold_spread": None if spread is None else float(spread),
                "hand_radius": None if hand is None else float(hand),
                "hand_bottom": None if hand is None else float(hand_bottom),
                "met": bool(met[k]),
                "sensitive": bool(sensitive[k]),
                "score": float(score[k]),
                "sensitivity": float(sens[k]),
                "specificity": float(spec[k]),
                "youden": float(youden[k]),
                "distance": float(distance[k]),
            }
            table.append(row)
            rank = (not row["met"], not row["sensitive"], -row["score"], row["distance"])
            if best is None or rank < best[0]:
                best = (rank, row)
    row = best[1]
    fields = {
        k: row[k]
        for k in (
            "trunk_radius",
            "leg_radius",
            "trunk_bottom",
            "leg_bottom",
            "leg_top",
            "leg_forward",
            "foothold_spread",
            "hand_radius",
        )
    }
    if row["foothold_spread"] is not None:
        fields.update(foothold_radius=row["foothold_radius"], foothold_search=row["foothold_search"])
    if row["hand_radius"] is not None:
        fields.update(hand_bottom=row["hand_bottom"])
    config = dataclasses.replace(base_config, **fields)
    return {
        "config": config,
        "met": row["met"],
        "sensitive": row["sensitive"],
        "candidates": int(len(tb)) * len(table),
        "fit_figures": {"sensitivity": row["sensitivity"], "specificity": row["specificity"]},
        "table": table,
    }


def figures(terrain, poses, truth, config, fit) -> dict:
    """Figures of one config with the jitted `reachability.valid`, on all / fit / held-out poses."""
    predicted = cylinder_verdicts(terrain, poses, config)
    return {
        "all": confusion(predicted, truth),
        "fit": confusion(predicted[fit], truth[fit]),
        "held_out": confusion(predicted[~fit], truth[~fit]),
    }, predicted


def breakdown(poses, truth, predicted, terrain, nominal: float = 1.0) -> list[dict]:
    """Rates per band of root height above the reference ground (where the errors are)."""
    from leas_jax.env.field import disk_filter

    reference = disk_filter(
        terrain.raster(), REFERENCE_RADIUS / terrain.resolution, "max", terrain.void_height
    )
    ij = np.clip(
        np.round((poses[:, :2] - terrain.bounds[0]) / terrain.resolution).astype(int),
        0,
        np.array(reference.shape) - 1,
    )
    offset = poses[:, 2] - reference[ij[:, 0], ij[:, 1]] - nominal
    rows = []
    for lo in np.arange(Z_OFFSETS[0], Z_OFFSETS[1] - 1e-9, 0.1):
        band = (offset >= lo) & (offset < lo + 0.1)
        c = confusion(predicted[band], truth[band])
        rows.append(
            {
                "offset_from": round(float(lo), 2),
                "offset_to": round(float(lo + 0.1), 2),
                "poses": int(band.sum()),
                "feasible": int(truth[band].sum()),
                **c,
            }
        )
    return rows


def _describe(cfg) -> str:
    """One line of a ReachabilityConfig: cylinders and the optional terms."""
    text = (
        f"trunk r {cfg.trunk_radius:.2f} [{cfg.trunk_bottom:+.3f}, {cfg.trunk_top:+.2f}], "
        f"legs r {cfg.leg_radius:.2f} [{cfg.leg_bottom:+.3f}, {cfg.leg_top:+.3f}]"
    )
    if cfg.leg_forward != 0.0:
        text += f", lookahead legs {cfg.leg_forward:+.2f} m"
    if cfg.foothold_spread is not None:
        text += (
            f", foothold r {cfg.foothold_radius:.3f} within {cfg.foothold_search:.2f} m, "
            f"spread <= {cfg.foothold_spread:.3f} m"
        )
    if cfg.hand_radius is not None:
        text += f", hands r {cfg.hand_radius:.2f} below {cfg.hand_bottom:+.2f}"
    return text


def _fmt(c: dict) -> str:
    return (
        f"sens {100 * c['sensitivity']:5.1f} %  spec {100 * c['specificity']:5.1f} %  "
        f"tp {c['tp']:5d} fn {c['fn']:5d} fp {c['fp']:5d} tn {c['tn']:5d}"
    )


def main(argv=None) -> None:
    from common import add_out_argument, load_average, save

    from leas_jax.env import ReachabilityConfig
    from leas_jax.terrain import load_terrain
    from leas_jax.training.config import REACHABILITY_TERMS_OFF, TRAINING_REACHABILITY

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--poses", type=int, default=48000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--terrain", default=str(ARENA))
    parser.add_argument("--reuse", action="store_true", help="reuse the cached ground truth if it matches")
    parser.add_argument(
        "--truth",
        choices=("static", "walking"),
        default="static",
        help="feasible = a double-support posture (static) or a plan "
        "covering a 0.36 m straight guide from the pose (walking)",
    )
    parser.add_argument(
        "--baseline",
        default=None,
        help="old defaults as 'trunk_radius,trunk_bottom,trunk_top,leg_radius,leg_bottom,leg_top' "
        "(default: docs/design.md §5 values)",
    )
    add_out_argument(parser)
    args = parser.parse_args(argv)
    load_before = load_average()

    terrain = load_terrain(args.terrain)
    # docs/design.md §5 values: the defaults before this calibration.
    old = ReachabilityConfig(
        trunk_radius=0.30,
        trunk_bottom=-0.63,
        trunk_top=0.60,
        leg_radius=0.25,
        leg_lateral_offset=0.085,
        leg_bottom=-1.06,
        leg_top=-0.54,
        **REACHABILITY_TERMS_OFF,
    )
    if args.baseline:
        tr, tb, tt, lr, lb, lt = map(float, args.baseline.split(","))
        old = ReachabilityConfig(
            trunk_radius=tr,
            trunk_bottom=tb,
            trunk_top=tt,
            leg_radius=lr,
            leg_bottom=lb,
            leg_top=lt,
            **REACHABILITY_TERMS_OFF,
        )
    poses = sample_poses(terrain, args.poses, args.seed)
    suffix = "" if args.truth == "static" else f"_{args.truth}"
    truth, gt_seconds = cached_ground_truth(terrain, poses, args.truth, args.workers, args.reuse, args.seed)
    print(
        f"ground truth: {len(poses)} poses, {int(truth.sum())} feasible, {gt_seconds:.0f} s "
        f"with {args.workers} workers ({1e3 * gt_seconds * max(args.workers, 1) / len(poses):.1f} ms per pose "
        f"per worker)"
    )
    fit = np.random.default_rng(args.seed + 1).random(len(poses)) < 2 / 3

    start = time.perf_counter()
    search = grid_search(terrain, poses, truth, fit, old)
    search_seconds = time.perf_counter() - start
    new = search["config"]
    start = time.perf_counter()
    terms_search = grid_search(terrain, poses, truth, fit, old, terms_grid=TERMS_GRID)
    terms_seconds = time.perf_counter() - start
    with_terms = terms_search["config"]
    start = time.perf_counter()
    hands_grid = {
        "trunk_radius": (with_terms.trunk_radius,),
        "leg_radius": (with_terms.leg_radius,),
        "leg_forward": TERMS_GRID["leg_forward"],
        "foothold": (
            None
            if with_terms.foothold_spread is None
            else (with_terms.foothold_radius, with_terms.foothold_search),
        ),
        "foothold_spread": (with_terms.foothold_spread,),
        **HANDS_GRID,
    }
    hands_search = grid_search(terrain, poses, truth, fit, old, terms_grid=hands_grid)
    hands_seconds = time.perf_counter() - start
    with_hands = hands_search["config"]
    old_figures, old_pred = figures(terrain, poses, truth, old, fit)
    new_figures, new_pred = figures(terrain, poses, truth, new, fit)
    terms_figures, terms_pred = figures(terrain, poses, truth, with_terms, fit)
    hands_figures, hands_pred = figures(terrain, poses, truth, with_hands, fit)
    current = ReachabilityConfig()
    current_figures, current_pred = figures(terrain, poses, truth, current, fit)
    training_figures, _ = figures(terrain, poses, truth, TRAINING_REACHABILITY, fit)
    # The NumPy thresholds of the searches must agree with the jitted condition.
    mismatch = 0
    for cfg, pred in ((new, new_pred), (with_terms, terms_pred), (with_hands, hands_pred)):
        foothold = None if cfg.foothold_spread is None else (cfg.foothold_radius, cfg.foothold_search)
        samples = raster_samples(
            terrain,
            poses,
            cfg.trunk_radius,
            cfg.leg_radius,
            cfg.leg_lateral_offset,
            cfg.leg_forward,
            foothold,
            cfg.hand_radius,
        )
        mismatch += int(
            np.sum(
                thresholds(
                    samples,
                    cfg.trunk_bottom,
                    cfg.leg_bottom,
                    cfg.leg_top,
                    cfg.foothold_spread,
                    None if cfg.hand_radius is None else cfg.hand_bottom,
                )
                != pred
            )
        )

    print(
        f"\ngrid search: {search['candidates']} candidates in {search_seconds:.1f} s; best per radius pair "
        f"(fitting poses):"
    )
    print(
        f"{'trunk r':>7s} {'leg r':>5s} {'trunk bot':>9s} {'leg bot':>7s} {'leg top':>7s} "
        f"{'sens %':>6s} {'spec %':>6s} {'met':>4s}"
    )
    for row in search["table"]:
        print(
            f"{row['trunk_radius']:7.2f} {row['leg_radius']:5.2f} {row['trunk_bottom']:9.3f} "
            f"{row['leg_bottom']:7.3f} {row['leg_top']:7.3f} {100 * row['sensitivity']:6.1f} "
            f"{100 * row['specificity']:6.1f} {'yes' if row['met'] else 'no':>4s}"
        )
    rank = lambda r: (not r["met"], not r["sensitive"], -r["score"], r["distance"])  # noqa: E731
    print(
        f"\nsearch with the optional terms: {terms_search['candidates']} candidates in {terms_seconds:.1f} s; "
        f"the 12 best settings (fitting poses):"
    )
    print(
        f"{'trunk r':>7s} {'leg r':>5s} {'trunk bot':>9s} {'leg bot':>7s} {'leg top':>7s} {'fwd':>5s} "
        f"{'foothold r/search/spread':>24s} {'sens %':>6s} {'spec %':>6s} {'met':>4s}"
    )
    for row in sorted(terms_search["table"], key=rank)[:12]:
        foot = (
            "off"
            if row["foothold_spread"] is None
            else f"{row['foothold_radius']:.3f}/{row['foothold_search']:.2f}/{row['foothold_spread']:.3f}"
        )
        print(
            f"{row['trunk_radius']:7.2f} {row['leg_radius']:5.2f} {row['trunk_bottom']:9.3f} "
            f"{row['leg_bottom']:7.3f} {row['leg_top']:7.3f} {row['leg_forward']:5.2f} {foot:>24s} "
            f"{100 * row['sensitivity']:6.1f} {100 * row['specificity']:6.1f} {'yes' if row['met'] else 'no':>4s}"
        )
    print(
        f"\nsearch with the hands term on that setting: {hands_search['candidates']} candidates in "
        f"{hands_seconds:.1f} s; best per hand radius and bottom (fitting poses):"
    )
    print(
        f"{'trunk bot':>9s} {'leg bot':>7s} {'leg top':>7s} {'hand r':>6s} {'hand bot':>8s} "
        f"{'sens %':>6s} {'spec %':>6s} {'met':>4s}"
    )
    for row in hands_search["table"]:
        hand = (
            ("   off", "     -")
            if row["hand_radius"] is None
            else (f"{row['hand_radius']:6.2f}", f"{row['hand_bottom']:8.2f}")
        )
        print(
            f"{row['trunk_bottom']:9.3f} {row['leg_bottom']:7.3f} {row['leg_top']:7.3f} {hand[0]:>6s} "
            f"{hand[1]:>8s} {100 * row['sensitivity']:6.1f} {100 * row['specificity']:6.1f} "
            f"{'yes' if row['met'] else 'no':>4s}"
        )
    print()
    for name, cfg, fig in (
        ("old (docs/design.md §5)", old, old_figures),
        ("new (cylinders only)", new, new_figures),
        ("new with the optional terms", with_terms, terms_figures),
        ("new with the optional terms and the hands", with_hands, hands_figures),
        ("current EnvConfig defaults", current, current_figures),
        ("training presets (TRAINING_REACHABILITY)", TRAINING_REACHABILITY, training_figures),
    ):
        print(f"{name}: {_describe(cfg)}")
        for part in ("all", "fit", "held_out"):
            print(f"  {part:9s} {_fmt(fig[part])}")
    for name, result in (
        ("cylinders only", search),
        ("with the optional terms", terms_search),
        ("with the optional terms and the hands", hands_search),
    ):
        print(
            f"{name}: targets (sens >= {100 * TARGET_SENSITIVITY:.0f} %, spec >= {100 * TARGET_SPECIFICITY:.0f} %) "
            f"{'met' if result['met'] else 'NOT met'} on the fitting poses (sensitivity target "
            f"{'met' if result['sensitive'] else 'NOT met'})"
        )
    print(f"jitted/NumPy mismatches: {mismatch}")

    as_dict = lambda c: dataclasses.asdict(c)  # noqa: E731
    save(
        f"reachability_calibration{suffix}",
        {
            "truth": args.truth,
            "terrain": str(Path(args.terrain).resolve().relative_to(REPO))
            if Path(args.terrain).resolve().is_relative_to(REPO)
            else args.terrain,
            "poses": len(poses),
            "feasible": int(truth.sum()),
            "seed": args.seed,
            "workers": args.workers,
            "ground_truth_seconds": gt_seconds,
            "search_seconds": search_seconds,
            "terms_search_seconds": terms_seconds,
            "hands_search_seconds": hands_seconds,
            "sampling": {
                "z_offsets_m": Z_OFFSETS,
                "near_obstacle_fraction": NEAR_FRACTION,
                "reference": f"highest terrain point within {REFERENCE_RADIUS} m",
                "nominal_m": 1.0,
            },
            "targets": {"sensitivity": TARGET_SENSITIVITY, "specificity": TARGET_SPECIFICITY},
            "flat_ground_constraint": {"heights_m": FLAT_HEIGHTS, "margin_m": FLAT_MARGIN},
            "grid": {k: list(map(float, v)) for k, v in GRID.items()},
            "candidates": search["candidates"],
            "terms_grid": {k: list(v) for k, v in TERMS_GRID.items()},
            "terms_candidates": terms_search["candidates"],
            "hands_grid": {k: list(v) for k, v in HANDS_GRID.items()},
            "hands_candidates": hands_search["candidates"],
            "targets_met_on_fit": search["met"],
            "sensitivity_target_met_on_fit": search["sensitive"],
            "terms_targets_met_on_fit": terms_search["met"],
            "terms_sensitivity_target_met_on_fit": terms_search["sensitive"],
            "hands_targets_met_on_fit": hands_search["met"],
            "hands_sensitivity_target_met_on_fit": hands_search["sensitive"],
            "chosen": as_dict(new),
            "chosen_with_terms": as_dict(with_terms),
            "chosen_with_hands": as_dict(with_hands),
            "old": as_dict(old),
            "current": as_dict(current),
            "training": as_dict(TRAINING_REACHABILITY),
            "figures": {
                "old": old_figures,
                "new": new_figures,
                "new_with_terms": terms_figures,
                "new_with_hands": hands_figures,
                "current": current_figures,
                "training": training_figures,
            },
            "by_height_offset": {
                "old": breakdown(poses, truth, old_pred, terrain),
                "new": breakdown(poses, truth, new_pred, terrain),
                "new_with_terms": breakdown(poses, truth, terms_pred, terrain),
                "new_with_hands": breakdown(poses, truth, hands_pred, terrain),
                "current": breakdown(poses, truth, current_pred, terrain),
            },
            "best_per_radius_pair": search["table"],
            "best_per_terms_setting": terms_search["table"],
            "best_per_hands_setting": hands_search["table"],
            "jit_numpy_mismatches": mismatch,
        },
        load_before,
        args.out,
    )


if __name__ == "__main__":
    main()
