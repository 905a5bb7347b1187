"""The walkability model: which root poses on rough ground the contact generator walks from.

The global layer of `leas navigate` (`leas_jax.navigate.lattice`) judges root poses standing
`nominal_root_height` above the ground (the highest solid ground within the leg radius; void
narrower than a crack counts as ground). A pose is *plausible* when the reachability cylinders
without their sole-flatness and lookahead terms accept it (trunk, leg reach, hands, solid
ground): no contact plan passes without those. Among plausible poses, the walkability model
says which the generator walks from (its walking truth: it covers the 0.36 m straight guide
ahead, `walking_truth`): the learned condition's network (`leas_jax.env.learned_feasibility`:
root-frame height patch, height above the local ground, the cylinders' margins), fitted on
poses of procedural terrain families (`families`) labelled by the generator, its threshold
set for `target_sensitivity` on a share of them kept aside.

Everything here is host code around jitted pieces (`judge` is jitted and vmapped):
  - `relaxed_reachability`, `crack_filled_ground`, `judge`, `judge_poses`: the plausible set
    and the model's verdicts, shared with the lattice;
  - `family_poses`, `walking_labels`: data (labels cached on disk under a key of the terrain
    text, the generator's settings and code; resumable);
  - `build`: data, fit and report in one call (`leas feasibility walkability`).
"""

from __future__ import annotations

import dataclasses
import functools
import multiprocessing
import time
from dataclasses import dataclass
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from leas_jax.env import reachability
from leas_jax.env.field import sample_nearest
from leas_jax.env.reachability import relaxed_reachability
from leas_jax.feasibility.label_cache import cached_labels
from leas_jax.feasibility.walking_truth import (
    WALK_TIMESTEP,
    dataset_key,
    generator_key,
    walking_guide,
    warn_if_stale,
)
from leas_jax.terrain.families import FAMILIES, FEATURE_X, family_terrain

WEIGHTS = "checkpoints/walkability/walkability.npz"  # the shipped model (relative to the repository)
HELD_OUT = ("blocks", "stones")  # families kept out of the fit: the report's generalisation test
# Terrain seeds: the fit takes 0.. (nominal heights, then jittered ones), the test of the
# training families TEST_SEEDS.. (nominal) and TEST_SEEDS + JITTERED_TEST_OFFSET.. (jittered),
# the held-out families HELD_OUT_SEEDS..: far apart, so no fit, however large, reaches a test.
TEST_SEEDS = 10_000
JITTERED_TEST_OFFSET = 1_000
HELD_OUT_SEEDS = 200
SCENE_SEEDS = 1_000  # the pose draws of the k-th scene: seed config.seed + SCENE_SEEDS + k (`scene_seed`)


