"""Which tiles of a curriculum arena does a policy cross? Where the curriculum holds it.

A curriculum policy's envs climb to a mean row and stay there (`metrics.jsonl`'s
`curriculum_level`); which families' tiles stop them is not in the training metrics. Here each
tile (row r, family column c) of a curriculum arena is crossed by the deterministic policy from
`--starts` seeded starts on its flat ground before the feature (x = 0.5 m into the tile, y within
0.9 m of the tile's centre line, heading +x +- 17 deg), walking to the point 5.0 m further along x
(the flat ground after every family's feature), under the policy's own termination, for up to
`--steps` steps. Per tile: the share of starts that reach the point (Wilson 95 %), end on an
invalid pose, or stop short (the horizon ran out), and the mean share of the 5.0 m walked.

    python studies/curriculum_tiles.py --policy generalist=checkpoints/leas_generalist \\
        --policy paper_arena=checkpoints/leas_talos/pretrain --out OUT

writes `curriculum_tiles.json`, `.md` and `.png` (one heat map per policy) into `--out`.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from leas_jax.stats import wilson

sys.path.insert(0, str(Path(__file__).resolve().parent))
from generalist import machine  # noqa: E402 (the curriculum study's)

ROOT = Path(__file__).resolve().parents[1]
START_X = 0.5  # m into the tile: flat ground for every family (features begin at 2.0 m)
WALK = 5.0  # m along x to the target (5.5 m into the tile): past every feature (stairs end by 5.05 m)
HALF_SPREAD_Y = 0.9  # m, starts within this of the tile's centre line
YAW_SPREAD = 0.3  # rad, starts heading +x within this


def tile_starts(row: int, column: int, tile: tuple[float, float], origin, n: int, seed: int) -> np.ndarray:
    """[n, 3] (x, y, yaw) starts on tile (row, column), seeded per tile."""
    rng = np.random.default_rng([seed, row, column])
    x = origin[0] + row * tile[0] + START_X
    y = origin[1] + (column + 0.5) * tile[1] + rng.uniform(-HALF_SPREAD_Y, HALF_SPREAD_Y, n)
    yaw = rng.uniform(-YAW_SPREAD, YAW_SPREAD, n)
    return np.column_stack([np.full(n, x), y, yaw])


def cross_tiles(policy, terrain, starts_per_tile: int, seed: int, steps: int) -> dict:
    """Per-tile crossings of `policy` on a curriculum `terrain`: {family: [row dicts]}."""
    from leas_jax.env.field import heightfield_from_terrain
    from leas_jax.steering.leas import rollout_batch, start_poses

    layout = terrain.curriculum
    field = heightfield_from_terrain(terrain, policy.config.env)
    origin = terrain.bounds[0]
    starts = np.concatenate(
        [
            tile_starts(r, c, layout.tile, origin, starts_per_tile, seed)
            for r in range(layout.levels)
            for c in range(len(layout.families))
        ]
    )
    poses = start_poses(field, starts, policy.config.env.nominal_root_height)
    targets = starts[:, :2] + np.array([WALK, 0.0])
    result = rollout_batch(policy, field, poses, targets, max_steps=steps, stop_at_target=True)
    last = result.poses[np.arange(len(starts)), result.lengths - 1, 0]
    walked = np.clip((last - starts[:, 0]) / WALK, 0.0, 1.0)
    table = {family: [] for family in layout.families}
    k = 0
    for row in range(layout.levels):
        for family in layout.families:
            part = slice(k, k + starts_per_tile)
            reached, invalid = int(result.reached[part].sum()), int(result.invalid[part].sum())
            table[family].append(
                {
                    "row": row,
                    "n": starts_per_tile,
                    "reached": reached,
                    "invalid": invalid,
                    "short": starts_per_tile - reached - invalid,
                    "walked": float(walked[part].mean()),
                }
            )
            k += starts_per_tile
    return table


def markdown(results: dict) -> str:
    lines = [
        "# Curriculum tiles crossed",
        "",
        f"Terrain `{results['terrain']}`; {results['starts']} starts per tile, seed {results['seed']}, "
        f"at most {results['steps']} steps; cell: reached % [95 % CI] (ended invalid %).",
        "",
    ]
    for label, table in results["policies"].items():
        rows = len(next(iter(table.values())))
        lines += [f"## {label} (`{results['runs'][label]}`)", ""]
        lines.append("| family | " + " | ".join(f"row {r}" for r in range(rows)) + " |")
        lines.append("|---|" + "---|" * rows)
        for family, cells in table.items():
            text = []
            for cell in cells:
                low, high = wilson(cell["reached"], cell["n"])
                text.append(
                    f"{100 * cell['reached'] / cell['n']:.0f} [{100 * low:.0f}, {100 * high:.0f}] "
                    f"({100 * cell['invalid'] / cell['n']:.0f})"
                )
            lines.append(f"| {family} | " + " | ".join(text) + " |")
        lines.append("")
    return "\n".join(lines) + "\n"


def plot(results: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = list(results["policies"])
    fig, axes = plt.subplots(
        1, len(labels), figsize=(5.0 * len(labels) + 1.0, 4.2), squeeze=False, layout="constrained"
    )
    for ax, label in zip(axes[0], labels):
        table = results["policies"][label]
        families = list(table)
        grid = np.array([[c["reached"] / c["n"] for c in table[f]] for f in families])
        image = ax.imshow(grid, vmin=0.0, vmax=1.0, cmap="viridis", aspect="auto")
        ax.set_yticks(range(len(families)), families)
        ax.set_xticks(range(grid.shape[1]))
        ax.set_xlabel("row (difficulty)")
        ax.set_title(label)
        for (i, j), value in np.ndenumerate(grid):
            ax.text(j, i, f"{100 * value:.0f}", ha="center", va="center", fontsize=7, color="w")
    fig.colorbar(image, ax=axes[0].tolist(), label="tile crossed")
    fig.savefig(path, dpi=70)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--policy", action="append", required=True, metavar="LABEL=RUN_DIR")
    parser.add_argument("--terrain", default="terrains/curriculum_arena.toml")
    parser.add_argument("--starts", type=int, default=32, help="starts per tile")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--steps", type=int, default=400)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()

    from leas_jax.terrain import load_terrain
    from leas_jax.training.policy import load_policy

    terrain = load_terrain(ROOT / args.terrain if not Path(args.terrain).is_absolute() else args.terrain)
    if terrain.curriculum is None:
        parser.error(f"--terrain {args.terrain}: not a curriculum arena (no [curriculum] table)")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results = {
        "terrain": args.terrain,
        "starts": args.starts,
        "seed": args.seed,
        "steps": args.steps,
        "runs": {},
        "policies": {},
    }
    for item in args.policy:
        label, _, run_dir = item.partition("=")
        results["runs"][label] = run_dir
        results["policies"][label] = cross_tiles(
            load_policy(run_dir), terrain, args.starts, args.seed, args.steps
        )
        print(f"{label}: done", flush=True)
    results["machine"] = machine()
    store = out / "curriculum_tiles.json"
    tmp = store.with_suffix(".tmp")
    tmp.write_text(json.dumps(results, separators=(",", ":")) + "\n")  # compact: one cell per tile and policy
    tmp.replace(store)
    (out / "curriculum_tiles.md").write_text(markdown(results))
    plot(results, out / "curriculum_tiles.png")
    print(markdown(results))


if __name__ == "__main__":
    main()
