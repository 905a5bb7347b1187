"""Resolution-complete global search over the lattice: A* from the start's node.

The graph's nodes are the valid lattice nodes (cell, heading); its edges are
  - forward moves (cell -> cell + OFFSETS[h], same heading), where `Lattice.move_valid`;
    cost: length x (1 + clearance_weight x shortfall + doubt_penalty where the move is
    doubtful + penalty of the cell entered), where shortfall = max(0, 1 - clearance /
    clearance_scale) draws the path to the middle of a passage without closing narrow ones
    (the bridge's strip keeps a finite cost), and a doubtful move (ground only the relaxed
    condition accepts, `lattice`) is taken only where no confident path is much shorter;
  - turns in place to the neighbouring heading (both nodes valid); cost: turn_cost x the
    angle (rad).
The LeaS policy walks along its heading, so a path is a sequence of forward moves and turns.

A* runs as Dijkstra (SciPy's compiled csgraph) on costs reduced by a potential, the planar
distance from a node's cell to the goal's disk: every edge costs at least the distance it
moves (its multipliers are >= 1, turns move nothing), so the potential is consistent, reduced
costs are >= 0, and Dijkstra on them expands exactly A*'s nodes in A*'s order. Expansion is
bounded by SciPy's `limit` on the reduced distance, doubled until a goal node is settled: on
a large scene the work stays near the corridor of the answer. The answer is exact at the
lattice's resolution (resolution-complete: a passage as wide as two cells is found whenever
it is connected). When no goal node is reachable, one unbounded run settles the whole
reachable set and the path ends at the reachable node nearest the goal (the best partial
answer).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from leas_jax.navigate.lattice import HEADINGS, OFFSETS, Lattice, heading_index


@dataclass(frozen=True)
class SearchConfig:
    """Costs of the global search (m of walking per unit)."""

    # m per rad: the policy turns at omega_max = 0.35 rad/s and walks at 0.18 m/s, so one
    # radian of turning takes as long as ~0.5 m of walking
    turn_cost: float = 0.5
    clearance_weight: float = 1.0  # extra cost per m where the clearance is 0
    clearance_scale: float = 0.30  # m: clearance beyond this costs nothing extra
    start_radius: float = 0.15  # m: the start's node is the valid node nearest it within this
    goal_radius: float = 0.15  # m: goal nodes are the valid nodes within this of the goal
    waypoint_spacing: float = 0.5  # m of path between the waypoints given to the policy
    # extra cost per m (on top of 1) of a doubtful move: a confident detour up to 4 x as long
    # is preferred, so doubtful ground is offered where it saves a long way round or is the
    # only way (the generator then judges it)
    doubt_penalty: float = 3.0
    # m of reduced cost (path cost over the straight line) the first A* round may spend; each
    # further round doubles it
    first_limit: float = 2.0


@dataclass(frozen=True)
class SearchResult:
    """A lattice path.

    Attributes:
        reached: the path ends at a goal node.
        reason: None when reached, else why not ("goal-invalid", "no-path").
        path: [P, 3] (x, y, yaw) world of the path's nodes, start first (one node: no move).
        waypoints: [W, 2] world points along the path every `waypoint_spacing`, its end last.
        cost: the path's cost (m-equivalent).
        length: m of forward moves.
        end_distance: m from the path's end to the goal.
    """

    reached: bool
    reason: str | None
    path: np.ndarray
    waypoints: np.ndarray
    cost: float
    length: float
    end_distance: float


def _node_ids(shape) -> np.ndarray:
    nx, ny, nh = shape
    return np.arange(nx * ny * nh).reshape(nx, ny, nh)


def graph(lattice: Lattice, penalty: np.ndarray | None, config: SearchConfig, trusted=None):
    """Sparse directed graph of the lattice (scipy.sparse csr, node id = (i * ny + j) * 16 + h).

    Args:
        lattice: the valid set.
        penalty: [nx, ny] extra cost per m of moving into each cell (failed regions), or None.
        config: costs.
        trusted: [nx, ny] bool, cells where doubtful moves cost no doubt_penalty (ground the
            contact generator has walked), or None.
    """
    from scipy import sparse

    nx, ny, nh = lattice.shape
    ids = _node_ids(lattice.shape)
    rows, cols, costs = [], [], []
    shortfall = np.clip(1.0 - lattice.clearance / config.clearance_scale, 0.0, 1.0)
    for h, (dx, dy) in enumerate(OFFSETS):
        i, j = np.nonzero(lattice.move_valid[:, :, h])
        ti, tj = i + dx, j + dy
        length = lattice.resolution * math.hypot(dx, dy)
        extra = config.clearance_weight * shortfall[ti, tj, h]
        doubt = lattice.move_doubtful[i, j, h]
        if trusted is not None:
            doubt = doubt & ~trusted[ti, tj]
        extra = extra + config.doubt_penalty * doubt
        if penalty is not None:
            extra = extra + penalty[ti, tj]
        rows.append(ids[i, j, h])
        cols.append(ids[ti, tj, h])
        costs.append(length * (1.0 + extra))
    step = np.abs(np.diff(np.unwrap(np.concatenate([HEADINGS, HEADINGS[:1]]))))  # [16], h -> h + 1
    for turn in (1, -1):
        target = (np.arange(nh) + turn) % nh
        angle = step if turn == 1 else np.roll(step, 1)  # h -> h - 1 spans step[h - 1]
        ok = lattice.node_valid & lattice.node_valid[:, :, target]
        i, j, h = np.nonzero(ok)
        rows.append(ids[i, j, h])
        cols.append(ids[i, j, target[h]])
        costs.append(config.turn_cost * angle[h])
    rows, cols, costs = (np.concatenate(a) for a in (rows, cols, costs))
    n = nx * ny * nh
    return sparse.csr_matrix((costs, (rows, cols)), shape=(n, n))


def start_node(lattice: Lattice, pose, config: SearchConfig) -> int | None:
    """Valid node nearest the start (x, y, ..., yaw) within `start_radius`, its heading nearest
    the start's yaw (then its neighbours), or None."""
    pose = np.asarray(pose, np.float64).reshape(-1)
    h0 = int(heading_index(pose[-1]))
    cells = _cells_near(lattice, pose[:2], config.start_radius)
    for dh in (0, 1, -1, 2, -2):
        h = (h0 + dh) % 16
        for c in cells:
            if lattice.node_valid[c[0], c[1], h]:
                return int(_node_ids(lattice.shape)[c[0], c[1], h])
    return None


