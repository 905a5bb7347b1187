"""The root's valid set over a lattice of positions x headings (host wrapper of jitted checks).

The lattice covers the terrain's bounds with cells of `resolution` m and 16 headings, the
directions of the 16-neighbourhood offsets (1, 0), (2, 1), (1, 1), (1, 2), ... (every 22.5 deg
on average; an offset, not an angle, so that a forward move lands on a cell centre). Each node
(cell, heading) is the root pose (x, y, z = terrain + nominal height, yaw = heading), and each
forward move (cell -> cell + offset, same heading) is checked at its midpoint as well. Both are
judged by `steering.baselines.lift_checked`, the reachability condition of the LeaS environment
plus solid ground under the root: the same test as the RBKino+RRT baseline's, so the two global
layers search the same valid set. The check runs as vmapped jitted calls over fixed-size chunks
of poses (one compiled shape for every terrain, memory bounded by the chunk).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

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


@dataclass(frozen=True)
class Lattice:
    """Valid root poses over a grid of cells x the 16 headings.

    Attributes:
        origin: [2] world (x, y) of cell (0, 0), m.
        resolution: m between cell centres.
        node_valid: [nx, ny, 16] bool, the pose at cell (i, j), heading h is valid.
        move_valid: [nx, ny, 16] bool, the forward move from (i, j, h) to
            (i, j) + OFFSETS[h] (same heading) is valid: both ends and the midpoint.
        clearance: [nx, ny, 16] float, m from the node to the nearest invalid node of the
            same heading (0 for invalid nodes).
    """

    origin: np.ndarray
    resolution: float
    node_valid: np.ndarray
    move_valid: np.ndarray
    clearance: np.ndarray

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


def _check(field, planar: np.ndarray, nominal_root_height: float, reach, chunk: int) -> np.ndarray:
    """lift_checked's validity of planar poses [M, 3] (x, y, yaw), `chunk` poses per jitted call."""
    from leas_jax.steering.baselines import lift_checked

    out = np.zeros(len(planar), bool)
    for begin in range(0, len(planar), chunk):
        part = planar[begin : begin + chunk]
        if len(part) < chunk:  # pad: every call has the same shape (one compile)
            part = np.concatenate([part, np.repeat(part[-1:], chunk - len(part), axis=0)])
        _, ok = lift_checked(field, part, nominal_root_height, reach)
        out[begin : begin + chunk] = ok[: min(chunk, len(planar) - begin)]
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
    ok = _check(field, planar, nominal_root_height, reach, config.chunk)
    node_valid = ok[: nx * ny * 16].reshape(nx, ny, 16)
    middle_valid = ok[nx * ny * 16 :].reshape(nx, ny, 16)
    move_valid = node_valid & middle_valid
    for h, (dx, dy) in enumerate(OFFSETS):
        target = np.zeros((nx, ny), bool)  # node_valid of (i + dx, j + dy, h), False off the grid
        xs = slice(max(dx, 0), nx + min(dx, 0))
        ys = slice(max(dy, 0), ny + min(dy, 0))
        xd = slice(max(-dx, 0), nx + min(-dx, 0))
        yd = slice(max(-dy, 0), ny + min(-dy, 0))
        target[xd, yd] = node_valid[xs, ys, h]
        move_valid[:, :, h] &= target
    clearance = np.stack(
        [ndimage.distance_transform_edt(node_valid[:, :, h]) * res for h in range(16)], axis=-1
    )
    return Lattice(origin, res, node_valid, move_valid, clearance)
