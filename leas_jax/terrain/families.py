"""Procedural terrain families: the rough ground of the field's scenes, as box terrains. Host-only.

Each family draws a 6 x 3 m terrain (x 0..6, y 0..3) from a seed: flat ground at z = 0 for
x < 2 and x > 4.4 where the family allows, and between them the family's feature, whose
parameters are drawn uniformly over the ranges the contact-planning community's scenes span
(hpp-environments' rubble, DARPA blocks, stairs, bridges, debris) and past them, so that the
labels hold ground the generator does not walk as well as ground it does:

  - rubble: 0.3 m tiles tilted up to 5-30 deg about both axes, 0-0.05 m cracks, +-0.08 m offsets;
  - blocks: DARPA-style 0.4 x 0.2 m cinder blocks in a grid, 0.1-0.3 m high, tilted 10-25 deg
    in alternating directions;
  - stairs: 2-4 steps up with 0.05-0.30 m risers and 0.25-0.35 m treads, a 0.6 m landing,
    the same steps down;
  - narrow: a beam or narrow stairs 0.2-0.6 m wide over the void between two platforms;
  - stones: stepping stones 0.2-0.45 m square, 0.05-0.50 m apart over the void (and from the
    ground on either side), +-0.10 m high;
  - gaps: a 0.05-0.80 m gap over the void across the whole width;
  - slopes: a ramp 5-40 deg up (beyond about 30 deg it leaves the friction cone of the
    generator's feet), a landing, a step of up to 0.15 m down to the ground beyond;
  - clutter: flat ground with 4-10 pillars and walls 0.1-0.5 m wide and 0.05-1.5 m high.

Three more families serve the training curriculum (`leas_jax.terrain.curriculum`) and stay out
of the walkability model's data (`FAMILIES`): holes (a round hole in flat ground, 0.2-1.6 m
across), flat ground, and beams (the narrow family's beam alone, 0.2-0.6 m wide at ground level
over the void, so that a curriculum may grow a beam narrower without growing narrow stairs'
risers with it).

Drawn without a `difficulty`, a family's parameters are uniform over its ranges (the
walkability model's data). With a difficulty d in [0, 1] (the curriculum's rows), each
difficulty parameter sits at the d-quantile of its range, from an easier start where the
range's low end is not easy (e.g. blocks from 0 deg), jittered by +-0.05: legged_gym's terrain
levels, with the same families as the walkability model.

A terrain is TOML text (`leas_jax.terrain.loads_terrain`), so a family's terrains are data:
the walkability model's labels are cached under a hash of that text.
"""

from __future__ import annotations

import math

import numpy as np

FAMILIES = ("rubble", "blocks", "stairs", "narrow", "stones", "gaps", "slopes", "clutter")
CURRICULUM_ONLY = ("holes", "flat", "beams")  # families of the training curriculum alone
ALL_FAMILIES = FAMILIES + CURRICULUM_ONLY  # the order seeds each family's draws: append only
DIFFICULTY_JITTER = 0.05  # +- spread of a difficulty parameter's quantile around d
SIZE = (6.0, 3.0)  # m, x and y extent of every family terrain
FEATURE_X = (2.0, 4.4)  # m, where the feature lies along x (flat ground before and after)
THICKNESS = 0.2  # m, boxes standing on the void hang this far down from their top


class _Draw:
    """Random draws of a family terrain: positions from `rng` as they are; difficulty
    parameters (`param`) uniform over their range, or at the `difficulty` quantile of it."""

    def __init__(self, rng, difficulty: float | None):
        self.rng = rng
        self.difficulty = difficulty

    def uniform(self, *args, **kwargs):
        return self.rng.uniform(*args, **kwargs)

    def integers(self, *args, **kwargs):
        return self.rng.integers(*args, **kwargs)

    def param(self, low: float, high: float, easy: float | None = None) -> float:
        """A difficulty parameter: uniform in [low, high] without a difficulty; else between `easy`
        (default `low`; `high` may be below it when smaller is harder) and `high` at quantile d."""
        if self.difficulty is None:
            return self.rng.uniform(min(low, high), max(low, high))
        start = low if easy is None else easy
        quantile = np.clip(
            self.difficulty + self.rng.uniform(-DIFFICULTY_JITTER, DIFFICULTY_JITTER), 0.0, 1.0
        )
        return start + (high - start) * quantile

    def scale(self, value: float) -> float:
        """An amplitude fixed without a difficulty, scaled by d with one."""
        return value if self.difficulty is None else value * self.difficulty

    def count(self, low: int, high: int) -> int:
        """An integer in [low, high) uniformly, or at quantile d."""
        if self.difficulty is None:
            return int(self.rng.integers(low, high))
        return int(low + round((high - 1 - low) * self.difficulty))