def _cells_near(lattice: Lattice, xy, radius: float) -> np.ndarray:
    """Grid cells within `radius` of xy, nearest first. -> [K, 2] int."""
    centre = lattice.cell_of(xy)
    r = int(math.ceil(radius / lattice.resolution))
    di, dj = np.meshgrid(np.arange(-r, r + 1), np.arange(-r, r + 1), indexing="ij")
    cells = centre + np.stack([di.ravel(), dj.ravel()], axis=1)
    cells = cells[lattice.inside(cells)]
    dist = np.hypot(*(lattice.position(cells) - np.asarray(xy, np.float64)).T)
    order = np.lexsort((cells[:, 1], cells[:, 0], dist))  # deterministic ties
    keep = order[dist[order] <= radius + 1e-9]
    return cells[keep]


def goal_nodes(lattice: Lattice, goal, config: SearchConfig) -> np.ndarray:
    """Ids of the valid nodes (any heading) within `goal_radius` of the goal. -> [G] int."""
    cells = _cells_near(lattice, goal, config.goal_radius)
    ids = _node_ids(lattice.shape)
    out = [ids[c[0], c[1], h] for c in cells for h in range(16) if lattice.node_valid[c[0], c[1], h]]
    return np.array(out, np.int64)


def potential(lattice: Lattice, goal, radius: float) -> np.ndarray:
    """A*'s heuristic per node id: planar m from each cell centre to the disk of `radius` round
    the goal (x, y), 0 inside it. A lower bound of any path's cost to a goal node (every move
    costs at least its length) that changes along an edge by at most the edge's cost
    (consistent). -> [nx * ny * 16] float."""
    nx, ny, nh = lattice.shape
    cells = np.stack(np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij"), axis=-1)
    gap = np.hypot(*(lattice.position(cells) - np.asarray(goal, np.float64)).transpose(2, 0, 1))
    return np.repeat(np.maximum(gap - radius, 0.0).reshape(-1), nh)


def astar(adjacency, source: int, goals: np.ndarray, heuristic: np.ndarray, first_limit: float):
    """A* from `source` until a goal node is settled, as Dijkstra on reduced costs (host).

    Args:
        adjacency: csr graph with costs >= 0 (`graph`).
        source: start node id.
        goals: [G] goal node ids (may be empty).
        heuristic: [N] consistent lower bound of the cost to a goal node (`potential`).
        first_limit: reduced cost the first round may spend; each further round doubles it.

    Returns:
        (dist [N], pred [N]): costs from `source` (inf where not settled) and predecessors
        (-9999 where none), exact for every settled node. Without a settled goal node the
        last round is unbounded: every reachable node is settled.
    """
    from scipy import sparse
    from scipy.sparse import csgraph

    heads = np.repeat(np.arange(adjacency.shape[0]), np.diff(adjacency.indptr))
    reduced = adjacency.data - heuristic[heads] + heuristic[adjacency.indices]
    # >= 0 up to rounding; explicit zeros stay edges in a csr matrix
    reduced = sparse.csr_matrix(
        (np.maximum(reduced, 0.0), adjacency.indices, adjacency.indptr), shape=adjacency.shape
    )
    limit = float(first_limit) if len(goals) else np.inf
    while True:
        dist, pred = csgraph.dijkstra(
            reduced, directed=True, indices=source, return_predecessors=True, limit=limit
        )
        settled = np.isfinite(dist)
        if settled[goals].any() or not _frontier(reduced, heads, settled).any():
            break  # a goal is settled, or every reachable node is
        limit *= 2.0
    return dist + heuristic[source] - heuristic, pred


def _frontier(adjacency, heads: np.ndarray, settled: np.ndarray) -> np.ndarray:
    """[E] bool: the edges of csr `adjacency` (`heads`: [E] each edge's tail node) that leave the
    settled set [N] bool."""
    return settled[heads] & ~settled[adjacency.indices]


def planar_arc_length(xy: np.ndarray) -> np.ndarray:
    """[N] length (m) of the horizontal polyline through points xy [N, 2] (world) from point 0 to each."""
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])


