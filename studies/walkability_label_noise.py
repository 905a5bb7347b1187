"""How repeatable is the generator's walking truth under a pose change no terrain model could see?

The walkability model (`leas feasibility walkability`) reaches 95-99 % sensitivity but 50-70 %
specificity on terrains it did not fit. Either the model misses what makes a pose unwalkable, or
the label itself changes under a move far below the terrain's resolution (the greedy contact
generator's choices branching on a centimetre). This study measures the second: on the family
terrains of the model's test split (seeds 100-101 of every family, the same plausible poses as
the build draws), it takes every pose an earlier build's cache labelled unwalkable and as many
labelled walkable, labels each again with the current generator at the pose itself and at
`--neighbours` poses moved by at most `--shift` m in x and y and `--turn` rad in yaw (z kept),
and reports how often a pose's label differs from its neighbours'.

A pose whose neighbour the generator walks from, 2 cm away, is one that a model of the terrain
around the root (an 0.08 m height patch) cannot tell from a walkable one: the share of unwalkable
poses with a walkable neighbour bounds the specificity any such model reaches at full sensitivity.

    python studies/walkability_label_noise.py [--workers 1] [--out DIR]

Writes label_noise.json and label_noise.md into --out. Labels are cached (resumable) under
--cache; an earlier build's labels are read from --old-cache (files `walkability_*.npz` whose
poses equal the drawn ones).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))

from common import load_average, provenance  # noqa: E402

TEST_SEEDS = (100, 101)  # the walkability build's test terrains (`WalkabilityConfig`)


def earlier_labels(poses: np.ndarray, cache: Path) -> np.ndarray | None:
    """bool [N]: labels of exactly these poses [N, 4] in any finished cache file of `cache`
    (whatever generator made them), or None."""
    for path in sorted(cache.glob(f"walkability_*_{len(poses)}.npz")):
        with np.load(path) as data:
            if int(data["done"]) == len(poses) and np.array_equal(data["poses"], poses):
                return np.asarray(data["labels"], bool)
    return None


def neighbours(poses: np.ndarray, count: int, shift: float, turn: float, rng) -> np.ndarray:
    """[N, count, 4]: each pose [N, 4] (x, y, z, yaw) moved by uniform draws within +-shift m in
    x and y and +-turn rad in yaw, z unchanged."""
    moved = np.repeat(poses[:, None, :], count, axis=1).copy()
    moved[..., :2] += rng.uniform(-shift, shift, (len(poses), count, 2))
    moved[..., 3] += rng.uniform(-turn, turn, (len(poses), count))
    return moved


def repeatability(exact: np.ndarray, near: np.ndarray) -> dict:
    """Counts of a label's agreement with its neighbours'.

    Args:
        exact: [N] bool, the label at each pose.
        near: [N, K] bool, the labels of its K neighbours.
    """
    from leas_jax.stats import wilson

    out = {}
    for name, mask in (("unwalkable", ~exact), ("walkable", exact)):
        n = int(mask.sum())
        differs = int((near[mask] != exact[mask, None]).any(axis=1).sum())
        flips, pairs = int((near[mask] != exact[mask, None]).sum()), int(mask.sum() * near.shape[1])
        out[name] = {
            "poses": n,
            "with_a_differing_neighbour": differs,
            "share": differs / n if n else float("nan"),
            "share_ci": list(wilson(differs, n)),
            "neighbour_flip_rate": flips / pairs if pairs else float("nan"),
            "neighbour_flip_rate_ci": list(wilson(flips, pairs)),
        }
    return out


def _percent(r: dict, key: str) -> str:
    low, high = r[f"{key}_ci"]
    return f"{100 * r[key]:.1f} [{100 * low:.1f}, {100 * high:.1f}]"


def table(rows: dict) -> str:
    lines = [
        "| terrains | unwalkable now | with a walkable neighbour % | neighbours walkable % | "
        "walkable now | with an unwalkable neighbour % | neighbours unwalkable % |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, r in rows.items():
        u, w = r["unwalkable"], r["walkable"]
        lines.append(
            f"| {name} | {u['poses']} | {_percent(u, 'share')} | {_percent(u, 'neighbour_flip_rate')} | "
            f"{w['poses']} | {_percent(w, 'share')} | {_percent(w, 'neighbour_flip_rate')} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:

    from leas_jax.feasibility import walkability as wk
    from leas_jax.files import atomic_write_text
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.families import FAMILIES, family_terrain

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--old-cache", type=Path, default=Path(".cache"))
    parser.add_argument("--cache", type=Path, default=Path(".cache/label_noise"))
    parser.add_argument("--neighbours", type=int, default=2)
    parser.add_argument("--shift", type=float, default=0.02, help="m, largest move in x and in y")
    parser.add_argument("--turn", type=float, default=0.03, help="rad, largest turn")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("docs/results/2026-12-06-walkability-label-noise"))
    args = parser.parse_args()
    load_before = load_average()
    config = wk.WalkabilityConfig(terrains_per_family=4, test_terrains_per_family=2, poses_per_terrain=250)
    args.cache.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    per_family, everything = {}, []
    for family in FAMILIES:
        parts = []
        for seed in TEST_SEEDS:
            terrain = loads_terrain(family_terrain(family, seed), source=f"<family {family} {seed}>")
            poses, _ = wk.plausible_poses(
                wk._field(terrain), terrain.bounds, config.poses_per_terrain, config.seed + seed, config
            )
            old = earlier_labels(poses, args.old_cache)
            if old is None:
                print(f"{family} {seed}: no earlier labels of these poses in {args.old_cache}; skipped")
                continue
            walkable = np.flatnonzero(old)
            chosen = np.concatenate(
                [
                    np.flatnonzero(~old),
                    rng.choice(walkable, min(len(walkable), int((~old).sum())), replace=False),
                ]
            )
            if len(chosen) == 0:
                continue
            moved = neighbours(poses[chosen], args.neighbours, args.shift, args.turn, rng)
            batch = np.concatenate([poses[chosen], moved.reshape(-1, 4)])
            labels = wk.walking_labels(terrain, batch, args.cache, args.workers)
            exact, near = labels[: len(chosen)], labels[len(chosen) :].reshape(len(chosen), -1)
            parts.append((old[chosen], exact, near))
            print(
                f"{family} {seed}: {len(chosen)} poses ({int((~old[chosen]).sum())} unwalkable before), "
                f"now {int((~exact).sum())} unwalkable; {int((near != exact[:, None]).any(axis=1).sum())} "
                "with a differing neighbour",
                flush=True,
            )
        if parts:
            per_family[family] = [np.concatenate(p) for p in zip(*parts, strict=True)]
            everything.append(per_family[family])
    rows = {"all": repeatability(*[np.concatenate(p) for p in zip(*everything, strict=True)][1:])}
    rows |= {family: repeatability(exact, near) for family, (_, exact, near) in per_family.items()}
    old_all, exact_all = (np.concatenate([p[k] for p in everything]) for k in (0, 1))
    changed = {
        "unwalkable_before_walkable_now": int((~old_all & exact_all).sum()),
        "unwalkable_before": int((~old_all).sum()),
        "walkable_before_unwalkable_now": int((old_all & ~exact_all).sum()),
        "walkable_before": int(old_all.sum()),
    }
    settings = {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()}
    record = {**provenance(load_before), "settings": settings, "generator_change": changed, "rows": rows}
    args.out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(args.out / "label_noise.json", json.dumps(record, indent=1) + "\n")
    text = (
        f"Neighbours: {args.neighbours} per pose, within +-{args.shift} m in x and y and "
        f"+-{args.turn} rad in yaw. Against the earlier labels: {changed['unwalkable_before_walkable_now']} "
        f"of {changed['unwalkable_before']} unwalkable poses are walkable now, "
        f"{changed['walkable_before_unwalkable_now']} of {changed['walkable_before']} walkable ones are not.\n\n"
        + table(rows)
    )
    atomic_write_text(args.out / "label_noise.md", text)
    print(text)


if __name__ == "__main__":
    main()