@dataclass(frozen=True)
class WalkabilityConfig:
    """Data, fit and split of the walkability model."""

    train_families: tuple = tuple(f for f in FAMILIES if f not in HELD_OUT)
    held_out_families: tuple = HELD_OUT
    # 120 terrains x 25 draws of each training family fit; 2 unseen terrains x 250 draws of each
    # training family and 250 draws per scene test. Many small fitting terrains rather than a few large
    # ones (each stair flight is one riser and tread): at the same label cost, 40 x 25 against
    # 4 x 250 refused 78.0 % of the unwalkable poses of unseen terrains against 72.3 %, and 80 or
    # 120 x 25 80.3 %, at 94-95 % sensitivity (docs/results/2026-12-07-walkability-many-terrains;
    # those test terrains, seeds 100-101, were among the 120-terrain fit's: on the disjoint
    # TEST_SEEDS the nominal 120 x 25 model refuses 82.9 %, docs/results/2026-12-07-walkability-root-heights).
    terrains_per_family: int = 120  # seeds 0..n-1 fit (training families); seeds TEST_SEEDS.. test
    test_terrains_per_family: int = 2
    # The env judges a policy's poses, whose root rises and dips about the lattice's nominal
    # height (on the paper-arena policy's stair guides -0.08..+0.05 m from it, 5-95 %). More
    # fitting terrains (the seeds after the nominal ones), and as many test terrains
    # (TEST_SEEDS + JITTERED_TEST_OFFSET..), draw each root height uniformly within
    # +-root_height_jitter of the nominal one. With 40 such terrains per family the model refused
    # 67.9 % [62.9, 72.5] of the unwalkable jittered test poses against 57.2 % [52.0, 62.2]
    # without them, at 94 / 93 % sensitivity, and did not differ at the nominal height
    # (docs/results/2026-12-07-walkability-root-heights).
    jittered_terrains_per_family: int = 40
    root_height_jitter: float = 0.10  # m
    poses_per_terrain: int = 25  # plausible poses drawn per fitting terrain (before labelling)
    test_poses_per_terrain: int = 250  # pose draws per test terrain and per scene (before labelling)
    # The held-out families are judged on terrains of their own, many of them: on two terrains
    # the blocks held 5 unwalkable poses of 499, on 30 (seeds 200-229) 536 of 1481.
    held_out_terrains_per_family: int = 30  # seeds HELD_OUT_SEEDS..
    held_out_poses_per_terrain: int = 50
    feature_fraction: float = 0.8  # share of poses drawn over the feature's x band (+-0.5 m)
    # The model reads the footing shares at the guide's footstep places as well
    # (`learned_feasibility.footing_points`, `field.footing_rasters`): ground a sole stands on
    # within the generator's friction limit is the same rule on families the model never saw,
    # where the patch's shapes are the fitting families'. On the held-out families the model with
    # them refuses 62.4 % [58.6, 66.1] of the unwalkable poses against 33.0 % [29.5, 36.7]
    # without, at 88.7 against 89.5 % sensitivity; on 40-terrain fits, three network seeds each,
    # 41-50 % against 27-32 % (docs/results/2026-12-07-walkability-footing).
    footing: bool = True
    target_sensitivity: float = 0.95  # the threshold keeps this share of walkable poses
    nominal_root_height: float = 1.0  # m above the ground (EnvConfig.nominal_root_height)
    crack_width: float = 0.10  # m, `crack_filled_ground`
    seed: int = 0


def crack_filled_ground(field, crack_width: float) -> np.ndarray:
    """[nx, ny] bool over the field's grid: solid ground, or void narrower than `crack_width`
    (m) between solid ground on both sides (host; a binary closing by a disk, so a platform's
    edge stays an edge)."""
    from scipy import ndimage

    heights = np.asarray(field.heights)
    solid = heights > float(field.void_height) + 1e-3
    radius = int(round(0.5 * crack_width / float(field.resolution)))
    if radius < 1:
        return solid
    di, dj = np.meshgrid(np.arange(-radius, radius + 1), np.arange(-radius, radius + 1), indexing="ij")
    disk = di**2 + dj**2 <= radius**2
    padded = np.pad(solid, radius, mode="edge")  # the grid's border is no edge of the ground
    return solid | ndimage.binary_closing(padded, structure=disk)[radius:-radius, radius:-radius]


