"""Does the plane a sole would stand on tell the walkability model which unseen rough ground it walks?

The walkability model (`leas feasibility walkability`) reads a root-frame height patch, the
height above the local ground and the calibrated cylinders' margins. On the held-out families
(DARPA-style blocks, stepping stones) it keeps 89 % of the walkable poses and refuses only 31 %
of the unwalkable ones (docs/results/2026-12-07-walkability-many-terrains). The contact generator places a sole on one planar face within the
friction cone: what it needs is a sole-sized plane near each footstep, not flat ground. This
study gives the model that explicitly. At each footstep place of the walking truth's guide
(root-frame x in `STEPS_X`, y = +-leg_lateral_offset) and at candidate sole centres within
`SEARCH` of it, a least-squares plane is fitted to the heights under the 0.20 x 0.13 m sole
rectangle (turned with the yaw); per place it keeps the best candidate's largest residual
(how far the ground under the sole is from a plane: an edge, a crack, a block's end), its
tilt and its height relative to the root. Variants, fitted on the same poses and labels as the
build's nominal fit (its label cache):

  - `shipped`: the shipped features;
  - `planes`: the shipped features and the sole planes;
  - `margins_planes`: the sole planes, the height above the ground and the margins, no patch.

For each, sensitivity / specificity at the fitted threshold on the fit, on unseen terrains of
the training families, on the held-out families (30 terrains x 50 draws each) and on the hpp
scenes, with 95 % Wilson intervals, over `--fit-seeds` network seeds.

    python studies/walkability_sole_planes.py --out DIR [--fit-seeds 2]

Results: docs/results/2026-12-07-walkability-root-heights (no gain on the held-out families).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))

from common import load_average, provenance  # noqa: E402

STEPS_X = (0.0, 0.12, 0.24, 0.36)  # m, root frame: the guide's footstep places
SOLE = (0.20, 0.13)  # m, Talos's sole rectangle (docs/design.md)
SOLE_POINTS = (6, 4)  # height samples along and across the sole
SEARCH = 0.10  # m, candidate sole centres within this of each place (the cylinders' foothold_search)
SEARCH_STEP = 0.04  # m
RESIDUAL_CLIP = 0.3  # m
VARIANTS = ("shipped", "planes", "margins_planes")


def sole_offsets() -> np.ndarray:
    """[S, 2] sample points of the sole rectangle about its centre, sole frame (m)."""
    gx = np.linspace(-SOLE[0] / 2, SOLE[0] / 2, SOLE_POINTS[0])
    gy = np.linspace(-SOLE[1] / 2, SOLE[1] / 2, SOLE_POINTS[1])
    px, py = np.meshgrid(gx, gy, indexing="ij")
    return np.stack([px.ravel(), py.ravel()], axis=-1)


def candidate_centres(lateral: float) -> np.ndarray:
    """[K, C, 2] root-frame candidate sole centres: K = 2 x len(STEPS_X) places (left then right
    at each x), C candidates within SEARCH of each."""
    g = np.arange(-SEARCH, SEARCH + 1e-9, SEARCH_STEP)
    d = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
    d = d[np.linalg.norm(d, axis=1) <= SEARCH + 1e-9]
    places = np.array([(x, s * lateral) for x in STEPS_X for s in (1.0, -1.0)])
    return places[:, None, :] + d[None]


def plane_features_fn(lateral: float):
    """A jitted, vmapped function (field, poses [N, 4]) -> [N, 3 K]: per place (left, right at
    each STEPS_X), the best candidate's residual (m), tilt (rad) and plane height at the sole
    centre minus the root's z (m)."""
    import jax
    import jax.numpy as jnp

    from leas_jax.env.field import sample_nearest_xy
    from leas_jax.env.kinematics import world_xy

    sole = sole_offsets()
    design = np.column_stack([np.ones(len(sole)), sole])  # [S, 3]: plane h = a + b x + c y
    solve = jnp.asarray(np.linalg.pinv(design))  # [3, S]
    design = jnp.asarray(design)
    centres = candidate_centres(lateral)  # [K, C, 2]
    points = jnp.asarray(centres[:, :, None, :] + sole[None, None], jnp.float32)  # [K, C, S, 2]
    k, c, s = points.shape[:3]

    def one(field, pose):
        x, y = world_xy(pose, points.reshape(-1, 2))
        h = sample_nearest_xy(field, field.heights, x, y).reshape(k, c, s) - pose[2]
        coef = h @ solve.T  # [K, C, 3]
        residual = jnp.clip(jnp.max(jnp.abs(h - coef @ design.T), axis=-1), 0.0, RESIDUAL_CLIP)
        tilt = jnp.arctan(jnp.hypot(coef[..., 1], coef[..., 2]))
        best = jnp.argmin(residual + 0.05 * tilt, axis=1)  # [K]: flattest, then least tilted
        pick = lambda a: jnp.take_along_axis(a, best[:, None], axis=1)[:, 0]  # noqa: E731
        return jnp.stack(
            [pick(residual), pick(tilt), jnp.clip(pick(coef[..., 0]), -1.6, 0.4)], axis=1
        ).ravel()

    return jax.jit(jax.vmap(one, in_axes=(None, 0)))