def _box(center, size, rpy=(0.0, 0.0, 0.0)) -> str:
    c = ", ".join(f"{v:.4f}" for v in center)
    s = ", ".join(f"{v:.4f}" for v in size)
    r = ", ".join(f"{v:.4f}" for v in rpy)
    return f"[[box]]\ncenter = [{c}]\nsize = [{s}]\nrpy = [{r}]\n"


def _slab(x0: float, x1: float, top: float = 0.0, y0: float = 0.0, y1: float = SIZE[1]) -> str:
    """A flat box whose top is at `top`, spanning [x0, x1] x [y0, y1]."""
    return _box(((x0 + x1) / 2, (y0 + y1) / 2, top - THICKNESS / 2), (x1 - x0, y1 - y0, THICKNESS))


def _ground(before: float = FEATURE_X[0], after: float = FEATURE_X[1]) -> list[str]:
    """Flat ground before and after the feature."""
    return [_slab(0.0, before), _slab(after, SIZE[0])]


def _rubble(rng) -> list[str]:
    boxes = _ground()
    tile, crack = 0.3, rng.param(0.0, 0.05)
    tilt = math.radians(rng.param(5.0, 30.0, easy=0.0))
    offset = rng.scale(0.08)
    for x in np.arange(FEATURE_X[0] + tile / 2, FEATURE_X[1], tile):
        for y in np.arange(tile / 2, SIZE[1], tile):
            top = rng.uniform(-offset, offset)
            rpy = (rng.uniform(-tilt, tilt), rng.uniform(-tilt, tilt), 0.0)
            boxes.append(_box((x, y, top - 0.05), (tile - crack, tile - crack, 0.1), rpy))
    return boxes