@functools.partial(jax.jit, static_argnums=(3, 4, 5))
def judge(
    field, ground_ok: jax.Array, planar: jax.Array, nominal_root_height: float, confident, plausible, model
):
    """Root z and both verdicts of planar poses [M, 3] (x, y, yaw), world.

    The root stands `nominal_root_height` above the highest solid ground within `leg_radius`
    of it (`Heightfield.leg_max`), not above the point under it: a root over a crack between
    rubble tiles stands at the tiles' height, where the generator's feet are. The ground under
    it must be solid or a crack (`ground_ok` [nx, ny] bool, `crack_filled_ground`).

    Args:
        field: the heightfield, with the rasters of `confident`.
        ground_ok: [nx, ny] bool.
        planar: [M, 3].
        nominal_root_height: m.
        confident: `ReachabilityConfig` of the confident verdict without a model (and of the
            model's margins with one).
        plausible: `ReachabilityConfig` of the plausible set (`relaxed_reachability`).
        model: `LearnedParams` of the walkability model, or None (confident: the cylinders).

    Returns:
        (z [M], confident [M] bool, plausible [M] bool); confident implies plausible with a
        model (the model only splits the plausible set).
    """
    from leas_jax.env import learned_feasibility as lf

    ground = sample_nearest(field, field.leg_max, planar[:, :2], outside=-jnp.inf)
    solid = jnp.isfinite(ground) & sample_nearest(field, ground_ok, planar[:, :2], outside=False)
    z = jnp.where(solid, ground, field.void_height) + nominal_root_height
    poses = jnp.stack([planar[:, 0], planar[:, 1], z, planar[:, 2]], axis=1)
    maybe = jax.vmap(lambda pose: reachability.valid(field, pose, plausible))(poses) & solid
    if model is None:
        sure = jax.vmap(lambda pose: reachability.valid(field, pose, confident))(poses) & solid
    else:
        sure = maybe & (
            jax.vmap(lambda pose: lf.logit(model, field, pose, confident))(poses) >= model["threshold"]
        )
    return z, sure, maybe


def judge_poses(
    field, ground_ok, planar: np.ndarray, nominal_root_height: float, confident, plausible, model, chunk: int
):
    """`judge` over planar poses [M, 3] (x, y, yaw), `chunk` poses per jitted call (one
    compiled shape). -> (root z [M] float, confident [M] bool, plausible [M] bool)."""
    out = np.zeros((3, len(planar)))
    ground_ok = jnp.asarray(ground_ok)
    for begin in range(0, len(planar), chunk):
        part = planar[begin : begin + chunk]
        if len(part) < chunk:  # pad: every call has the same shape (one compile)
            part = np.concatenate([part, np.repeat(part[-1:], chunk - len(part), axis=0)])
        n = min(chunk, len(planar) - begin)
        judged = judge(
            field,
            ground_ok,
            jnp.asarray(part, jnp.float32),
            float(nominal_root_height),
            confident,
            plausible,
            model,
        )
        out[:, begin : begin + n] = np.stack([np.asarray(a, np.float64)[:n] for a in judged])
    return out[0], out[1] > 0.5, out[2] > 0.5


def load_walkability(path, reach):
    """The walkability model's `LearnedParams` from an .npz of `leas feasibility walkability` (a path as given
    or relative to the repository).

    Warns (`walking_truth.StaleConditionWarning`) where the model records the key of another
    contact generator than the current one (`walking_truth.stale_weights`).

    Raises:
        UsageError: the file cannot be read, or its model reads the margins of another
            `ReachabilityConfig` than `reach` (the field's rasters).
    """
    import json

    from leas_jax.env.learned_weights import load_params
    from leas_jax.errors import UsageError
    from leas_jax.files import resolve_data_path

    resolved = resolve_data_path(path)
    try:
        params, metadata = load_params(resolved)
    except ValueError as error:
        raise UsageError(str(error)) from None
    warn_if_stale(resolved, metadata)
    fitted = metadata.get("reachability")
    if fitted is not None and json.loads(fitted) != dataclasses.asdict(reach):
        raise UsageError(
            f"{resolved}: the walkability model reads the margins of another ReachabilityConfig "
            f"({fitted}) than the policy's env"
        )
    return params


# ---- data ------------------------------------------------------------------------------------


def _field(terrain):
    """The heightfield of a terrain with the calibrated cylinders' rasters (the model's margins)."""
    from leas_jax.env import EnvConfig, heightfield_from_terrain

    return heightfield_from_terrain(terrain, EnvConfig(condition="cylinders"))