def mirror_planes(extra: np.ndarray) -> np.ndarray:
    """Plane features [N, 3 K] of the mirrored poses: left and right places swapped."""
    n = extra.shape[1] // 3
    order = np.arange(n) ^ 1
    return extra.reshape(len(extra), n, 3)[:, order].reshape(len(extra), -1)


@dataclasses.dataclass
class Part:
    x: np.ndarray
    planes: np.ndarray
    y: np.ndarray
    group: np.ndarray


def labelled(terrain, group, count, seed, config, cache, workers, grid, planes_of, band):
    """`Part` of one terrain: the build's poses (same draws; `band` as `plausible_poses` takes
    it), cached labels, both feature sets."""
    import jax.numpy as jnp

    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.feasibility import walkability as wk
    from leas_jax.feasibility.fit import features_of

    field = wk._field(terrain)
    poses, _ = wk.plausible_poses(field, terrain.bounds, count, seed, config, band)
    labels = wk.walking_labels(terrain, poses, cache, workers)
    x = features_of(grid, field, poses, ReachabilityConfig())
    planes = np.asarray(planes_of(field, jnp.asarray(poses, jnp.float32)))
    return Part(x, planes, labels, np.full(len(poses), group))


def join(parts) -> Part:
    return Part(*(np.concatenate([getattr(p, f.name) for p in parts]) for f in dataclasses.fields(Part)))


def inputs(part: Part, variant: str, patch: int) -> np.ndarray:
    if variant == "shipped":
        return part.x
    if variant == "planes":
        return np.concatenate([part.x, part.planes], axis=1)
    return np.concatenate([part.x[:, patch:], part.planes], axis=1)


def mirrored_inputs(part: Part, variant: str, grid, patch: int) -> np.ndarray:
    from leas_jax.feasibility.fit import mirrored

    mx = Part(mirrored(part.x, grid), mirror_planes(part.planes), part.y, part.group)
    return inputs(mx, variant, patch)


def fit_variant(train: Part, variant: str, grid, patch: int, seed: int):
    """(params, logit function) of the variant fitted as `fit.fit` fits the shipped model: the
    same steps, decay, rate, mirror images, class balance and threshold rule."""
    import jax
    import jax.numpy as jnp

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.feasibility.fit import FitConfig, _train, balanced_weights, threshold_for

    config = FitConfig(seed=seed)
    rng = np.random.default_rng(seed)
    order = rng.permutation(len(train.y))
    n_aside = int(round(config.aside_fraction * len(train.y)))
    aside, kept = order[:n_aside], order[n_aside:]
    sub = lambda idx: Part(train.x[idx], train.planes[idx], train.y[idx], train.group[idx])  # noqa: E731
    fit_part = sub(kept)
    xt = np.concatenate([inputs(fit_part, variant, patch), mirrored_inputs(fit_part, variant, grid, patch)])
    yt = np.concatenate([fit_part.y, fit_part.y])
    sizes = (xt.shape[1], *config.hidden, 1)
    params = {"mean": jnp.asarray(xt.mean(0)), "std": jnp.asarray(np.maximum(xt.std(0), 1e-3))}
    for layer, (key, (n_in, n_out)) in enumerate(
        zip(jax.random.split(jax.random.PRNGKey(seed), 3), zip(sizes[:-1], sizes[1:]), strict=True)
    ):
        limit = np.sqrt(6.0 / (n_in + n_out))
        params[f"w{layer}"] = jax.random.uniform(key, (n_in, n_out), minval=-limit, maxval=limit)
        params[f"b{layer}"] = jnp.zeros(n_out)
    params, _ = _train(
        params,
        jnp.asarray(xt, jnp.float32),
        jnp.asarray(yt, jnp.float32),
        jnp.asarray(balanced_weights(yt)),
        steps=config.steps,
        learning_rate=config.learning_rate,
        weight_decay=config.weight_decay,
    )
    logits = lambda x: np.asarray(lf.logit_of_features(params, jnp.asarray(x, jnp.float32)))  # noqa: E731
    aside_part = sub(aside)
    threshold = threshold_for(
        logits(inputs(aside_part, variant, patch)), aside_part.y, config.target_sensitivity
    )
    return logits, threshold


