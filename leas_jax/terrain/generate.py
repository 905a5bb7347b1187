"""Terrain generators: the seeded training arena and the evaluation terrains (TOML text).

Host code (NumPy). The training arena follows the paper (§IV-A, Fig. 1): a 10 x 10
grid of 2 x 2 m cells, each of one kind (flat ground, stairs up and down, slopes,
holes, gaps, bridges, rubble, walls, pillars, platforms too high to climb). The
evaluation terrains reproduce the scenarios of §IV-B to §IV-D (ground, hole, bridge,
stairs facing and side-on, manual circuit) with dimensions that differ from the
training ones, as the paper requires.

Every walkable surface of the ground level has its top at z = 0. Features that
replace the ground (stairs, slopes, platforms, rubble, holes) claim an axis-aligned
rectangle in which no ground box is laid; the ground is the rest of the cell, split
into rectangles. Obstacles standing on the ground (walls, pillars) are placed so that
they never cover the centre of a ground box, so every box's top face is a support
surface (`Terrain.support_surfaces` drops faces whose centre is covered).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from leas_jax.errors import UsageError
from leas_jax.files import resolve_data_path

ARENA_CELLS = 10  # cells per side, paper §IV-A ("10x10 grid")
CELL = 2.0  # m, cell side: 20 x 20 m arena, paper §IV-A
RESOLUTION = 0.02  # m, heightfield cell
VOID_HEIGHT = -2.0  # m, height of uncovered points (holes)
FLOOR = -0.6  # m, bottom of ground-level boxes (below the deepest pit, 3 x 0.15 m)
TREAD = 0.30  # m, stair tread depth
RISE = (0.10, 0.15)  # m, stair rise range
BRIDGE_WIDTH = (0.30, 0.45)  # m, training bridges (evaluation: 0.30, paper §IV-B.3)
OBSTACLE_HEIGHT = (0.7, 2.0)  # m, walls and pillars
HIGH_PLATFORM = (0.5, 1.0)  # m, platforms too high to climb

# Number of cells of each kind in the arena (sums to 100); shuffled by the seed.
CELL_KINDS = {
    "flat": 14,
    "stairs_up": 9,
    "stairs_pit": 7,
    "slope": 10,
    "hole": 8,
    "gap": 7,
    "bridge": 8,
    "rubble": 10,
    "wall": 8,
    "pillars": 7,
    "high_platform": 7,
    "step_platform": 5,
}

TRAINING_COMMAND = "leas terrain generate --seed {seed} --out terrains/training_arena.toml"
EVAL_COMMAND = "leas terrain generate --eval-dir terrains"


@dataclass(frozen=True)
class BoxSpec:
    """A box to write: centre [3] world, full size [3], rpy [3] rad (world_R_box = Rz Ry Rx)."""

    center: tuple[float, float, float]
    size: tuple[float, float, float]
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)


Rect = tuple[float, float, float, float]  # (xmin, ymin, xmax, ymax), m


# --------------------------------------------------------------------------- boxes


def slab(rect: Rect, top: float, bottom: float = FLOOR) -> BoxSpec:
    """Axis-aligned box over `rect` spanning z in [bottom, top]."""
    x0, y0, x1, y1 = rect
    return BoxSpec(((x0 + x1) / 2, (y0 + y1) / 2, (top + bottom) / 2), (x1 - x0, y1 - y0, top - bottom))


def ramp(
    start_xy, yaw: float, length: float, angle: float, width: float, z0: float = 0.0, thickness: float = 0.3
) -> BoxSpec:
    """Tilted box whose top face rises from height z0 at `start_xy` along heading `yaw`.

    The top face is a `width`-wide rectangle whose horizontal projection runs `length`
    from start_xy along (cos yaw, sin yaw), rising by length * tan(angle). With
    R = Rz(yaw) Ry(-angle) the box x axis is Rz(yaw) (cos a, 0, sin a) (up the slope)
    and its z axis Rz(yaw) (-sin a, 0, cos a); the centre is the top-face centre moved
    down that z axis by half the thickness. The box never reaches behind start_xy.

    Args:
        start_xy: [2] world point at the middle of the low edge, m.
        yaw: heading of the ascent, rad.
        length: horizontal run, m.
        angle: slope, rad (> 0 rises).
        width: m.
        z0: height of the low edge, m.
        thickness: box thickness perpendicular to the slope, m.
    """
    c, s = math.cos(yaw), math.sin(yaw)
    rise = length * math.tan(angle)
    top_centre = np.array([start_xy[0] + 0.5 * length * c, start_xy[1] + 0.5 * length * s, z0 + 0.5 * rise])
    z_axis = np.array([-math.sin(angle) * c, -math.sin(angle) * s, math.cos(angle)])
    centre = top_centre - 0.5 * thickness * z_axis
    return BoxSpec(tuple(centre), (length / math.cos(angle), width, thickness), (0.0, -angle, yaw))


def ground_pieces(region: Rect, claimed: list[Rect]) -> list[Rect]:
    """Split `region` minus the `claimed` rectangles into few axis-aligned rectangles.

    The region is cut into a grid by every claimed edge; free grid cells are merged
    into runs along x, then runs with the same x span are merged along y.

    Args:
        region: (xmin, ymin, xmax, ymax).
        claimed: rectangles (clipped to the region) where no ground goes.

    Returns:
        disjoint rectangles covering region minus claimed.
    """
    x0, y0, x1, y1 = region
    clipped = [(max(a, x0), max(b, y0), min(c, x1), min(d, y1)) for a, b, c, d in claimed]
    clipped = [r for r in clipped if r[0] < r[2] - 1e-9 and r[1] < r[3] - 1e-9]
    xs = sorted({round(v, 9) for r in clipped for v in (r[0], r[2])} | {x0, x1})
    ys = sorted({round(v, 9) for r in clipped for v in (r[1], r[3])} | {y0, y1})

    def free(i, j):
        cx, cy = (xs[i] + xs[i + 1]) / 2, (ys[j] + ys[j + 1]) / 2
        return not any(a < cx < c and b < cy < d for a, b, c, d in clipped)

    open_runs: dict[tuple[int, int], int] = {}  # (i0, i1) -> first row j
    pieces = []
    for j in range(len(ys) - 1):
        runs, i = [], 0
        while i < len(xs) - 1:
            if free(i, j):
                start = i
                while i < len(xs) - 1 and free(i, j):
                    i += 1
                runs.append((start, i))
            else:
                i += 1
        for run in list(open_runs):
            if run not in runs:
                pieces.append((xs[run[0]], ys[open_runs.pop(run)], xs[run[1]], ys[j]))
        for run in runs:
            open_runs.setdefault(run, j)
    for run, j0 in open_runs.items():
        pieces.append((xs[run[0]], ys[j0], xs[run[1]], ys[-1]))
    return sorted(pieces, key=lambda r: (r[1], r[0]))


def stairs(
    start: float,
    lo: float,
    hi: float,
    tops,
    axis: int,
    direction: int = 1,
    tread: float = TREAD,
    bottom: float = FLOOR,
) -> list[BoxSpec]:
    """A flight of treads, one slab each.

    Args:
        start: coordinate along `axis` where the first tread begins, m.
        lo, hi: extent across the flight (along the other horizontal axis), m.
        tops: top heights of the treads in walking order, m.
        axis: 0 (flight along x) or 1 (along y).
        direction: +1 or -1, walking direction along the axis.
        tread: tread depth, m.
        bottom: bottom of the slabs, m.

    Returns:
        one slab per tread, from `start` on, in walking order.
    """
    boxes, pos = [], start
    for top in tops:
        a, b = sorted((pos, pos + direction * tread))
        rect = (a, lo, b, hi) if axis == 0 else (lo, a, hi, b)
        boxes.append(slab(rect, top, bottom))
        pos += direction * tread
    return boxes


# ------------------------------------------------------------------- arena cells


@dataclass
class _Cell:
    """Contents of one arena cell in its local frame [0, CELL]^2 (before rotation)."""

    kind: str
    boxes: list  # BoxSpec, local frame
    claimed: list  # Rect, local frame: no ground there


def _uniform(rng, lo, hi) -> float:
    """One uniform draw in [lo, hi]; hi below lo by rounding (a degenerate range) gives lo."""
    return float(rng.uniform(lo, max(lo, hi)))


def _cell_flat(rng) -> _Cell:
    return _Cell("flat", [], [])


def _staircase(rng, kind: str, sign: int) -> _Cell:
    """Stairs up then down (sign +1) or down into a pit then up (sign -1) along u."""
    steps = int(rng.integers(2, 4))  # 2 or 3 rises each way
    rise = round(_uniform(rng, *RISE), 3)
    width = round(_uniform(rng, 1.0, 1.6), 2)
    # Treads: rise, 2 rise, ..., steps*rise (the landing), ..., rise; room for 1.6 m.
    landing = TREAD if steps == 3 else round(_uniform(rng, TREAD, 1.6 - 2 * TREAD * (steps - 1)), 2)
    length = 2 * TREAD * (steps - 1) + landing
    u0 = round(_uniform(rng, 0.2, CELL - 0.2 - length), 2)
    v0 = round(_uniform(rng, 0.2, CELL - 0.2 - width), 2)
    boxes, pos = [], u0
    levels = list(range(1, steps + 1)) + list(range(steps - 1, 0, -1))
    for level in levels:
        depth = landing if level == steps else TREAD
        boxes.append(slab((pos, v0, pos + depth, v0 + width), sign * level * rise))
        pos += depth
    return _Cell(kind, boxes, [(u0, v0, u0 + length, v0 + width)])


def _cell_stairs_up(rng) -> _Cell:
    return _staircase(rng, "stairs_up", 1)


def _cell_stairs_pit(rng) -> _Cell:
    return _staircase(rng, "stairs_pit", -1)


def _cell_slope(rng) -> _Cell:
    """A hill along u: ramp up, flat top, ramp down, at 4-15 degrees."""
    angle_deg = round(_uniform(rng, 4.0, 15.0), 1)
    angle = math.radians(angle_deg)
    run = round(_uniform(rng, 0.45, 0.7), 2)
    top_len = round(_uniform(rng, 0.2, 1.6 - 2 * run), 2)
    width = round(_uniform(rng, 1.0, 1.6), 2)
    length = 2 * run + top_len
    u0 = round(_uniform(rng, 0.2, CELL - 0.2 - length), 2)
    v0 = round(_uniform(rng, 0.2, CELL - 0.2 - width), 2)
    vm = v0 + width / 2
    height = run * math.tan(angle)
    boxes = [
        ramp((u0, vm), 0.0, run, angle, width),
        slab((u0 + run, v0, u0 + run + top_len, v0 + width), height),
        ramp((u0 + length, vm), math.pi, run, angle, width),
    ]
    return _Cell("slope", boxes, [(u0, v0, u0 + length, v0 + width)])


def _cell_hole(rng) -> _Cell:
    """A rectangular hole (void) inside the cell, ground all around."""
    su, sv = (round(_uniform(rng, 0.4, 1.2), 2) for _ in range(2))
    u0 = round(_uniform(rng, 0.3, CELL - 0.3 - su), 2)
    v0 = round(_uniform(rng, 0.3, CELL - 0.3 - sv), 2)
    return _Cell("hole", [], [(u0, v0, u0 + su, v0 + sv)])


def _cell_gap(rng) -> _Cell:
    """A ditch (void) 0.15-0.5 m wide across the whole cell."""
    width = round(_uniform(rng, 0.15, 0.5), 2)
    u0 = round(_uniform(rng, 0.6, CELL - 0.6 - width), 2)
    return _Cell("gap", [], [(u0, 0.0, u0 + width, CELL)])


def _cell_bridge(rng) -> _Cell:
    """Void across the cell between two ground strips, crossed by a narrow bridge along u."""
    d0, d1 = (round(_uniform(rng, 0.3, 0.5), 2) for _ in range(2))
    width = round(_uniform(rng, *BRIDGE_WIDTH), 2)
    v0 = round(_uniform(rng, 0.4, CELL - 0.4 - width), 2)
    # A beam 0.3 m deep, top at the ground level.
    beam = slab((d0, v0, CELL - d1, v0 + width), 0.0, -0.3)
    return _Cell("bridge", [beam], [(d0, 0.0, CELL - d1, CELL)])


def _splits(rng, lo: float, hi: float, parts: int, min_size: float = 0.2) -> list[float]:
    """Sorted cut points lo = c0 < ... < c_parts = hi with pieces of at least min_size."""
    free = hi - lo - parts * min_size
    weights = rng.uniform(0.5, 1.5, parts)
    sizes = min_size + free * weights / weights.sum()
    cuts = lo + np.concatenate([[0.0], np.cumsum(sizes)])
    cuts = [round(float(c), 2) for c in cuts]
    cuts[-1] = round(hi, 2)
    return cuts


def _cell_rubble(rng) -> _Cell:
    """A field of tiles of random heights (0.02-0.14 m, some left at ground level)."""
    margin = round(_uniform(rng, 0.2, 0.4), 2)
    us = _splits(rng, margin, CELL - margin, int(rng.integers(3, 5)))
    vs = _splits(rng, margin, CELL - margin, int(rng.integers(3, 5)))
    boxes = []
    for i in range(len(us) - 1):
        for j in range(len(vs) - 1):
            top = round(_uniform(rng, 0.02, 0.14), 3) if rng.uniform() < 0.75 else 0.0
            boxes.append(slab((us[i], vs[j], us[i + 1], vs[j + 1]), top))
    return _Cell("rubble", boxes, [(margin, margin, CELL - margin, CELL - margin)])


def _upright(centre, size_xy, height: float, yaw: float) -> BoxSpec:
    """A box standing on the ground (bottom 0.1 m below z = 0 so it is embedded)."""
    return BoxSpec(
        (centre[0], centre[1], (height - 0.1) / 2), (size_xy[0], size_xy[1], height + 0.1), (0.0, 0.0, yaw)
    )


def _fits(box: BoxSpec, margin: float, keep_clear) -> bool:
    """Whether an upright box lies inside [margin, CELL - margin]^2 and off the points keep_clear."""
    yaw = box.rpy[2]
    c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
    ex = 0.5 * (c * box.size[0] + s * box.size[1])
    ey = 0.5 * (s * box.size[0] + c * box.size[1])
    if box.center[0] - ex < margin or box.center[0] + ex > CELL - margin:
        return False
    if box.center[1] - ey < margin or box.center[1] + ey > CELL - margin:
        return False
    for px, py, clearance in keep_clear:
        # point in the box frame
        dx, dy = px - box.center[0], py - box.center[1]
        lx = math.cos(yaw) * dx + math.sin(yaw) * dy
        ly = -math.sin(yaw) * dx + math.cos(yaw) * dy
        if abs(lx) <= box.size[0] / 2 + clearance and abs(ly) <= box.size[1] / 2 + clearance:
            return False
    return True


# The ground of wall and pillar cells is one box whose top-face centre is the cell
# centre: obstacles keep 0.1 m away from it.
_CELL_CENTRE_CLEAR = ((CELL / 2, CELL / 2, 0.1),)


def _cell_wall(rng) -> _Cell:
    """A wall 0.7-2 m tall, 0.8-1.8 m long, 0.1-0.3 m thick, at a random heading."""
    for _ in range(1000):
        length = round(_uniform(rng, 0.8, 1.8), 2)
        thick = round(_uniform(rng, 0.1, 0.3), 2)
        height = round(_uniform(rng, *OBSTACLE_HEIGHT), 2)
        yaw = round(_uniform(rng, 0.0, math.pi), 4)
        centre = (round(_uniform(rng, 0.3, CELL - 0.3), 2), round(_uniform(rng, 0.3, CELL - 0.3), 2))
        wall = _upright(centre, (length, thick), height, yaw)
        if _fits(wall, 0.15, _CELL_CENTRE_CLEAR):
            return _Cell("wall", [wall], [])
    raise RuntimeError("no wall placement found")


def _cell_pillars(rng) -> _Cell:
    """Two to five square pillars 0.2-0.4 m wide, 0.7-2 m tall, at least 0.5 m apart."""
    count = int(rng.integers(2, 6))
    pillars: list[BoxSpec] = []
    for _ in range(1000):
        if len(pillars) == count:
            break
        side = round(_uniform(rng, 0.2, 0.4), 2)
        height = round(_uniform(rng, *OBSTACLE_HEIGHT), 2)
        yaw = round(_uniform(rng, 0.0, math.pi / 2), 4)
        centre = (round(_uniform(rng, 0.3, CELL - 0.3), 2), round(_uniform(rng, 0.3, CELL - 0.3), 2))
        pillar = _upright(centre, (side, side), height, yaw)
        clear = _CELL_CENTRE_CLEAR + tuple((p.center[0], p.center[1], 0.5) for p in pillars)
        if _fits(pillar, 0.15, clear):
            pillars.append(pillar)
    return _Cell("pillars", pillars, [])


def _platform(rng, kind: str, heights) -> _Cell:
    su, sv = (round(_uniform(rng, 0.6, 1.4), 2) for _ in range(2))
    u0 = round(_uniform(rng, 0.25, CELL - 0.25 - su), 2)
    v0 = round(_uniform(rng, 0.25, CELL - 0.25 - sv), 2)
    top = round(_uniform(rng, *heights), 3)
    rect = (u0, v0, u0 + su, v0 + sv)
    return _Cell(kind, [slab(rect, top)], [rect])


def _cell_high_platform(rng) -> _Cell:
    """A platform 0.5-1 m high: too high to climb."""
    return _platform(rng, "high_platform", HIGH_PLATFORM)


def _cell_step_platform(rng) -> _Cell:
    """A platform one stair rise high (0.08-0.15 m): climbable."""
    return _platform(rng, "step_platform", (0.08, 0.15))


_CELL_BUILDERS = {
    "flat": _cell_flat,
    "stairs_up": _cell_stairs_up,
    "stairs_pit": _cell_stairs_pit,
    "slope": _cell_slope,
    "hole": _cell_hole,
    "gap": _cell_gap,
    "bridge": _cell_bridge,
    "rubble": _cell_rubble,
    "wall": _cell_wall,
    "pillars": _cell_pillars,
    "high_platform": _cell_high_platform,
    "step_platform": _cell_step_platform,
}


def _rotate_cell(cell: _Cell, quarter_turns: int, origin) -> tuple[list[BoxSpec], list[Rect]]:
    """Move a cell from its local frame to the world: turn by quarter_turns x 90 deg about
    the cell centre, then translate to `origin` (the cell's min corner).

    Axis-aligned boxes stay axis-aligned (their x/y sizes swap on odd turns) so that the
    file carries exact zero angles; tilted or yawed boxes get the turn added to their yaw.
    """
    half = CELL / 2
    k = quarter_turns % 4
    cos_k, sin_k = [(1, 0), (0, 1), (-1, 0), (0, -1)][k]

    def point(u, v):
        du, dv = u - half, v - half
        return origin[0] + half + cos_k * du - sin_k * dv, origin[1] + half + sin_k * du + cos_k * dv

    boxes = []
    for box in cell.boxes:
        x, y = point(box.center[0], box.center[1])
        roll, pitch, yaw = box.rpy
        if roll == 0.0 and pitch == 0.0 and yaw == 0.0:
            size = box.size if k % 2 == 0 else (box.size[1], box.size[0], box.size[2])
            boxes.append(BoxSpec((x, y, box.center[2]), size))
        else:
            new_yaw = math.remainder(yaw + k * math.pi / 2, 2 * math.pi)
            boxes.append(BoxSpec((x, y, box.center[2]), box.size, (roll, pitch, new_yaw)))
    rects = []
    for u0, v0, u1, v1 in cell.claimed:
        (ax, ay), (bx, by) = point(u0, v0), point(u1, v1)
        rects.append((min(ax, bx), min(ay, by), max(ax, bx), max(ay, by)))
    return boxes, rects


def arena_cells(seed: int) -> list[tuple[int, int, str, list[BoxSpec]]]:
    """Contents of the training arena cell by cell.

    Args:
        seed: seed of numpy's default generator (PCG64); same seed, same arena.

    Returns:
        [(i, j, kind, boxes)] for the cell spanning [2i, 2i+2] x [2j, 2j+2], row-major
        in j then i; boxes include the cell's ground pieces (top at z = 0).
    """
    rng = np.random.default_rng(seed)
    kinds = [kind for kind, count in CELL_KINDS.items() for _ in range(count)]
    assert len(kinds) == ARENA_CELLS * ARENA_CELLS
    order = rng.permutation(len(kinds))
    cells = []
    for index, pick in enumerate(order):
        i, j = index % ARENA_CELLS, index // ARENA_CELLS
        kind = kinds[pick]
        local = _CELL_BUILDERS[kind](rng)
        origin = (i * CELL, j * CELL)
        boxes, claimed = _rotate_cell(local, int(rng.integers(0, 4)), origin)
        region = (origin[0], origin[1], origin[0] + CELL, origin[1] + CELL)
        ground = [slab(rect, 0.0) for rect in ground_pieces(region, claimed)]
        cells.append((i, j, kind, ground + boxes))
    return cells


def generate_training_arena(seed: int = 0) -> str:
    """TOML text of the 20 x 20 m training arena (paper §IV-A, Fig. 1).

    A 10 x 10 grid of 2 x 2 m cells; `CELL_KINDS` gives how many cells of each kind,
    their order, orientation and dimensions are drawn from `seed`. Bounds
    [[0, 0], [20, 20]], resolution 0.02 m, void height -2 m, ground top at z = 0.

    Args:
        seed: generator seed (>= 0).

    Returns:
        TOML text (terrain format v1) with a header naming the command that made it.
    """
    header = [
        f"Generated by `{TRAINING_COMMAND.format(seed=seed)}`: do not edit by hand.",
        f"Training arena (paper IV-A, Fig. 1): {ARENA_CELLS} x {ARENA_CELLS} cells of "
        f"{CELL:g} x {CELL:g} m, seed {seed}.",
    ]
    sections = [
        (
            f"cell ({i}, {j}) [{i * CELL:g}, {(i + 1) * CELL:g}] x [{j * CELL:g}, {(j + 1) * CELL:g}]: {kind}",
            boxes,
        )
        for i, j, kind, boxes in arena_cells(seed)
    ]
    side = ARENA_CELLS * CELL
    return terrain_toml(f"training_arena_seed{seed}", ((0.0, 0.0), (side, side)), sections, header=header)


# ------------------------------------------------------------------------ writing


def _num(value: float) -> str:
    """Shortest text of a float rounded to 1e-9 (nm): stable across platforms."""
    value = round(float(value), 9)
    if value == 0.0:
        return "0.0"
    return repr(value)


def _vec(values) -> str:
    return "[" + ", ".join(_num(v) for v in values) + "]"


def terrain_toml(
    name: str,
    bounds,
    sections,
    header=(),
    scenario: dict | None = None,
    void_height: float = VOID_HEIGHT,
    resolution: float = RESOLUTION,
) -> str:
    """Render a terrain as TOML (terrain format v1).

    Args:
        name: terrain name.
        bounds: [[xmin, ymin], [xmax, ymax]], m.
        sections: [(comment, [BoxSpec])]: boxes grouped under a comment line.
        header: comment lines at the top of the file.
        scenario: the [scenario] table as a dict (values: numbers or nested lists), or None.
        void_height: m.
        resolution: m.

    Returns:
        TOML text.
    """
    lines = [f"# {line}" for line in header]
    lines += [
        f'name = "{name}"',
        f"bounds = [{_vec(bounds[0])}, {_vec(bounds[1])}]",
        f"void_height = {_num(void_height)}",
        f"resolution = {_num(resolution)}",
    ]
    for comment, boxes in sections:
        lines += ["", f"# {comment}"]
        for box in boxes:
            lines += ["[[box]]", f"center = {_vec(box.center)}", f"size = {_vec(box.size)}"]
            if any(a != 0.0 for a in box.rpy):
                lines.append(f"rpy = {_vec(box.rpy)}")
    if scenario is not None:
        lines += ["", "[scenario]"]
        for key, value in scenario.items():
            if isinstance(value, int):
                text = str(value)
            elif isinstance(value, float):
                text = _num(value)
            elif np.ndim(value) == 1:
                text = _vec(value)
            else:
                text = "[" + ", ".join(_vec(row) for row in value) + "]"
            lines.append(f"{key} = {text}")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- evaluation terrains


def _scenario(
    target,
    start_region,
    start_yaw_deg,
    start_speed=(0.01, 0.07),
    n_starts: int = 60,
    seed: int = 0,
    waypoints=None,
) -> dict:
    table = {
        "target": list(target),
        "start_region": [list(r) for r in start_region],
        "start_yaw_deg": list(start_yaw_deg),
        "start_speed": list(start_speed),
        "n_starts": n_starts,
        "seed": seed,
    }
    if waypoints is not None:
        table["waypoints"] = [list(w) for w in waypoints]
    return table


def _eval_ground() -> tuple:
    """Flat 12 x 8 m ground, target 4 m ahead of the start region (paper §IV-B.1, Table II)."""
    bounds = ((0.0, 0.0), (12.0, 8.0))
    sections = [("ground, top at z = 0", [slab((0.0, 0.0, 12.0, 8.0), 0.0)])]
    # Start region centred 4 m behind the target; the yaw ranges of Table II
    # ([-30, 30], [60, 120], [150, 210]) and speeds 0.01/0.04/0.07 m/s are swept by the
    # evaluation, this file holds the first cell.
    scenario = _scenario((8.0, 4.0), ((3.9, 3.9), (4.1, 4.1)), (-30.0, 30.0))
    return (
        "Flat ground (paper IV-B.1, Table II): target 4 m ahead of the start region.",
        bounds,
        sections,
        scenario,
    )


EVAL_HOLE_WIDTH = 3.0  # m, across the line to the target (y); the training holes are 0.4-1.2 m
EVAL_HOLE_LENGTH = 2.0  # m, along the line to the target (x)


def _eval_hole(width: float = EVAL_HOLE_WIDTH, length: float = EVAL_HOLE_LENGTH) -> tuple:
    """10 x 8 m ground, a `width` x `length` hole between the start region and the target (§IV-B.2).

    The hole spans x in [4, 4 + length] and y in [4 - width/2, 4 + width/2]; the starts
    (x in [1, 2.5]) span the same y range, so the straight line from every start to the
    target (8.5, 4) crosses the hole's x range beside or inside it.
    """
    if not 0.0 < width <= 7.0 or not 0.0 < length <= 4.0:
        raise ValueError(f"hole width must lie in (0, 7] m and length in (0, 4] m, got {width}, {length}")
    bounds = ((0.0, 0.0), (10.0, 8.0))
    y0, y1 = round(4.0 - width / 2, 4), round(4.0 + width / 2, 4)
    hole = (4.0, y0, round(4.0 + length, 4), y1)
    ground = [slab(r, 0.0) for r in ground_pieces((0.0, 0.0, 10.0, 8.0), [hole])]
    sections = [(f"ground around a hole over x in [4, {hole[2]:g}], y in [{y0:g}, {y1:g}]", ground)]
    scenario = _scenario((8.5, 4.0), ((1.0, y0), (2.5, y1)), (-30.0, 30.0))
    return (
        (
            f"Hole (paper IV-B.2, Fig. 6a): a {width:g} m wide hole; the straight line from most starts "
            "to the target crosses it."
        ),
        bounds,
        sections,
        scenario,
    )


def hole_terrain_toml(width: float, length: float = EVAL_HOLE_LENGTH) -> str:
    """TOML text of `eval_hole` with another hole size (m); the sweep of `leas hole-sweep`."""
    description, bounds, sections, scenario = _eval_hole(width, length)
    return terrain_toml(f"hole_{width:g}m", bounds, sections, header=[description], scenario=scenario)


def _eval_bridge() -> tuple:
    """Two platforms joined by a 0.30 m bridge over the void; stairs lead down elsewhere (§IV-B.3)."""
    bounds = ((0.0, 0.0), (12.0, 8.0))
    low = -0.7  # m, lower floor reached by the stairs: 5 rises of 0.14 m
    rise = 0.14
    flight = stairs(4.0, 0.0, 2.0, [-(k + 1) * rise for k in range(5)], axis=0, bottom=FLOOR + low)
    sections = [
        ("start platform, top at z = 0", [slab((0.0, 0.0, 4.0, 8.0), 0.0)]),
        ("bridge 0.30 m wide over the void x in [4, 7]", [slab((4.0, 4.85, 7.0, 5.15), 0.0, -0.3)]),
        ("target platform, top at z = 0", [slab((7.0, 2.0, 12.0, 8.0), 0.0)]),
        (
            "stairs down along +x (5 x 0.14 m) to a lower floor beside the target platform, "
            "which is 0.7 m too high to climb from there",
            flight + [slab((5.5, 0.0, 12.0, 2.0), low, FLOOR + low)],
        ),
    ]
    scenario = _scenario((9.5, 5.0), ((1.0, 1.0), (3.0, 7.0)), (-30.0, 30.0))
    return (
        (
            "Bridge (paper IV-B.3, Fig. 6b): a 0.30 m wide bridge between two platforms; "
            "stairs lead down to a floor where the target platform is too high."
        ),
        bounds,
        sections,
        scenario,
    )


def _stairs_geometry() -> tuple:
    """Shared geometry of the two stairs scenarios: 10 x 6 m, six 0.12 m rises along +x."""
    bounds = ((0.0, 0.0), (10.0, 6.0))
    rise, count = 0.12, 6
    top = rise * count
    x_top = 4.0 + TREAD * (count - 1)  # the sixth rise is the edge of the top platform
    flight = stairs(4.0, 1.5, 4.5, [(k + 1) * rise for k in range(count - 1)], axis=0)
    ground = [slab(r, 0.0) for r in ground_pieces((0.0, 0.0, x_top, 6.0), [(4.0, 1.5, x_top, 4.5)])]
    sections = [
        ("ground, top at z = 0 (beside the flight it meets the top platform's 0.72 m edge)", ground),
        (f"stairs 3 m wide along +x: {count} rises of {rise} m, treads {TREAD} m", flight),
        (f"top platform at z = {top:g}", [slab((x_top, 0.0, 10.0, 6.0), top)]),
    ]
    return bounds, sections


def _eval_stairs() -> tuple:
    """Start facing the stairs, target on the top platform (§IV-B.4, Fig. 6c)."""
    bounds, sections = _stairs_geometry()
    scenario = _scenario((7.5, 3.0), ((1.0, 2.0), (2.5, 4.0)), (-30.0, 30.0))
    return (
        "Stairs (paper IV-B.4, Fig. 6c): start facing the stairs, target at the top.",
        bounds,
        sections,
        scenario,
    )


def _eval_stairs_side() -> tuple:
    """Same stairs, start yaw perpendicular to the stairs direction (§IV-B.4, Fig. 6d)."""
    bounds, sections = _stairs_geometry()
    scenario = _scenario((7.5, 3.0), ((1.0, 2.0), (2.5, 4.0)), (60.0, 120.0))
    return (
        (
            "Stairs side-on (paper IV-B.4, Fig. 6d): same stairs, initial heading 60-120 deg "
            "from the direction to the target."
        ),
        bounds,
        sections,
        scenario,
    )


def _eval_circuit() -> tuple:
    """A 16 x 10 m course followed through waypoints (§IV-D.2, Fig. 9).

    Route: rubble tiles, a 10 degree ramp up to a plateau, two steps down, a pillar
    slalom, along the north side of a hole, over stairs up and down, to the target.
    """
    bounds = ((0.0, 0.0), (16.0, 10.0))
    angle = math.radians(10.0)
    plateau = 1.5 * math.tan(angle)  # m, top of the 1.5 m ramp
    rubble_tops = [[0.04, 0.0, 0.08, 0.03], [0.0, 0.06, 0.02, 0.07], [0.05, 0.03, 0.0, 0.06]]
    us = [2.5, 3.0, 3.5, 4.0, 4.5]
    vs = [0.7, 1.23, 1.77, 2.3]
    rubble = [
        slab((us[i], vs[j], us[i + 1], vs[j + 1]), rubble_tops[j][i]) for i in range(4) for j in range(3)
    ]
    step = plateau / 2  # two equal steps down from the plateau (~0.13 m)
    down = stairs(10.0, 0.5, 2.5, [step], axis=0)
    ramp_box = ramp((5.5, 1.5), 0.0, 1.5, angle, 2.0)
    pillars = [
        _upright((x, y), (0.3, 0.3), 1.5, yaw)
        for x, y, yaw in ((12.2, 3.4, 0.3), (13.9, 2.6, 0.0), (14.3, 5.0, 0.6), (14.0, 6.4, 0.2))
    ]
    pyramid = stairs(6.4, 6.7, 8.3, [0.12, 0.24, 0.12], axis=0)
    hole = (9.5, 4.8, 12.0, 6.6)
    claimed = [(2.5, 0.7, 4.5, 2.3), (5.5, 0.5, 10.3, 2.5), hole, (6.4, 6.7, 7.3, 8.3)]
    ground = [slab(r, 0.0) for r in ground_pieces((0.0, 0.0, 16.0, 10.0), claimed)]
    sections = [
        ("ground, top at z = 0, around the features and a hole over x in [9.5, 12], y in [4.8, 6.6]", ground),
        ("rubble tiles, tops 0-0.08 m", rubble),
        (
            "10 degree ramp up to a plateau, then two steps down",
            [ramp_box, slab((7.0, 0.5, 10.0, 2.5), plateau)] + down,
        ),
        ("pillar slalom", pillars),
        ("stairs up and down (0.12 m rises) across the path", pyramid),
    ]
    waypoints = ((5.0, 1.5), (8.5, 1.5), (12.0, 1.5), (13.3, 4.5), (12.5, 7.6), (8.0, 7.6))
    scenario = _scenario(
        (4.0, 7.6), ((0.8, 1.2), (1.4, 1.8)), (-15.0, 15.0), (0.0, 0.0), n_starts=10, waypoints=waypoints
    )
    return (
        (
            "Circuit (paper IV-D.2, Fig. 9): waypoints through rubble, a ramp and plateau, steps "
            "down, pillars, past a hole and over stairs."
        ),
        bounds,
        sections,
        scenario,
    )


_EVAL_BUILDERS = {
    "eval_ground": _eval_ground,
    "eval_hole": _eval_hole,
    "eval_bridge": _eval_bridge,
    "eval_stairs": _eval_stairs,
    "eval_stairs_side": _eval_stairs_side,
    "eval_circuit": _eval_circuit,
}
# The evaluation scenarios, each the [scenario] table of terrains/eval_<name>.toml.
SCENARIOS = tuple(name.removeprefix("eval_") for name in _EVAL_BUILDERS)


def scenario_file(name: str) -> Path:
    """terrains/eval_<name>.toml of a scenario of `SCENARIOS`, resolved from the repository root."""
    if name not in SCENARIOS:
        raise UsageError(
            f"--scenario: unknown scenario {name!r} (expected one of {', '.join(SCENARIOS)}, all)"
        )
    return resolve_data_path(f"terrains/eval_{name}.toml")


def generate_eval_terrains() -> dict[str, str]:
    """TOML texts of the evaluation terrains, each with its [scenario] (docs/design.md §4, §8).

    Returns:
        {name: TOML text} for eval_ground, eval_hole, eval_bridge, eval_stairs,
        eval_stairs_side and eval_circuit; write them as terrains/<name>.toml.
    """
    texts = {}
    for name, build in _EVAL_BUILDERS.items():
        description, bounds, sections, scenario = build()
        header = [f"Generated by `{EVAL_COMMAND}`: do not edit by hand.", description]
        texts[name] = terrain_toml(name, bounds, sections, header=header, scenario=scenario)
    return texts