def plausible_poses(
    field,
    bounds,
    count: int,
    seed: int,
    config: WalkabilityConfig,
    band=FEATURE_X,
    height_jitter: float = 0.0,
):
    """Plausible root poses on a terrain, seeded: x over `band` +- 0.5 m for `feature_fraction` of
    the draws (None: all over the terrain), the rest anywhere 0.3 m inside `bounds` [[x0, y0],
    [x1, y1]]; yaw uniform; z as the lattice sets it (`judge`), moved by a uniform draw within
    +-`height_jitter` (m) where it is positive.

    Args:
        field: the terrain's heightfield with the calibrated cylinders' rasters (`_field`).
        height_jitter: m; a jittered pose is plausible where the lattice's pose at its (x, y,
            yaw) is and where the relaxed cylinders accept it at its own height. The draws of
            the lattice's poses do not depend on it (the heights are drawn after them).

    Returns:
        (poses [k <= count, 4] (x, y, z, yaw), cylinders [k] bool: the calibrated cylinders'
        verdict on each, the confident set without a model).
    """
    from leas_jax.env.config import ReachabilityConfig

    rng = np.random.default_rng(seed)
    (x0, y0), (x1, y1) = np.asarray(bounds) + np.array([[0.3, 0.3], [-0.3, -0.3]])
    near = 0 if band is None else int(round(config.feature_fraction * count))
    xs = np.concatenate(
        [
            rng.uniform(max(x0, band[0] - 0.5), min(x1, band[1] + 0.5), near) if near else np.zeros(0),
            rng.uniform(x0, x1, count - near),
        ]
    )
    planar = np.column_stack([xs, rng.uniform(y0, y1, count), rng.uniform(-np.pi, np.pi, count)])
    reach = ReachabilityConfig()
    z, cylinders, maybe = judge_poses(
        field,
        crack_filled_ground(field, config.crack_width),
        planar,
        config.nominal_root_height,
        reach,
        relaxed_reachability(reach),
        None,
        chunk=1024,
    )
    poses = np.column_stack([planar[:, :2], z, planar[:, 2]])
    if height_jitter > 0.0:
        poses[:, 2] += rng.uniform(-height_jitter, height_jitter, count)
        moved = jnp.asarray(poses, jnp.float32)
        maybe &= np.asarray(reachability.valid_poses(field, moved, relaxed_reachability(reach)))
        cylinders = maybe & np.asarray(reachability.valid_poses(field, moved, reach))
    return poses[maybe], cylinders[maybe]


_WORKER = {}


def _init_worker(terrain_text: str, generator_config) -> None:
    from leas_jax.contacts.planner.generator import ContactGenerator
    from leas_jax.terrain import loads_terrain

    _WORKER["generator"] = ContactGenerator(
        loads_terrain(terrain_text, source="<walkability>"), generator_config
    )


def _walk(poses: np.ndarray) -> np.ndarray:
    generator = _WORKER["generator"]
    return np.array([generator.plan(walking_guide(p), WALK_TIMESTEP).coverage >= 1.0 for p in poses], bool)


def walking_labels(
    terrain, poses: np.ndarray, cache: Path, workers: int, generator_config=None
) -> np.ndarray:
    """The generator's walking truth at poses [N, 4] (bool [N]); cached in `cache` under the
    data key of the terrain text, generator settings and code (resumable chunk by chunk).
    `workers` > 1: spawned processes, one ContactGenerator each."""
    from leas_jax.contacts.planner.generator import GeneratorConfig

    generator_config = GeneratorConfig() if generator_config is None else generator_config
    key = dataset_key(terrain.text, generator_config)
    path = Path(cache) / f"walkability_{key[:16]}_{len(poses)}.npz"
    chunk = 25
    if workers <= 1:
        _init_worker(terrain.text, generator_config)
        return cached_labels(poses, key, path, lambda chunks: map(_walk, chunks), chunk)
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(workers, initializer=_init_worker, initargs=(terrain.text, generator_config)) as pool:
        return cached_labels(poses, key, path, lambda chunks: pool.imap(_walk, chunks), chunk)


@dataclass
class LabelledSet:
    """Poses with their features and the generator's verdicts, from several terrains.

    Attributes:
        x: [N, F] raw features (`learned_feasibility.features`).
        y: [N] bool, walkable (walking truth).
        cylinders: [N] bool, the calibrated cylinders' verdict (the confident set without a model).
        group: [N] str, the family or scene each pose comes from.
    """

    x: np.ndarray
    y: np.ndarray
    cylinders: np.ndarray
    group: np.ndarray