def _blocks(rng) -> list[str]:
    boxes = _ground()
    height = rng.param(0.1, 0.3, easy=0.05)
    tilt = math.radians(rng.param(10.0, 25.0, easy=0.0))
    length, width = 0.4, 0.2
    for k, x in enumerate(np.arange(FEATURE_X[0] + length / 2, FEATURE_X[1], length)):
        for m, y in enumerate(np.arange(width / 2, SIZE[1], width)):
            sign = 1.0 if (k + m // 2) % 2 == 0 else -1.0
            boxes.append(_box((x, y, height / 2), (length, width, height), (0.0, sign * tilt, 0.0)))
    return boxes


def _stair_tops(rng) -> tuple[list[tuple[float, float, float]], float]:
    """Steps up, a landing, steps down: [(x0, x1, top)], and the x where the ground resumes."""
    steps, riser, tread = int(rng.integers(2, 5)), rng.param(0.05, 0.30, easy=0.03), rng.uniform(0.25, 0.35)
    tops, x = [], FEATURE_X[0]
    for k in range(1, steps + 1):
        tops.append((x, x + tread, k * riser))
        x += tread
    tops.append((x, x + 0.6, steps * riser))
    x += 0.6
    for k in range(steps - 1, 0, -1):
        tops.append((x, x + tread, k * riser))
        x += tread
    return tops, x


def _stairs(rng) -> list[str]:
    tops, end = _stair_tops(rng)
    return _ground(after=end) + [_slab(x0, x1, top) for x0, x1, top in tops]


def _beam_width(rng) -> float:
    return rng.param(0.6, 0.2, easy=1.2)  # narrower is harder


def _beam(width: float) -> list[str]:
    """A beam of `width` at ground level over the void between the grounds, on the centre line."""
    y0 = SIZE[1] / 2 - width / 2
    return _ground() + [_slab(FEATURE_X[0], FEATURE_X[1], 0.0, y0, y0 + width)]


def _narrow(rng) -> list[str]:
    width = _beam_width(rng)
    if rng.uniform() < 0.5:
        return _beam(width)
    y0 = SIZE[1] / 2 - width / 2
    tops, end = _stair_tops(rng)  # narrow stairs
    return _ground(after=end) + [_slab(x0, x1, top, y0, y0 + width) for x0, x1, top in tops]


def _beams(rng) -> list[str]:
    return _beam(_beam_width(rng))


def _stones(rng) -> list[str]:
    side, gap = rng.param(0.45, 0.2, easy=0.6), rng.param(0.05, 0.50, easy=0.02)  # smaller stones, wider gaps
    pitch = side + gap
    columns = np.arange(FEATURE_X[0] + gap + side / 2, FEATURE_X[1] - side / 2, pitch)
    # the ground resumes `gap` after the last column of stones, as it ends `gap` before the first
    boxes = _ground(after=columns[-1] + side / 2 + gap)
    for x in columns:
        for y in np.arange(side / 2 + rng.uniform(0.0, pitch), SIZE[1] - side / 2, pitch):
            boxes.append(
                _slab(
                    x - side / 2,
                    x + side / 2,
                    rng.uniform(-rng.scale(0.10), rng.scale(0.10)),
                    y - side / 2,
                    y + side / 2,
                )
            )
    return boxes


def _gaps(rng) -> list[str]:
    width = rng.param(0.05, 0.80, easy=0.0)
    middle = (FEATURE_X[0] + FEATURE_X[1]) / 2
    return [_slab(0.0, middle - width / 2), _slab(middle + width / 2, SIZE[0])]


def _slopes(rng) -> list[str]:
    angle = math.radians(rng.param(5.0, 40.0, easy=0.0))
    run = 1.0
    rise = run * math.tan(angle)
    length = run / math.cos(angle)
    x0 = FEATURE_X[0]
    ramp = _box(
        (x0 + run / 2, SIZE[1] / 2, rise / 2 - 0.05 / math.cos(angle)),
        (length, SIZE[1], 0.1),
        (0.0, -angle, 0.0),
    )
    landing = _slab(x0 + run, x0 + run + 0.6, rise)
    return [_slab(0.0, x0), ramp, landing, _slab(x0 + run + 0.6, SIZE[0], rise - min(rise, 0.15))]


def _clutter(rng) -> list[str]:
    boxes = [_slab(0.0, SIZE[0])]
    for _ in range(rng.count(4, 11) if rng.difficulty is None else rng.count(1, 13)):
        sx, sy = rng.uniform(0.1, 0.5, 2)
        if rng.uniform() < 0.3:  # a wall
            sy = rng.uniform(0.6, 1.2)
        height = rng.uniform(0.05, 1.5)
        x, y = rng.uniform(FEATURE_X[0], FEATURE_X[1]), rng.uniform(0.2, SIZE[1] - 0.2)
        boxes.append(_box((x, y, height / 2), (sx, sy, height), (0.0, 0.0, rng.uniform(0.0, math.pi))))
    return boxes


def _holes(rng) -> list[str]:
    """Flat ground around a square-ish hole over the void (the hole is cut as four slabs)."""
    side = rng.param(0.2, 1.6)
    x0 = (FEATURE_X[0] + FEATURE_X[1]) / 2 - side / 2
    y0 = rng.uniform(0.3, max(0.3, SIZE[1] - 0.3 - side))
    y1 = min(y0 + side, SIZE[1])
    boxes = [_slab(0.0, x0), _slab(x0 + side, SIZE[0]), _slab(x0, x0 + side, 0.0, 0.0, y0)]
    if y1 < SIZE[1]:
        boxes.append(_slab(x0, x0 + side, 0.0, y1, SIZE[1]))
    return boxes


def _flat(rng) -> list[str]:
    return [_slab(0.0, SIZE[0])]


_BUILDERS = {
    "rubble": _rubble,
    "blocks": _blocks,
    "stairs": _stairs,
    "narrow": _narrow,
    "stones": _stones,
    "gaps": _gaps,
    "slopes": _slopes,
    "clutter": _clutter,
    "holes": _holes,
    "flat": _flat,
    "beams": _beams,
}


def family_boxes(family: str, seed: int, difficulty: float | None = None) -> list[str]:
    """The `[[box]]` tables of the family's 6 x 3 m terrain drawn from `seed` (deterministic),
    at `difficulty` in [0, 1] (None: parameters uniform over their ranges; see the module doc).

    Raises:
        ValueError: an unknown family (the message lists the known ones) or a difficulty
            outside [0, 1].
    """
    if family not in _BUILDERS:
        raise ValueError(f"unknown terrain family {family!r}: expected one of {', '.join(ALL_FAMILIES)}")
    if difficulty is not None and not 0.0 <= difficulty <= 1.0:
        raise ValueError(f"difficulty must lie in [0, 1], got {difficulty!r}")
    rng = np.random.default_rng([seed, ALL_FAMILIES.index(family)])
    return _BUILDERS[family](_Draw(rng, difficulty))


def family_terrain(family: str, seed: int, resolution: float = 0.02, difficulty: float | None = None) -> str:
    """TOML text of the family's terrain drawn from `seed` (deterministic); see `family_boxes`.

    Raises:
        ValueError: as `family_boxes`.
    """
    boxes = family_boxes(family, seed, difficulty)
    header = (
        f'name = "family_{family}_{seed}"\n'
        f"bounds = [[0.0, 0.0], [{SIZE[0]}, {SIZE[1]}]]\nvoid_height = -2.0\nresolution = {resolution}\n"
    )
    return header + "\n".join(boxes)
