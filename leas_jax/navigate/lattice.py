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

import dataclasses
import functools
import math
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from leas_jax.env import reachability
from leas_jax.env.field import sample_nearest

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


def relaxed_reachability(reach, config: LatticeConfig):
    """The plausible nodes' condition: `reach` (a `ReachabilityConfig`) without its lookahead
    legs (the step model bounds height changes instead) and, unless
    `config.relaxed_foothold_spread` is set, without its sole-flatness term (the leg disks must
    still touch solid ground)."""
    spread = reach.foothold_spread
    if spread is not None:
        spread = (
            None if config.relaxed_foothold_spread is None else max(spread, config.relaxed_foothold_spread)
        )
    return dataclasses.replace(reach, leg_forward=0.0, foothold_spread=spread)


def _all_terms(field, pose: jax.Array, reach) -> jax.Array:
    """`reachability.valid` as a chain of ands: the disabled terms' constant True fold away
    (stacked, XLA spends seconds constant-folding them over a 65 536-pose chunk)."""
    return functools.reduce(jnp.logical_and, reachability.terms(field, pose, reach).values())


def crack_filled_ground(field, crack_width: float) -> np.ndarray:
    """[nx, ny] bool over the field's grid: solid ground, or void narrower than `crack_width`
    (m) between solid ground on both sides (host; a binary closing by a disk)."""
    from scipy import ndimage

    heights = np.asarray(field.heights)
    solid = heights > float(field.void_height) + 1e-3
    radius = int(round(0.5 * crack_width / float(field.resolution)))
    if radius < 1:
        return solid
    di, dj = np.meshgrid(np.arange(-radius, radius + 1), np.arange(-radius, radius + 1), indexing="ij")
    disk = di**2 + dj**2 <= radius**2
    padded = np.pad(solid, radius, mode="edge")  # the grid's border is no edge of the ground
    return solid | ndimage.binary_closing(padded, structure=disk)[radius:-radius, radius:-radius]


@functools.partial(jax.jit, static_argnums=(3, 4, 5))
def _judge(field, ground_ok: jax.Array, planar: jax.Array, nominal_root_height: float, confident, plausible):
    """Root z and both verdicts of planar poses [M, 3] (x, y, yaw) -> (z [M], confident [M],
    plausible [M]).

    The root stands `nominal_root_height` above the highest solid ground within `leg_radius`
    of it (`Heightfield.leg_max`), not above the point under it: a root over a crack between
    rubble tiles stands at the tiles' height, where the generator's feet are. The ground under
    it must be solid or a crack (`ground_ok` [nx, ny] bool, `crack_filled_ground`).
    """
    ground = sample_nearest(field, field.leg_max, planar[:, :2], outside=-jnp.inf)
    solid = jnp.isfinite(ground) & sample_nearest(field, ground_ok, planar[:, :2], outside=False)
    z = jnp.where(solid, ground, field.void_height) + nominal_root_height
    poses = jnp.stack([planar[:, 0], planar[:, 1], z, planar[:, 2]], axis=1)
    sure = jax.vmap(lambda pose: _all_terms(field, pose, confident))(poses) & solid
    maybe = jax.vmap(lambda pose: _all_terms(field, pose, plausible))(poses) & solid
    return z, sure, maybe


def _check(
    field, ground_ok, planar: np.ndarray, nominal_root_height: float, confident, plausible, chunk: int
):
    """`_judge` over planar poses [M, 3] (x, y, yaw), `chunk` poses per jitted call (one
    compiled shape). -> (root z [M] float, confident [M] bool, plausible [M] bool)."""
    out = np.zeros((3, len(planar)))
    for begin in range(0, len(planar), chunk):
        part = planar[begin : begin + chunk]
        if len(part) < chunk:  # pad: every call has the same shape (one compile)
            part = np.concatenate([part, np.repeat(part[-1:], chunk - len(part), axis=0)])
        n = min(chunk, len(planar) - begin)
        judged = _judge(field, ground_ok, jnp.asarray(part), float(nominal_root_height), confident, plausible)
        out[:, begin : begin + n] = np.stack([np.asarray(a, np.float64)[:n] for a in judged])
    return out[0], out[1] > 0.5, out[2] > 0.5


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
    plausible = relaxed_reachability(reach, config) if config.offer_doubtful else reach
    ground_ok = jnp.asarray(crack_filled_ground(field, config.crack_width))
    z, confident, ok = _check(field, ground_ok, planar, nominal_root_height, reach, plausible, config.chunk)
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