def labelled_terrain(
    terrain,
    group: str,
    count: int,
    seed: int,
    config,
    cache,
    workers,
    grid_params,
    band=FEATURE_X,
    height_jitter: float = 0.0,
):
    """`LabelledSet` of `count` draws of plausible poses on one terrain (`plausible_poses`)."""
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.feasibility.fit import features_of

    field = _field(terrain)
    poses, cylinders = plausible_poses(field, terrain.bounds, count, seed, config, band, height_jitter)
    labels = walking_labels(terrain, poses, cache, workers)
    x = features_of(grid_params, field, poses, ReachabilityConfig())
    return LabelledSet(x, labels, cylinders, np.full(len(poses), group))


def labelled_scene(scene, index: int, config, cache, workers, grid_params) -> LabelledSet:
    """`LabelledSet` of the `index`-th scene of a build: `test_poses_per_terrain` draws anywhere
    on it, seeded by `scene_seed`."""
    return labelled_terrain(
        scene,
        scene.name,
        config.test_poses_per_terrain,
        scene_seed(config, index),
        config,
        cache,
        workers,
        grid_params,
        band=None,
    )


def concatenate(sets) -> LabelledSet:
    """One `LabelledSet` of several."""
    return LabelledSet(
        *(np.concatenate([getattr(s, f.name) for s in sets]) for f in dataclasses.fields(LabelledSet))
    )


def rates(predicted: np.ndarray, y: np.ndarray) -> dict:
    """Sensitivity and specificity of verdicts [N] against labels [N], with 95 % Wilson intervals."""
    from leas_jax.stats import wilson

    predicted, y = np.asarray(predicted, bool), np.asarray(y, bool)
    tp, pos = int((predicted & y).sum()), int(y.sum())
    tn, neg = int((~predicted & ~y).sum()), int((~y).sum())
    return {
        "walkable": pos,
        "not_walkable": neg,
        "sensitivity": tp / pos if pos else float("nan"),
        "sensitivity_ci": list(wilson(tp, pos)),
        "specificity": tn / neg if neg else float("nan"),
        "specificity_ci": list(wilson(tn, neg)),
    }


def family_sets(
    families, seeds, config, cache, workers, grid_params, say, count=None, height_jitter: float = 0.0
) -> list[LabelledSet]:
    """A `LabelledSet` per (family, seed) terrain, `count` pose draws each (None:
    `config.poses_per_terrain`), root heights jittered by up to `height_jitter` (m). A progress
    bar per family where stderr is a terminal, and one line per family through `say`."""
    from tqdm.auto import tqdm

    from leas_jax.terrain import loads_terrain

    out = []
    if not len(seeds):
        return out
    for family in families:
        began = time.perf_counter()
        parts = []
        for seed in tqdm(seeds, desc=f"{family}: labelling", unit="terrain", leave=False, disable=None):
            terrain = loads_terrain(family_terrain(family, seed), source=f"<family {family} {seed}>")
            parts.append(
                labelled_terrain(
                    terrain,
                    family,
                    config.poses_per_terrain if count is None else count,
                    config.seed + seed,
                    config,
                    cache,
                    workers,
                    grid_params,
                    height_jitter=height_jitter,
                )
            )
        poses, walkable = sum(len(p.y) for p in parts), sum(int(p.y.sum()) for p in parts)
        jittered = f", root heights +-{height_jitter:g} m" if height_jitter > 0.0 else ""
        say(
            f"{family}, {len(parts)} terrains (seeds {seeds[0]}-{seeds[-1]}{jittered}): {poses} plausible poses, "
            f"{walkable} walkable ({time.perf_counter() - began:.1f} s)"
        )
        out += parts
    return out


# ---- fit and report ----------------------------------------------------------------------------


def scene_seed(config: WalkabilityConfig, index: int) -> int:
    """The seed of the pose draws on a build's `index`-th scene."""
    return config.seed + SCENE_SEEDS + index


