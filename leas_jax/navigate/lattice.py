"""The root's valid set over a lattice of positions x headings (host wrapper of jitted checks).

The lattice covers the terrain's bounds with cells of `resolution` m and 16 headings, the
directions of the 16-neighbourhood offsets (1, 0), (2, 1), (1, 1), (1, 2), ... (every 22.5 deg
on average; an offset, not an angle, so that a forward move lands on a cell centre). Each node
(cell, heading) is the root pose (x, y, z = terrain + nominal height, yaw = heading), and each
forward move (cell -> cell + offset, same heading) is checked at its midpoint as well.

Nodes are judged twice (a condition plus solid ground under the root, as the RBKino+RRT
baseline's `steering.baselines.lift_checked`):
  - *confident*: the reachability condition of the LeaS environment, the one fitted on flat
    ground, stairs and holes of the training arena;
  - *plausible*: the same cylinders with the checks that rough ground fails for no kinematic
    reason relaxed (`relaxed_reachability`): a tilted tile or a block's edge fails the
    confident condition's sole-flatness test, and its lookahead legs refuse a step down that
    the legs reach from a lowered root. Plausible nodes keep the trunk, leg-reach, hands and
    no-void tests, which no contact plan passes without.
A node that is plausible but not confident is *doubtful*: the search offers it at a cost
(`SearchConfig.doubt_penalty`), and the contact generator, which judges every guide, decides
(validation on demand, as lazy PRM and lazy A* validate edges only on the path they find).
A step model bounds each forward move: the root's height changes by at most `max_step`
between the move's ends and its midpoint, up or down (a riser that the legs do not reach in
one step is not an edge). The check runs as vmapped jitted calls over fixed-size chunks of
poses (one compiled shape for every terrain, memory bounded by the chunk).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from leas_jax.feasibility.walkability import (
    crack_filled_ground,
    judge_poses,
    load_walkability,
    relaxed_reachability,
)

# The 16-neighbourhood offsets (cells), counter-clockwise from +x: the lattice's headings.
OFFSETS = np.array(
    [
        (1, 0), (2, 1), (1, 1), (1, 2), (0, 1), (-1, 2), (-1, 1), (-2, 1),
        (-1, 0), (-2, -1), (-1, -1), (-1, -2), (0, -1), (1, -2), (1, -1), (2, -1),
    ],
    dtype=np.int64,
)  # fmt: skip
HEADINGS = np.arctan2(OFFSETS[:, 1], OFFSETS[:, 0])  # [16] rad


@dataclass(frozen=True)
class LatticeConfig:
    """Lattice settings.

    resolution: 0.05 m. eval_bridge's valid strip over its 0.30 m beam is 0.20 m wide: at
    0.05 m it holds four or five cell centres across, at 0.10 m one or two (a grid offset
    could leave it none), so 0.05 m is the coarsest cell that cannot miss it.
    """

    resolution: float = 0.05  # m
    chunk: int = 1 << 16  # poses per jitted call (one compiled shape)
    max_cells: int = 400_000  # refuse larger lattices (memory ~ 100 B per node); coarsen instead
    # Offer doubtful nodes (plausible, not confident) to the search; False keeps the confident
    # set alone (the lattice of earlier versions).
    offer_doubtful: bool = True
    # m, plausible nodes' sole-flatness bound (a sole disk within foothold_search of each leg whose
    # heights span at most this; the confident condition: 0.04 m), or None: no such term. None:
    # a root over a crack between rubble tiles or a missing tile has no flat sole disk within
    # the condition's 0.10 m search of its legs, yet the generator places the feet a stride
    # before and after it; the leg disks must still touch solid ground.
    relaxed_foothold_spread: float | None = None
    # m, the step model: the root's height changes by at most this between a move's end and its
    # midpoint, up or down. At the nominal root height the leg band (sole 0.75-1.175 m below the
    # root) holds a tread 0.25 m above or 0.175 m below the one under the root; a lowered root
    # reaches further down, so one bound both ways.
    max_step: float = 0.25
    # m: a strip of void narrower than this under the root (a crack between rubble tiles) counts
    # as ground: the root stands at the height of the ground beside it and the generator steps
    # over the strip. The edge of a platform stays an edge (a morphological closing of the
    # solid ground, which fills strips bounded on both sides only).
    crack_width: float = 0.10
    # The walkability model's weights (`leas feasibility walkability`), or None: the confident verdict is
    # then the env's reachability condition. With a model, a plausible pose is confident where
    # the model accepts it.
    walkability: str | None = None


@dataclass(frozen=True)
class Lattice:
    """Valid root poses over a grid of cells x the 16 headings.

    Attributes:
        origin: [2] world (x, y) of cell (0, 0), m.
        resolution: m between cell centres.
        node_valid: [nx, ny, 16] bool, the pose at cell (i, j), heading h is valid: confident,
            or plausible where the config offers doubtful nodes.
        move_valid: [nx, ny, 16] bool, the forward move from (i, j, h) to
            (i, j) + OFFSETS[h] (same heading) is valid: both ends and the midpoint valid,
            the root's height within `max_step` between them.
        clearance: [nx, ny, 16] float, m from the node to the nearest invalid node of the
            same heading (0 for invalid nodes).
        doubtful: [nx, ny, 16] bool, valid nodes that only the relaxed condition accepts.
        move_doubtful: [nx, ny, 16] bool, valid moves whose midpoint or end is doubtful.
        root_height: [nx, ny] float, root z (m, world) at each cell centre: terrain + nominal.
    """

    origin: np.ndarray
    resolution: float
    node_valid: np.ndarray
    move_valid: np.ndarray
    clearance: np.ndarray
    doubtful: np.ndarray
    move_doubtful: np.ndarray
    root_height: np.ndarray

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.node_valid.shape

    def position(self, cells) -> np.ndarray:
        """World (x, y) of integer cells [..., 2] -> [..., 2]."""
        return self.origin + self.resolution * np.asarray(cells, np.float64)

    def cell_of(self, xy) -> np.ndarray:
        """Nearest cell [..., 2] (int, may lie outside the grid) of world points [..., 2]."""
        return np.rint((np.asarray(xy, np.float64) - self.origin) / self.resolution).astype(np.int64)

    def inside(self, cells) -> np.ndarray:
        """[...] bool: integer cells [..., 2] lie on the grid."""
        cells = np.asarray(cells)
        nx, ny, _ = self.shape
        return (cells[..., 0] >= 0) & (cells[..., 0] < nx) & (cells[..., 1] >= 0) & (cells[..., 1] < ny)


def heading_index(yaw) -> np.ndarray:
    """Index of the lattice heading nearest each yaw (rad). [...] -> [...] int."""
    diff = (np.asarray(yaw, np.float64)[..., None] - HEADINGS + math.pi) % (2 * math.pi) - math.pi
    return np.argmin(np.abs(diff), axis=-1)


def _shifted(grid: np.ndarray, dx: int, dy: int, fill) -> np.ndarray:
    """grid[i + dx, j + dy, ...] at each (i, j) of grid [nx, ny, ...], `fill` off the grid."""
    nx, ny = grid.shape[:2]
    out = np.full_like(grid, fill)
    xs = slice(max(dx, 0), nx + min(dx, 0))
    ys = slice(max(dy, 0), ny + min(dy, 0))
    xd = slice(max(-dx, 0), nx + min(-dx, 0))
    yd = slice(max(-dy, 0), ny + min(-dy, 0))
    out[xd, yd] = grid[xs, ys]
    return out


def build_lattice(
    field, bounds, nominal_root_height: float, reach, config: LatticeConfig = LatticeConfig()
) -> Lattice:
    """The valid set of the root over the terrain (host; the checks are jitted JAX).

    Args:
        field: the heightfield (with the reachability rasters of `reach`).
        bounds: [[xmin, ymin], [xmax, ymax]] world, m: the lattice covers it.
        nominal_root_height: root height above the terrain, m.
        reach: `ReachabilityConfig` of the field.
        config: resolution and chunking.

    Returns:
        `Lattice`.
    """
    from scipy import ndimage

    from leas_jax.errors import UsageError

    bounds = np.asarray(bounds, np.float64).reshape(2, 2)
    res = float(config.resolution)
    nx, ny = (np.floor((bounds[1] - bounds[0]) / res + 1e-9).astype(int) + 1).tolist()
    if nx * ny > config.max_cells:
        raise UsageError(
            f"lattice resolution {res:g} m: {nx} x {ny} cells exceed max_cells {config.max_cells} "
            "(choose a coarser --resolution)"
        )
    origin = bounds[0].copy()
    ii, jj = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    cells = np.stack([ii, jj], axis=-1).reshape(-1, 1, 2).astype(np.float64)  # [C, 1, 2]
    nodes = origin + res * cells  # [C, 1, 2]
    middles = origin + res * (cells + OFFSETS[None] / 2.0)  # [C, 16, 2]
    yaw = np.broadcast_to(HEADINGS, (nx * ny, 16))
    planar = np.concatenate(
        [
            np.column_stack([np.broadcast_to(nodes, (nx * ny, 16, 2)).reshape(-1, 2), yaw.reshape(-1)]),
            np.column_stack([middles.reshape(-1, 2), yaw.reshape(-1)]),
        ]
    ).astype(np.float32)
    plausible = (
        relaxed_reachability(reach, config.relaxed_foothold_spread) if config.offer_doubtful else reach
    )
    ground_ok = crack_filled_ground(field, config.crack_width)
    model = None if config.walkability is None else load_walkability(config.walkability, reach)
    z, confident, ok = judge_poses(
        field, ground_ok, planar, nominal_root_height, reach, plausible, model, config.chunk
    )
    ok |= confident
    count = nx * ny * 16
    node_valid = ok[:count].reshape(nx, ny, 16)
    doubtful = node_valid & ~confident[:count].reshape(nx, ny, 16)
    root_height = z[:count].reshape(nx, ny, 16)[:, :, 0]
    middle_z = z[count:].reshape(nx, ny, 16)
    move_valid = node_valid & ok[count:].reshape(nx, ny, 16)
    move_doubtful = ~confident[count:].reshape(nx, ny, 16)  # the midpoint's
    for h, (dx, dy) in enumerate(OFFSETS):
        target_z = _shifted(root_height, int(dx), int(dy), np.nan)  # NaN off the grid: no move
        target_ok = _shifted(node_valid[:, :, h], int(dx), int(dy), False)
        step = np.maximum(np.abs(middle_z[:, :, h] - root_height), np.abs(target_z - middle_z[:, :, h]))
        move_valid[:, :, h] &= target_ok & (np.nan_to_num(step, nan=np.inf) <= config.max_step)
        move_doubtful[:, :, h] |= _shifted(doubtful[:, :, h], int(dx), int(dy), False)
    move_doubtful &= move_valid
    clearance = np.stack(
        [ndimage.distance_transform_edt(node_valid[:, :, h]) * res for h in range(16)], axis=-1
    )
    return Lattice(origin, res, node_valid, move_valid, clearance, doubtful, move_doubtful, root_height)
