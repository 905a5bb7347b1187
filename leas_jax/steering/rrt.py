"""RBKino+RRT: a kinodynamic bidirectional RRT whose local planner is RBKino.

Paper §IV-C compares LeaS with "RBKino with its path planner, which
stochastically explores waypoints to simplify the task of the local
controller" (HPP's kinodynamic planner, Fernbach et al. 2017). This one:

* states are planar (x, y, vx, vy); z follows the terrain and the yaw follows
  the velocity, as in `rbkino`;
* two trees, one from the start state (initial velocity along the heading)
  growing forward in time, one from the goal state (at rest) growing backward
  (its edges are RBKino paths *into* its nodes); they swap roles every
  iteration (RRT-Connect);
* samples: half uniform (a valid position, a velocity in any direction), half
  from the bridge test (Hsu et al. 2003), midpoints between two invalid
  positions, with a velocity along the passage: narrow passages such as the
  0.30 m bridge, under 1 % of the valid area, get a share of the samples;
* nearest neighbour by RBKino's minimum time (HPP's kinodynamic distance);
* a local path is valid when every pose on it, one every timestep, satisfies
  the reachability condition of the LeaS environment (`reachability.valid`,
  jitted and vmapped over the path), and the root stands over terrain, not
  the void (see `baselines.lift_checked`). An extension that hits an invalid pose is
  cut at the last valid state (forward tree) or after the last invalid one
  (backward tree) and kept if it is at least `min_extension` poses long, and
  at most `max_extension_seconds` of it is kept (the RRT step size);
* after each extension the new node tries a direct RBKino connection to the
  nearest node of the other tree; the first valid one closes the path;
* the node sequence is then shortened greedily (from each node, the farthest
  later node reachable by one valid RBKino path), like HPP's path optimisers;
* a seeded `numpy` RNG, bounded iterations and wall time.

The result's `waypoints` (node positions after the start) are what LeaS follows
in the "LeaS replaces RBKino" variant (paper §IV-D.1, Fig. 8).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from dataclasses import field as dataclass_field

import numpy as np

from leas_jax.env.config import ReachabilityConfig
from leas_jax.env.field import Heightfield
from leas_jax.steering.baselines import BaselineConfig, heading_from_velocity, lift_checked
from leas_jax.steering.rbkino import min_time, sample_times, steer


@dataclass(frozen=True)
class RRTConfig:
    """Search settings of the kinodynamic RRT."""

    max_iterations: int = 3000  # extensions (both trees together): the budget (~15 s on one core here)
    # s of wall time: a safety net only, far above the iteration budget, so that a search
    # gives the same answer on a loaded machine (results must not depend on the load)
    max_seconds: float = 300.0
    goal_bias: float = 0.05  # probability of sampling the other tree's root state
    sample_speed: float = 0.18  # m/s, sampled velocity norms in [0, this] (the target speed, paper §IV)
    sample_margin: float = 0.3  # m, positions are sampled this far inside the terrain bounds
    sample_attempts: int = 20  # draws per sample until its position is a valid pose
    min_extension: int = 3  # poses: shorter valid prefixes are not added to a tree
    # s: an extension keeps at most this much of its local path (the RRT step size);
    # short steps put more nodes, with fresh velocities, into narrow passages (the bridge)
    max_extension_seconds: float = 3.0
    # Narrow passages (the 0.30 m bridge: its valid strip is 0.2 m wide and 3 m long, under 1 %
    # of the valid area). This share of the samples comes from the bridge test (Hsu et al.,
    # ICRA 2003): two invalid positions `bridge_length` apart (uniform in the range) whose
    # midpoint is valid; the sample is that midpoint, its velocity along the passage (across
    # the segment). 0 disables it (uniform sampling only).
    bridge_fraction: float = 0.5
    bridge_length: tuple[float, float] = (0.3, 0.8)  # m
    shortcut: bool = True  # greedy shortening of the node sequence
    seed: int = 0


@dataclass(frozen=True)
class RRTResult:
    """Outcome of `plan_rrt`.

    Attributes:
        success: a valid path connects start and goal.
        states: [W + 1, 4] (x, y, vx, vy) of the path's nodes, start first, goal last
            (empty when not successful).
        waypoints: [W, 2] node positions after the start (the last is the goal).
        guide: [T, 4] (x, y, z, yaw) world, the RBKino paths between the nodes,
            one pose every timestep (None when not successful).
        iterations: extensions tried.
        seconds: wall time.
        tree_sizes: (start tree, goal tree) node counts.
    """

    success: bool
    states: np.ndarray
    waypoints: np.ndarray
    guide: np.ndarray | None
    iterations: int
    seconds: float
    tree_sizes: tuple[int, int]


@dataclass
class _Tree:
    """Nodes of one tree: states [N, 4], parent index, entry yaw (heading on arrival / departure)."""

    forward: bool  # True: edges go parent -> node in time; False: node -> parent
    states: list = dataclass_field(default_factory=list)
    parents: list = dataclass_field(default_factory=list)
    yaws: list = dataclass_field(default_factory=list)

    def add(self, state, parent: int, yaw: float) -> int:
        self.states.append(np.asarray(state, np.float64))
        self.parents.append(parent)
        self.yaws.append(float(yaw))
        return len(self.states) - 1

    def branch(self, index: int) -> list[int]:
        """Node indices from the root to `index`."""
        chain = []
        while index >= 0:
            chain.append(index)
            index = self.parents[index]
        return chain[::-1]


class _Problem:
    """Local paths and their validity on one terrain (host, calls the jitted checks)."""

    def __init__(self, field: Heightfield, config: BaselineConfig, reach: ReachabilityConfig):
        self.field, self.config, self.reach = field, config, reach

    def local_path(self, a, b, yaw_a: float | None):
        """RBKino from state a to state b. -> (states [M, 4], yaw [M], valid [M], guide [M, 4])."""
        c = self.config
        profile = steer(a[:2], a[2:], b[:2], b[2:], c.v_max, c.a_max)
        pos, vel = profile.state(sample_times(profile.duration, c.timestep))
        yaw = heading_from_velocity(vel, _initial_heading(vel) if yaw_a is None else yaw_a)
        guide, ok = lift_checked(self.field, np.column_stack([pos, yaw]), c.nominal_root_height, self.reach)
        return np.column_stack([pos, vel]), yaw, ok, guide

    def valid_positions(self, xy: np.ndarray, yaw: np.ndarray) -> np.ndarray:
        """[K] validity of root positions xy [K, 2] (world) heading yaw [K] (rad), one jitted check."""
        _, ok = lift_checked(
            self.field, np.column_stack([xy, yaw]), self.config.nominal_root_height, self.reach
        )
        return np.asarray(ok, bool)

    def valid_state(self, state) -> bool:
        """Validity of a state (x, y, vx, vy) heading along its velocity."""
        state = np.asarray(state, np.float64)
        return bool(self.valid_positions(state[None, :2], np.array([math.atan2(state[3], state[2])]))[0])


def _initial_heading(velocity: np.ndarray) -> float:
    """Direction of the first non-zero velocity (0 if the path never moves)."""
    speed = np.hypot(velocity[:, 0], velocity[:, 1])
    moving = np.flatnonzero(speed > 1e-6)
    return float(math.atan2(*velocity[moving[0], ::-1])) if len(moving) else 0.0


def _nearest(tree: _Tree, target: np.ndarray, config: BaselineConfig) -> int:
    """Node of `tree` with the shortest RBKino time to (forward tree) or from (backward tree) `target`."""
    states = np.asarray(tree.states)
    if tree.forward:
        a, b = states, target[None, :]
    else:
        a, b = target[None, :], states
    times = np.maximum(
        min_time(a[:, 0], b[:, 0], a[:, 2], b[:, 2], config.v_max, config.a_max),
        min_time(a[:, 1], b[:, 1], a[:, 3], b[:, 3], config.v_max, config.a_max),
    )
    return int(np.argmin(times))


def _sample(rng: np.random.Generator, bounds: np.ndarray, rrt: RRTConfig, problem: _Problem) -> np.ndarray:
    """Random state (x, y, vx, vy): from the bridge test with probability `bridge_fraction`, else
    a valid position uniform inside the bounds with a velocity of norm <= sample_speed in any
    direction. Falls back to the uniform draw when the bridge test finds no passage."""
    lo = bounds[0] + rrt.sample_margin
    hi = bounds[1] - rrt.sample_margin
    if rrt.bridge_fraction > 0.0 and rng.random() < rrt.bridge_fraction:
        state = _bridge_sample(rng, lo, hi, rrt, problem)
        if state is not None:
            return state
    state = None
    for _ in range(rrt.sample_attempts):
        xy = rng.uniform(lo, hi)
        angle = rng.uniform(-math.pi, math.pi)
        speed = rng.uniform(0.0, rrt.sample_speed)
        state = np.array([xy[0], xy[1], speed * math.cos(angle), speed * math.sin(angle)])
        if problem.valid_state(state):
            return state
    return state


def _bridge_sample(
    rng: np.random.Generator, lo: np.ndarray, hi: np.ndarray, rrt: RRTConfig, problem: _Problem
) -> np.ndarray | None:
    """Bridge test over `sample_attempts` draws at once: an invalid position p, another one q at
    a distance uniform in `bridge_length` in a uniform direction, and their midpoint valid.

    Every pose is checked heading along the passage, the direction across p -> q, in which the
    sampled velocity (norm uniform in [0, sample_speed], either way) points. Returns the state
    [4] at the midpoint of the first draw that passes, or None.
    """
    n = rrt.sample_attempts
    p = rng.uniform(lo, hi, (n, 2))
    across = rng.uniform(-math.pi, math.pi, n)
    q = p + rng.uniform(*rrt.bridge_length, n)[:, None] * np.column_stack([np.cos(across), np.sin(across)])
    middle = (p + q) / 2.0
    speed = rng.uniform(0.0, rrt.sample_speed, n) * np.where(rng.random(n) < 0.5, 1.0, -1.0)
    along = speed[:, None] * np.column_stack([-np.sin(across), np.cos(across)])
    heading = np.arctan2(along[:, 1], along[:, 0])
    valid = problem.valid_positions(np.concatenate([p, q, middle]), np.tile(heading, 3))
    inside = np.all((middle >= lo) & (middle <= hi), axis=1)
    passes = np.flatnonzero(~valid[:n] & ~valid[n : 2 * n] & valid[2 * n :] & inside)
    if len(passes) == 0:
        return None
    k = passes[0]
    return np.concatenate([middle[k], along[k]])


def _extend(tree: _Tree, target: np.ndarray, problem: _Problem, rrt: RRTConfig) -> int | None:
    """Grow `tree` toward `target`, keeping the longest valid part. Returns the new node or None."""
    near = _nearest(tree, target, problem.config)
    node = tree.states[near]
    limit = max(rrt.min_extension, int(round(rrt.max_extension_seconds / problem.config.timestep)) + 1)
    if tree.forward:
        states, yaw, ok, _ = problem.local_path(node, target, tree.yaws[near])
        bad = np.flatnonzero(~ok)
        end = len(ok) if len(bad) == 0 else bad[0]  # poses [0, end) are valid
        end = min(end, limit)
        if end < rrt.min_extension:
            return None
        return tree.add(states[end - 1], near, yaw[end - 1])
    states, yaw, ok, _ = problem.local_path(target, node, None)
    bad = np.flatnonzero(~ok)
    begin = 0 if len(bad) == 0 else bad[-1] + 1  # poses [begin, M) are valid
    begin = max(begin, len(ok) - limit)
    if len(ok) - begin < rrt.min_extension:
        return None
    return tree.add(states[begin], near, yaw[begin])


def _connect(new: int, tree: _Tree, other: _Tree, problem: _Problem) -> int | None:
    """Try one valid RBKino path from node `new` of `tree` to the nearest node of `other`."""
    state = tree.states[new]
    near = _nearest(other, state, problem.config)
    if tree.forward:
        _, _, ok, _ = problem.local_path(state, other.states[near], tree.yaws[new])
    else:
        _, _, ok, _ = problem.local_path(other.states[near], state, other.yaws[near])
    return near if ok.all() else None


def _shortcut(states: list, yaw0: float, problem: _Problem) -> list:
    """Greedy shortening: from each kept node, jump to the farthest later node with a valid RBKino path."""
    kept = [0]
    yaw = yaw0
    while kept[-1] < len(states) - 1:
        i = kept[-1]
        for j in range(len(states) - 1, i, -1):
            _, yaws, ok, _ = problem.local_path(states[i], states[j], yaw)
            if ok.all() or j == i + 1:
                kept.append(j)
                yaw = yaws[-1]
                break
    return [states[k] for k in kept]


def path_guide(
    states,
    start_yaw: float,
    field: Heightfield,
    config: BaselineConfig = BaselineConfig(),
    reach: ReachabilityConfig = ReachabilityConfig(),
) -> tuple[np.ndarray, np.ndarray]:
    """Concatenate RBKino paths through planar states into one guide.

    Args:
        states: [W + 1, 4] (x, y, vx, vy), start first.
        start_yaw: yaw (rad) of the first pose (held until the robot moves).
        field: the heightfield.
        config: RBKino bounds, timestep, root height.
        reach: reachability cylinders.

    Returns:
        (guide [T, 4] (x, y, z, yaw), valid [T] bool).
    """
    positions, velocities = [], []
    for k in range(len(states) - 1):
        a, b = states[k], states[k + 1]
        profile = steer(a[:2], a[2:], b[:2], b[2:], config.v_max, config.a_max)
        pos, vel = profile.state(sample_times(profile.duration, config.timestep))
        positions.append(pos if k == 0 else pos[1:])
        velocities.append(vel if k == 0 else vel[1:])
    pos = np.concatenate(positions)
    vel = np.concatenate(velocities)
    yaw = heading_from_velocity(vel, start_yaw)
    yaw[0] = start_yaw
    return lift_checked(field, np.column_stack([pos, yaw]), config.nominal_root_height, reach)


def plan_rrt(
    field: Heightfield,
    start,
    goal,
    initial_speed: float = 0.0,
    bounds=None,
    config: BaselineConfig = BaselineConfig(),
    rrt: RRTConfig = RRTConfig(),
    reach: ReachabilityConfig = ReachabilityConfig(),
) -> RRTResult:
    """Kinodynamic bidirectional RRT from a start pose to a goal point at rest (host; calls jitted checks).

    Args:
        field: the heightfield (with reachability rasters for `reach`).
        start: (x, y, z, yaw) world; the start velocity is `initial_speed` along yaw.
        goal: (x, y) world; reached at rest.
        initial_speed: m/s.
        bounds: [[xmin, ymin], [xmax, ymax]] sampling box (default: the heightfield's extent).
        config: RBKino bounds, timestep, root height.
        rrt: search settings (seed, iterations, time).
        reach: reachability cylinders.

    Returns:
        `RRTResult`; `guide` passes the reachability condition at every pose when `success`.
    """
    began = time.monotonic()
    start = np.asarray(start, np.float64).reshape(-1)
    yaw0 = float(start[-1])
    if bounds is None:
        heights = np.asarray(field.heights)
        origin = np.asarray(field.origin, np.float64)
        res = float(field.resolution)
        bounds = np.array([origin, origin + res * (np.array(heights.shape) - 1)])
    bounds = np.asarray(bounds, np.float64).reshape(2, 2)
    problem = _Problem(field, config, reach)
    rng = np.random.default_rng(rrt.seed)
    source = np.array([start[0], start[1], initial_speed * math.cos(yaw0), initial_speed * math.sin(yaw0)])
    sink = np.array([goal[0], goal[1], 0.0, 0.0])
    trees = (_Tree(forward=True), _Tree(forward=False))
    trees[0].add(source, -1, yaw0)
    trees[1].add(sink, -1, yaw0)
    roots = (source, sink)
    found = None
    iterations = 0
    for iterations in range(1, rrt.max_iterations + 1):
        if time.monotonic() - began > rrt.max_seconds:
            break
        side = (iterations - 1) % 2
        tree, other = trees[side], trees[1 - side]
        target = roots[1 - side] if rng.random() < rrt.goal_bias else _sample(rng, bounds, rrt, problem)
        new = _extend(tree, target, problem, rrt)
        if new is None:
            continue
        near = _connect(new, tree, other, problem)
        if near is not None:
            found = (new, near) if tree.forward else (near, new)
            break
    sizes = (len(trees[0].states), len(trees[1].states))
    if found is None:
        return RRTResult(
            False, np.zeros((0, 4)), np.zeros((0, 2)), None, iterations, time.monotonic() - began, sizes
        )
    forward_chain = [trees[0].states[k] for k in trees[0].branch(found[0])]
    backward_chain = [trees[1].states[k] for k in trees[1].branch(found[1])][::-1]
    states = forward_chain + backward_chain
    if rrt.shortcut:
        states = _shortcut(states, yaw0, problem)
    states = np.asarray(states)
    guide, ok = path_guide(states, yaw0, field, config, reach)
    return RRTResult(
        bool(ok.all()), states, states[1:, :2].copy(), guide, iterations, time.monotonic() - began, sizes
    )