@dataclass(frozen=True)
class BuildSeeds:
    """Terrain seeds of a build: of the training families, the fit at nominal root heights and
    at jittered ones, the test at nominal and jittered heights; of the held-out families."""

    fit: range
    jittered_fit: range
    test: range
    jittered_test: range
    held_out: range


def build_seeds(config: WalkabilityConfig) -> BuildSeeds:
    """The terrain seeds of a build (`TEST_SEEDS`, `HELD_OUT_SEEDS`): no two ranges of the
    training families overlap.

    Raises:
        ValueError: the fit's terrains would reach the test's seeds, or the nominal test's the
            jittered one's.
    """
    jittered_fit = config.terrains_per_family + config.jittered_terrains_per_family
    if jittered_fit > TEST_SEEDS or config.test_terrains_per_family > JITTERED_TEST_OFFSET:
        raise ValueError(
            f"at most {TEST_SEEDS} fitting terrains per family (nominal and jittered: {jittered_fit}) "
            f"and {JITTERED_TEST_OFFSET} test terrains ({config.test_terrains_per_family}): the test "
            "terrains' seeds start there"
        )
    jittered_test = TEST_SEEDS + JITTERED_TEST_OFFSET
    return BuildSeeds(
        fit=range(config.terrains_per_family),
        jittered_fit=range(config.terrains_per_family, jittered_fit),
        test=range(TEST_SEEDS, TEST_SEEDS + config.test_terrains_per_family),
        jittered_test=range(jittered_test, jittered_test + config.test_terrains_per_family),
        held_out=range(HELD_OUT_SEEDS, HELD_OUT_SEEDS + config.held_out_terrains_per_family),
    )


def data_key(config: WalkabilityConfig, scenes=()) -> str:
    """sha256 (hex) of what a build's data depend on: every family terrain's and scene's text,
    the generator's settings and code, and the config (`walking_truth.dataset_key`)."""
    import hashlib

    from leas_jax.contacts.planner.generator import GeneratorConfig

    digest = hashlib.sha256(repr(config).encode())
    seeds = build_seeds(config)
    training = (*seeds.fit, *seeds.jittered_fit, *seeds.test, *seeds.jittered_test)
    texts = [family_terrain(f, s) for f in config.train_families for s in training]
    texts += [family_terrain(f, s) for f in config.held_out_families for s in seeds.held_out]
    texts += [scene.text for scene in scenes]
    for text in texts:
        digest.update(dataset_key(text, GeneratorConfig()).encode())
    return digest.hexdigest()


def _row(name: str, model: dict, cylinders: dict) -> str:
    def cell(r, key):
        low, high = r[f"{key}_ci"]
        return f"{100 * r[key]:.1f} [{100 * low:.1f}, {100 * high:.1f}]"

    return (
        f"| {name} | {model['walkable']} / {model['not_walkable']} | {cell(model, 'sensitivity')} | "
        f"{cell(model, 'specificity')} | {cell(cylinders, 'sensitivity')} | {cell(cylinders, 'specificity')} |"
    )


def report_table(report: dict) -> str:
    """Markdown table of a build's report: per split and group, the model's and the calibrated
    cylinders' sensitivity and specificity (%, 95 % Wilson intervals)."""
    lines = [
        "| poses | walkable / not | model sensitivity | model specificity | cylinders sensitivity | "
        "cylinders specificity |",
        "|---|---|---|---|---|---|",
    ]
    for split, groups in report["splits"].items():
        for group, r in groups.items():
            lines.append(_row(f"{split}: {group}", r["model"], r["cylinders"]))
    return "\n".join(lines) + "\n"


def _split_report(part: LabelledSet, params) -> dict:
    from leas_jax.feasibility.fit import predict

    verdicts = predict(params, part.x)
    groups = {"all": np.ones(len(part.y), bool)} | {
        g: part.group == g for g in dict.fromkeys(part.group.tolist())
    }
    return {
        name: {"model": rates(verdicts[m], part.y[m]), "cylinders": rates(part.cylinders[m], part.y[m])}
        for name, m in groups.items()
    }


