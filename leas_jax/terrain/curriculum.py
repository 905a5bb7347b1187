"""Curriculum arenas: procedural terrain tiles in rows of difficulty and columns of families. Host-only.

legged_gym and Isaac Lab train locomotion policies on a grid of procedural tiles whose rows
grow harder; each env moves to a harder row when it walks far on its tile and to an easier one
when it fails early (`leas_jax.env.env.LeasEnv.next_root`). Here a tile is one 6 x 3 m terrain
of a family of `leas_jax.terrain.families` (flat ground, then the family's feature across the
tile, then flat ground) at the difficulty of its row; rows run along x, columns (one per
family) along y. The arena is a terrain file like any other (boxes over the void) with a
`[curriculum]` table that tells the env its rows.

    text = curriculum_terrain(seed=0)        # TOML text; `leas terrain curriculum --seed 0 --out F`
"""

from __future__ import annotations

import tomllib

from leas_jax.terrain.families import ALL_FAMILIES, SIZE, family_boxes

# The default columns: every family of the walkability model and the curriculum's own, in the
# order legged_gym's proportions list theirs (easy to hard, roughly).
CURRICULUM_FAMILIES = (
    "flat",
    "slopes",
    "rubble",
    "blocks",
    "stairs",
    "narrow",
    "stones",
    "gaps",
    "clutter",
    "holes",
)
CURRICULUM_LEVELS = 8  # rows: 8 x 6 m along x; a 400-step episode at 0.18 m/s walks 7.2 m
# The top row's difficulty of each family that the `generalist` preset's termination (the
# walkability model at logit -7 and the plausible cylinders) lets a straight walk cross: the highest
# difficulty up to which at least half the straight walks across the feature pass it
# (studies/curriculum_passability.py, 4 arena seeds, 10 walks per tile, difficulty steps of 0.1;
# docs/results/2026-12-07-curriculum-tiles). Past it an env promoted to the row meets a tile no
# policy crosses without ending its episode, and the policy learns to stop before the family's
# features: on the whole ranges a curriculum policy crossed no stairs tile above 0.07 m risers and
# no rubble tile but the level one, and climbed no HPP stairs; on these, three seeds climb the
# evaluation and HPP stairs from 120 of 120 starts and cross the HPP rubble from 20 of 30 (same
# folder). Stairs top at 0.11 m risers, slopes at 16 deg, blocks at 0.15 m and 10 deg, beams at
# 0.80 m wide (so no 0.30 m bridge is met: the bridges are lost); gaps and stepping stones at 0
# (hairline cracks): a gap wider than the leg disks' 0.10 m puts both under the root over the
# void at some pose of any walk, and rubble at 0 (level tiles), past which the model refuses most
# walks.
# Families not named keep their whole range (flat, clutter and holes are walked round, not across).
CURRICULUM_CEILINGS = {
    "slopes": 0.4,
    "rubble": 0.0,
    "blocks": 0.4,
    "stairs": 0.3,
    "narrow": 0.4,
    "stones": 0.0,
    "gaps": 0.0,
}


def _shifted(box: dict, dx: float, dy: float) -> str:
    """A `[[box]]` table moved by (dx, dy)."""
    center = box["center"]
    rpy = box.get("rpy", [0.0, 0.0, 0.0])

    def row(values):
        return ", ".join(f"{v:.4f}" for v in values)

    return (
        f"[[box]]\ncenter = [{row((center[0] + dx, center[1] + dy, center[2]))}]\n"
        f"size = [{row(box['size'])}]\nrpy = [{row(rpy)}]\n"
    )


def tile_difficulty(level: int, levels: int) -> float:
    """Difficulty in [0, 1] of row `level` of `levels` (0 easiest)."""
    return 0.0 if levels == 1 else level / (levels - 1)


def curriculum_terrain(
    seed: int = 0,
    levels: int = CURRICULUM_LEVELS,
    families=CURRICULUM_FAMILIES,
    resolution: float = 0.02,
    ceilings: dict = CURRICULUM_CEILINGS,
) -> str:
    """TOML text of a curriculum arena drawn from `seed` (deterministic).

    Args:
        seed: the arena's seed; each tile draws from (seed, row, column) and its family.
        levels: rows of difficulty along x (row k at difficulty k / (levels - 1) of its family's
            ceiling).
        families: the family of each column along y (`families.ALL_FAMILIES`).
        resolution: heightfield cell size (m).
        ceilings: {family: the top row's difficulty in [0, 1]}; a family not named keeps 1.0
            (its whole range); {}: every family's whole range.

    Returns:
        The terrain file's text: levels x 6 m by len(families) x 3 m of boxes over the void at
        -2 m, and its `[curriculum]` table.

    Raises:
        ValueError: an unknown family, fewer than one level or a negative seed.
    """
    if seed < 0:
        raise ValueError(f"seed must be >= 0, got {seed}")
    if levels < 1:
        raise ValueError(f"levels must be >= 1, got {levels}")
    ceilings = dict(ceilings)
    bad = {f: c for f, c in ceilings.items() if f not in ALL_FAMILIES or not 0.0 <= c <= 1.0}
    if bad:
        raise ValueError(
            f"ceilings {bad}: each must name a family of {', '.join(ALL_FAMILIES)} and lie in [0, 1]"
        )
    ceilings = {f: c for f, c in ceilings.items() if f in families}
    unknown = [f for f in families if f not in ALL_FAMILIES]
    if unknown or not families:
        raise ValueError(f"unknown terrain families {unknown}: expected some of {', '.join(ALL_FAMILIES)}")
    length, width = SIZE
    boxes = []
    for level in range(levels):
        for column, family in enumerate(families):
            tile_seed = (seed * 1000 + level) * 100 + column
            difficulty = tile_difficulty(level, levels) * ceilings.get(family, 1.0)
            text = "\n".join(family_boxes(family, tile_seed, difficulty))
            boxes += [_shifted(box, level * length, column * width) for box in tomllib.loads(text)["box"]]
    names = ", ".join(f'"{f}"' for f in families)
    command_args = (f" --levels {levels}" if levels != CURRICULUM_LEVELS else "") + (
        f" --families {','.join(families)}" if tuple(families) != CURRICULUM_FAMILIES else ""
    )
    command_args += "".join(f" --ceiling {f}={c:g}" for f, c in ceilings.items())
    header = (
        f"# Generated by `leas terrain curriculum --seed {seed}{command_args}`: do not edit by hand.\n"
        f"# Curriculum arena: {levels} rows of difficulty (x) x {len(families)} families (y), "
        f"{length:g} x {width:g} m tiles.\n"
        f'name = "curriculum_seed{seed}"\n'
        f"bounds = [[0.0, 0.0], [{levels * length:g}, {len(families) * width:g}]]\n"
        f"void_height = -2.0\nresolution = {resolution}\n\n"
        f"[curriculum]\nlevels = {levels}\ntile = [{length:g}, {width:g}]\nfamilies = [{names}]\n\n"
    )
    return header + "\n".join(boxes)
