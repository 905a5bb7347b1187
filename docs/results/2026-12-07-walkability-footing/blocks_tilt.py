"""Per held-out blocks terrain (seeds 200-229, the build's draws): its blocks' tilt and height, its
plausible poses, how many the generator does not walk, and how many of those the shipped model
accepts. Labels from the build's cache (`.cache`; a missing one is computed, 2 workers).

    python docs/results/2026-12-07-walkability-footing/blocks_tilt.py > docs/results/2026-12-07-walkability-footing/blocks_tilt.md
"""

import math
import re
from pathlib import Path

import jax


def main() -> None:
    from leas_jax.env import learned_feasibility as lf
    from leas_jax.feasibility import walkability as wk
    from leas_jax.feasibility.fit import predict
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.families import family_boxes, family_terrain

    config = wk.WalkabilityConfig()
    shipped, _ = lf.load_params(wk.WEIGHTS)
    template = lf.init_params(jax.random.PRNGKey(config.seed))
    print(
        "| seed | tilt deg | height m | plausible poses | not walkable | of those, accepted by the shipped model |"
    )
    print("|---|---|---|---|---|---|")
    rows = []
    for seed in range(wk.HELD_OUT_SEEDS, wk.HELD_OUT_SEEDS + config.held_out_terrains_per_family):
        block = family_boxes("blocks", seed)[2]  # after the two ground slabs
        size = [float(v) for v in re.search(r"size = \[(.*)\]", block).group(1).split(",")]
        pitch = [float(v) for v in re.search(r"rpy = \[(.*)\]", block).group(1).split(",")][1]
        terrain = loads_terrain(family_terrain("blocks", seed), source=f"<family blocks {seed}>")
        part = wk.labelled_terrain(
            terrain,
            "blocks",
            config.held_out_poses_per_terrain,
            config.seed + seed,
            config,
            Path(".cache"),
            2,
            template,
        )
        accepted = predict(shipped, part.x)
        rows.append(
            (
                abs(math.degrees(pitch)),
                seed,
                size[2],
                len(part.y),
                int((~part.y).sum()),
                int((accepted & ~part.y).sum()),
            )
        )
    for tilt, seed, height, n, bad, wrong in sorted(rows):
        print(f"| {seed} | {tilt:.2f} | {height:.2f} | {n} | {bad} ({100 * bad / n:.0f} %) | {wrong} |")


if __name__ == "__main__":
    main()