def build(
    out: Path,
    config: WalkabilityConfig = WalkabilityConfig(),
    scenes=(),
    cache: Path = Path(".cache"),
    workers: int = 2,
    say=print,
) -> dict:
    """Data, fit and report of the walkability model (host).

    Labels the plausible poses of `terrains_per_family` seeds of each training family at the
    lattice's root height and `jittered_terrains_per_family` more at jittered heights (the fit),
    of `test_terrains_per_family` other seeds of each at either (the tests on unseen terrains), of
    `held_out_terrains_per_family` seeds of each held-out family (families never seen), and of
    each scene (a `Terrain` with its own bounds; poses anywhere on it); fits the network (`fit.fit`, threshold for
    `target_sensitivity`), writes the weights to `out` (.npz, with the data key and settings)
    and returns the report (also written beside them as walkability.json and walkability.md).
    """
    import json

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.feasibility.fit import FitConfig, fit
    from leas_jax.files import atomic_write_text

    began = time.perf_counter()
    reach = ReachabilityConfig()
    footing = lf.footing_points(reach) if config.footing else None
    grid_params = lf.init_params(jax.random.PRNGKey(config.seed), reach=reach, footing=footing)
    cache = Path(cache)
    cache.mkdir(parents=True, exist_ok=True)
    seeds = build_seeds(config)
    jitter = config.root_height_jitter
    train = concatenate(
        family_sets(config.train_families, seeds.fit, config, cache, workers, grid_params, say)
        + family_sets(
            config.train_families,
            seeds.jittered_fit,
            config,
            cache,
            workers,
            grid_params,
            say,
            height_jitter=jitter,
        )
    )

    def tested(terrains, height_jitter):
        return concatenate(
            family_sets(
                config.train_families,
                terrains,
                config,
                cache,
                workers,
                grid_params,
                say,
                config.test_poses_per_terrain,
                height_jitter,
            )
        )

    tests = {"unseen terrains of the training families": tested(seeds.test, 0.0)}
    if jitter > 0.0:
        name = f"unseen terrains of the training families, root heights +-{jitter:g} m"
        tests[name] = tested(seeds.jittered_test, jitter)
    held = concatenate(
        family_sets(
            config.held_out_families,
            seeds.held_out,
            config,
            cache,
            workers,
            grid_params,
            say,
            config.held_out_poses_per_terrain,
        )
    )
    scene_sets = []
    for k, scene in enumerate(scenes):
        part = labelled_scene(scene, k, config, cache, workers, grid_params)
        say(f"{scene.name}: {len(part.y)} plausible poses, {int(part.y.sum())} walkable")
        scene_sets.append(part)
    fit_config = FitConfig(target_sensitivity=config.target_sensitivity, seed=config.seed)
    params, info = fit(train.x, train.y, fit_config, reach=reach, footing=footing)
    key = data_key(config, scenes)
    lf.save_params(
        out,
        params,
        data_key=key,
        generator_key=generator_key(),
        model="walkability",
        families=json.dumps(
            {"train": list(config.train_families), "held_out": list(config.held_out_families)}
        ),
        fit=json.dumps(dataclasses.asdict(fit_config)),
        walkability=json.dumps(dataclasses.asdict(config)),
        reachability=json.dumps(dataclasses.asdict(reach)),
    )
    splits = {
        "fit": _split_report(train, params),
        **{name: _split_report(part, params) for name, part in tests.items()},
        "held-out families": _split_report(held, params),
    }
    if scene_sets:
        splits["hpp-environments scenes"] = _split_report(concatenate(scene_sets), params)
    report = {
        "weights": str(out),
        "data_key": key,
        "config": dataclasses.asdict(config),
        "fit": info,
        "seconds": round(time.perf_counter() - began, 1),
        "splits": splits,
    }
    folder = Path(out).parent
    atomic_write_text(folder / "walkability.json", json.dumps(report, indent=1, default=float) + "\n")
    atomic_write_text(folder / "walkability.md", report_table(report))
    return report