def _waypoints(path_xy: np.ndarray, spacing: float) -> np.ndarray:
    """Points of the path every `spacing` m of arc length (lattice nodes), its end last. -> [W, 2]."""
    keep = np.concatenate([[True], np.any(np.diff(path_xy, axis=0) != 0, axis=1)])
    xy = path_xy[keep]
    if len(xy) == 1:
        return xy.copy()
    s = planar_arc_length(xy)
    marks = np.arange(spacing, s[-1], spacing)
    picks = np.searchsorted(s, marks)
    picks = np.unique(np.concatenate([picks, [len(xy) - 1]]))
    return xy[picks[picks > 0]]


def search(
    lattice: Lattice,
    start,
    goal,
    config: SearchConfig = SearchConfig(),
    penalty: np.ndarray | None = None,
    adjacency=None,
) -> SearchResult:
    """Cheapest lattice path from a start pose to a goal point (host; SciPy Dijkstra).

    Args:
        lattice: the valid set.
        start: (x, y, [z,] yaw) world; must lie within `start_radius` of a valid node.
        goal: (x, y) world.
        config: costs, radii and waypoint spacing.
        penalty: [nx, ny] extra cost per m in failed regions (see `graph`), or None.
        adjacency: the `graph(lattice, penalty, config)` when the caller already built it.

    Returns:
        `SearchResult`: the path to the cheapest goal node; when none is reachable, to the
        reachable node nearest the goal (reason "goal-invalid" when no valid node lies
        within `goal_radius` of the goal, "no-path" when none of those is reachable).

    Raises:
        ValueError: the start has no valid node near it.
    """
    goal = np.asarray(goal, np.float64).reshape(2)
    source = start_node(lattice, start, config)
    if source is None:
        raise ValueError(f"no valid lattice node within {config.start_radius} m of the start {start}")
    adjacency = graph(lattice, penalty, config) if adjacency is None else adjacency
    goals = goal_nodes(lattice, goal, config)
    dist, pred = astar(
        adjacency, source, goals, potential(lattice, goal, config.goal_radius), config.first_limit
    )
    reason = None
    if len(goals) == 0:
        reason = "goal-invalid"
    elif not np.isfinite(dist[goals]).any():
        reason = "no-path"
    if reason is None:
        end = int(goals[np.argmin(dist[goals])])  # argmin: the first of equal costs (ids ascend)
    else:
        reachable = np.flatnonzero(np.isfinite(dist))
        cells = np.stack(np.unravel_index(reachable, lattice.shape)[:2], axis=1)
        gap = np.hypot(*(lattice.position(cells) - goal).T)
        end = int(reachable[np.lexsort((dist[reachable], gap))[0]])
    chain = [end]
    while chain[-1] != source:
        chain.append(int(pred[chain[-1]]))
    chain = np.array(chain[::-1])
    i, j, h = np.unravel_index(chain, lattice.shape)
    xy = lattice.position(np.stack([i, j], axis=1))
    path = np.column_stack([xy, HEADINGS[h]])
    steps = np.hypot(*np.diff(xy, axis=0).T) if len(xy) > 1 else np.zeros(0)
    return SearchResult(
        reached=reason is None,
        reason=reason,
        path=path,
        waypoints=_waypoints(xy, config.waypoint_spacing),
        cost=float(dist[end]),
        length=float(steps.sum()),
        end_distance=float(np.hypot(*(xy[-1] - goal))),
    )
