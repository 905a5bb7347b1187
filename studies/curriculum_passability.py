"""How hard may a curriculum tile be before the training termination ends every straight walk across it?

A curriculum policy learns to stop before features that end its episodes. Where a tile of the
curriculum cannot be crossed without a pose that the env's condition rejects, no policy can
cross it, and an env promoted to that row learns to stop there. This sweep measures, per
family and difficulty, the share of straight walks across the feature that pass the condition of
an `EnvConfig` (default: the `generalist` preset's, the walkability model at its threshold and
the plausible cylinders):

  - one curriculum arena of `--levels` rows over the crossing families (each at its whole
    range, difficulty k / (levels - 1)), for each of `--seeds` arena seeds;
  - per tile, `--lines` straight walks along +x from 0.5 to 5.5 m into the tile (flat ground
    before and after every feature), 0.018 m apart (0.1 s at 0.18 m/s), heading +x, at lateral
    offsets evenly spread over +-0.9 m of the tile's centre line (+-0.02 m on the narrow and beams
    families, whose beam or stairs lie on that line); the root at the nominal height over the mean of
    the solid terrain within 0.1 m (the void of a crack or a gap does not pull it down);
  - a walk passes when every pose of it passes the condition.

Its ceiling for a family is the highest difficulty up to which at least `--pass-share` of the
walks pass at every difficulty.

    python studies/curriculum_passability.py --out OUT

writes `passability.json` and `passability.md` into `--out`.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from generalist import machine  # noqa: E402 (the curriculum study's)

CROSSING = (
    "slopes",
    "rubble",
    "blocks",
    "stairs",
    "narrow",
    "stones",
    "gaps",
    "beams",
)  # append only: a column seeds its tiles
STEP = 0.018  # m between poses of a walk (0.1 s at the target speed)
SPREAD = {"narrow": 0.02, "beams": 0.02}  # m, half-spread of the walks' lateral offsets; others HALF_SPREAD
HALF_SPREAD = 0.9
SOLID_BELOW = -1.0  # m: heights below this are the void (the arena's void lies at -2 m)


def walk_poses(field, xs: np.ndarray, y: float, nominal_root_height: float):
    """[N, 4] poses of a straight walk along +x at `y` (yaw 0), the root `nominal_root_height`
    over the mean solid height within 0.1 m."""
    import jax
    import jax.numpy as jnp

    from leas_jax.env.field import sample_bilinear

    xy = jnp.asarray(np.column_stack([xs, np.full_like(xs, y)]), jnp.float32)
    offsets = jnp.asarray(
        [[dx, dy] for dx in (-0.1, -0.05, 0, 0.05, 0.1) for dy in (-0.1, -0.05, 0, 0.05, 0.1)]
    )
    heights = jax.vmap(lambda o: sample_bilinear(field, xy + o))(offsets)  # [25, N]
    solid = heights > SOLID_BELOW
    ground = jnp.sum(jnp.where(solid, heights, 0.0), 0) / jnp.maximum(solid.sum(0), 1)
    return jnp.concatenate([xy, (ground + nominal_root_height)[:, None], jnp.zeros((len(xs), 1))], axis=1)


def passability(config, levels: int, seed: int, lines: int) -> dict:
    """{family: [share of walks passing, per row]} on one arena seed."""
    import jax

    from leas_jax.env import condition
    from leas_jax.env.field import heightfield_from_terrain
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.curriculum import curriculum_terrain

    terrain = loads_terrain(curriculum_terrain(seed, levels=levels, families=CROSSING, ceilings={}))
    field = heightfield_from_terrain(terrain, config)
    length, width = terrain.curriculum.tile
    judge = jax.jit(lambda f, poses: jax.vmap(lambda pose: condition.valid(f, pose, config))(poses).all())
    shares = {}
    for column, family in enumerate(CROSSING):
        spread = SPREAD.get(family, HALF_SPREAD)
        offsets = np.linspace(-spread, spread, lines)
        row_shares = []
        for level in range(levels):
            xs = level * length + np.arange(0.5, 5.5, STEP)
            passed = [
                bool(
                    judge(
                        field, walk_poses(field, xs, (column + 0.5) * width + dy, config.nominal_root_height)
                    )
                )
                for dy in offsets
            ]
            row_shares.append(float(np.mean(passed)))
        shares[family] = row_shares
    return shares


def ceiling(difficulties: list[float], shares: list[float], pass_share: float) -> float:
    """The highest difficulty up to which every share is at least `pass_share` (0.0 when the
    easiest fails)."""
    top = 0.0
    for difficulty, share in zip(difficulties, shares):
        if share < pass_share:
            break
        top = difficulty
    return top


def markdown(results: dict) -> str:
    difficulties = results["difficulties"]
    lines = [
        "# Straight walks across curriculum tiles that the condition lets through",
        "",
        f"Condition: {results['condition']}; {results['lines']} walks per tile, arena seeds "
        f"{results['seeds']}; cell: share of walks passing, %. Ceiling: the highest difficulty up to "
        f"which at least {100 * results['pass_share']:.0f} % pass.",
        "",
        "| family | " + " | ".join(f"{d:.2f}" for d in difficulties) + " | ceiling |",
        "|---|" + "---|" * (len(difficulties) + 1),
    ]
    for family, shares in results["shares"].items():
        cells = " | ".join(f"{100 * s:.0f}" for s in shares)
        lines.append(f"| {family} | {cells} | {results['ceilings'][family]:.2f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--preset", default="generalist", help="the training preset whose env condition judges"
    )
    parser.add_argument("--levels", type=int, default=11, help="difficulties 0, 1 / (levels - 1), ..., 1")
    parser.add_argument("--seeds", default="0,1")
    parser.add_argument("--lines", type=int, default=10, help="walks per tile")
    parser.add_argument("--pass-share", type=float, default=0.5)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()

    from leas_jax.training.config import preset

    config = preset(args.preset).env
    seeds = [int(s) for s in args.seeds.split(",")]
    per_seed = [passability(config, args.levels, seed, args.lines) for seed in seeds]
    shares = {f: np.mean([s[f] for s in per_seed], axis=0).tolist() for f in CROSSING}
    difficulties = [k / (args.levels - 1) for k in range(args.levels)]
    results = {
        "condition": f"`{args.preset}` preset: {config.condition}, threshold {config.condition_threshold}, "
        f"weights {config.learned_weights}",
        "lines": args.lines,
        "seeds": seeds,
        "pass_share": args.pass_share,
        "difficulties": difficulties,
        "shares": shares,
        "ceilings": {f: ceiling(difficulties, shares[f], args.pass_share) for f in CROSSING},
        "machine": machine(),
    }
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    store = out / "passability.json"
    tmp = store.with_suffix(".tmp")
    tmp.write_text(json.dumps(results, indent=1) + "\n")
    tmp.replace(store)
    (out / "passability.md").write_text(markdown(results))
    print(markdown(results))


if __name__ == "__main__":
    main()