def main() -> None:
    import jax

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.feasibility import walkability as wk
    from leas_jax.feasibility.commands import _scenes
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.families import FEATURE_X, family_terrain

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True)
    parser.add_argument(
        "--scenes", nargs="*", default=["terrains/hpp/rough/*.toml", "terrains/hpp/rubble.toml"]
    )
    parser.add_argument("--fit-seeds", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cache", default=".cache")
    args = parser.parse_args()
    load_before = load_average()
    began = time.perf_counter()
    config = wk.WalkabilityConfig()
    reach = ReachabilityConfig()
    grid_params = lf.init_params(jax.random.PRNGKey(config.seed), reach=reach)
    grid = np.asarray(grid_params["grid"])
    patch = len(grid)
    planes_of = plane_features_fn(reach.leg_lateral_offset)
    cache = Path(args.cache)
    seeds = wk.build_seeds(config)  # the nominal fit and test of the build, its held-out terrains

    def family_part(families, seeds, count):
        parts = []
        for family in families:
            for seed in seeds:
                terrain = loads_terrain(family_terrain(family, seed), source=f"<family {family} {seed}>")
                parts.append(
                    labelled(
                        terrain,
                        family,
                        count,
                        config.seed + seed,
                        config,
                        cache,
                        args.workers,
                        grid_params,
                        planes_of,
                        band=FEATURE_X,
                    )
                )
            print(f"{family}: seeds {seeds[0]}-{seeds[-1]} ({time.perf_counter() - began:.0f} s)", flush=True)
        return join(parts)

    splits = {
        "fit": family_part(config.train_families, seeds.fit, config.poses_per_terrain),
        "unseen terrains of the training families": family_part(
            config.train_families, seeds.test, config.test_poses_per_terrain
        ),
        "held-out families": family_part(
            config.held_out_families, seeds.held_out, config.held_out_poses_per_terrain
        ),
    }
    splits["hpp-environments scenes"] = join(
        [
            labelled(
                scene,
                scene.name,
                config.test_poses_per_terrain,
                wk.scene_seed(config, k),
                config,
                cache,
                args.workers,
                grid_params,
                planes_of,
                band=None,
            )
            for k, scene in enumerate(_scenes(args.scenes))
        ]
    )
    results = {}
    for variant in VARIANTS:
        for seed in range(args.fit_seeds):
            logits, threshold = fit_variant(splits["fit"], variant, grid, patch, seed)
            for name, part in splits.items():
                verdict = logits(inputs(part, variant, patch)) >= threshold
                groups = {"all": np.ones(len(part.y), bool)} | {
                    g: part.group == g for g in dict.fromkeys(part.group.tolist())
                }
                for g, m in groups.items():
                    results.setdefault(f"{name}: {g}", {}).setdefault(variant, []).append(
                        wk.rates(verdict[m], part.y[m])
                    )
            print(f"{variant} seed {seed} ({time.perf_counter() - began:.0f} s)", flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    lines = [
        "Sensitivity / specificity %, mean over the fit seeds, [95 % Wilson interval of that specificity on this set's count].\n",
        "| poses | walkable / not | " + " | ".join(VARIANTS) + " |",
        "|---|---|" + "---|" * len(VARIANTS) + "",
    ]
    from leas_jax.stats import wilson

    for row, by_variant in results.items():
        first = by_variant[VARIANTS[0]][0]
        cells = []
        for variant in VARIANTS:
            rs = by_variant[variant]
            neg = rs[0]["not_walkable"]
            sens = np.mean([r["sensitivity"] for r in rs])
            spec = np.mean([r["specificity"] for r in rs])
            lo, hi = wilson(round(spec * neg), neg) if neg else (float("nan"), float("nan"))
            cells.append(f"{100 * sens:.1f} / {100 * spec:.1f} [{100 * lo:.1f}, {100 * hi:.1f}]")
        lines.append(f"| {row} | {first['walkable']} / {first['not_walkable']} | " + " | ".join(cells) + " |")
    table = "\n".join(lines) + "\n"
    print(table)
    (out / "sole_planes.md").write_text(table)
    (out / "sole_planes.json").write_text(
        json.dumps(
            {
                "provenance": provenance(load_before),
                "seconds": round(time.perf_counter() - began, 1),
                "results": results,
            },
            indent=1,
            default=float,
        )
        + "\n"
    )


if __name__ == "__main__":
    main()
