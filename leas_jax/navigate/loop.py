"""Navigate: a verified contact plan from a start to a goal (host loop around jitted JAX parts).

One query runs, in a closed loop with the contact generator:

1. search: the cheapest lattice path from the current pose through the remaining route points
   to the goal (`search`, over the valid set of `lattice`), cut into waypoints;
2. policy rollout: the LeaS policy walks along those waypoints (`steering.leas.rollout_batch`,
   rolling on through poses the reachability condition rejects: the generator judges); a
   rollout that stalls away from the goal is cut where it stalled (`stall_start`), and the
   stall counts as a failure there (step 4);
3. contact planning: the generator validates the whole guide grown so far (the verified
   prefix of the previous attempts plus the new segment; one `ValidationPool` task);
4. where it stops short on the policy's guide, the searched path itself is walked from a
   verified pose `backoff_distance` before its last valid posture (`path_guide`, unless
   `path_fallback` is off); where it stops short on that (or on a policy guide without the
   fallback), the cells within `failure_radius` of where it failed are penalised, and the
   search is repeated from such a verified pose for the policy to walk, at most `max_replans`
   times.

The lattice offers doubtful ground (plausible, not confident: `lattice`) at a cost; the
generator's verdicts are what the loop learns from, kept across the replans of a query: the
cells its verified postures stand on are trusted (doubtful moves into them cost nothing
extra), the disks where it failed are penalised. Doubtful ground is thus validated on demand,
as a lazy planner validates only the edges of the paths it finds.

The generator plans each grown guide from its start, so the returned plan is one continuous
plan that `leas verify` checks like any other. Nothing in the loop is random: a query's
answer is a function of the policy, the terrain, the query and the configs, whatever the
number of workers or the other queries of a batch (`Navigator.run` runs many queries with
their generator tasks in flight together, as `leas evaluate` does).
"""

from __future__ import annotations

import concurrent.futures
import functools
import math
import time
from dataclasses import dataclass, field

import numpy as np

from leas_jax.contacts.metrics import SUCCESS_RADIUS
from leas_jax.contacts.planner.config import GeneratorConfig
from leas_jax.errors import UsageError
from leas_jax.navigate import result as reasons
from leas_jax.navigate.lattice import LatticeConfig, build_lattice, relaxed_reachability
from leas_jax.navigate.result import Attempt, NavigationResult
from leas_jax.navigate.search import SearchConfig, SearchResult, graph, planar_arc_length, search


@dataclass(frozen=True)
class NavigateConfig:
    """Settings of the closed loop (the lattice's and the search's are nested)."""

    lattice: LatticeConfig = LatticeConfig()
    search: SearchConfig = SearchConfig()
    # searches after the first one that the policy walks (those whose path is walked itself,
    # `path_fallback`, are not counted). 5: on the HPP rough scenes (20 starts each,
    # docs/results/2026-12-06-rough-scenes) every query that failed with 3 had used all 3 (the
    # generator stops on rubble, another way round is tried); a query that reaches needs 0-2.
    max_replans: int = 5
    # extra cost per m (on top of 1) of moving within failure_radius of a failure: 4 makes a
    # detour up to 5 x the length of the penalised stretch cheaper than going through again
    failure_penalty: float = 4.0
    # m, about a step and a half of Talos. The penalised disk is centred failure_radius / 2
    # ahead of the guide pose where the generator failed, along its heading: what stopped it
    # (a foothold it could not find) lies ahead of the root, and the pose the search starts
    # again from (backoff_distance before) then lies outside the disk.
    failure_radius: float = 0.5
    # m of verified guide given up before the failure: room for the policy to turn away (it
    # turns at most omega_max = 0.35 rad/s while walking, a quarter turn takes ~0.5-0.8 m)
    backoff_distance: float = 1.0
    # LeaS horizon = this x the time to walk the waypoints at the target speed (eval's factor),
    # rounded up to `horizon_quantum` steps so that queries share a few compiled rollouts
    horizon_factor: float = 2.5
    horizon_quantum: int = 200
    via_radius: float = 0.5  # m: a route point counts as passed once the guide came this close
    # m: cells this close to a verified guide pose are trusted (a doubtful move into them costs
    # nothing extra); about the half-width of the feet's stance (0.085 m each side) plus a cell
    trust_radius: float = 0.15
    # s and m: a rollout that ends away from the goal with its last `stall_time` or more within
    # `stall_radius` of one pose has stalled there (LeaS dithering before ground it does not
    # take: the entrance of rubbles_stairs_2's rubble, where the policy marked time for 100 s
    # of every 120 s rollout, each replan walking on into the same stall). The guide is cut at
    # the stall and the stall is treated as a failure of the generator there (penalised,
    # searched round), which also spares the generator planning the stalled poses
    # (test_a_stalled_rollout_is_cut_and_searched_round). A quarter turn in place at the
    # policy's 0.35 rad/s takes about 4.5 s. stall_time None: never.
    stall_time: float | None = 5.0
    stall_radius: float = 0.25
    # Where the generator stops on the policy's guide, the next attempt first walks the searched
    # lattice path itself from the same verified pose (`path_guide`: its cells' positions and
    # headings at the env's target speed, on the terrain), before the failed region is penalised
    # and searched round: a policy that wavers off a narrow beam loses the crossing that the
    # path along the beam's valid cells keeps (eval_bridge with the `quick` preset's 30 M
    # policies, docs/results/2026-12-06-navigate-path-fallback). Such an attempt does not count
    # against max_replans; where it fails too, its failure is penalised and the policy walks
    # the next search. False: the policy walks every search.
    path_fallback: bool = True
    generator: object = None  # `GeneratorConfig` of the contact generator (None: its defaults)


@dataclass(frozen=True)
class Query:
    """One navigate query.

    Attributes:
        start: [4] (x, y, z, yaw) world, z at the nominal height above the terrain.
        speed: initial speed along the heading, m/s.
        route: [R, 2] world points to visit in order, the goal last.
    """

    start: np.ndarray
    speed: float
    route: np.ndarray

    @property
    def goal(self) -> np.ndarray:
        return self.route[-1]


@dataclass
class _State:
    """A query in flight."""

    query: Query
    penalty: np.ndarray
    trusted: np.ndarray  # [nx, ny] bool, cells the generator's verified postures stood on
    guide: np.ndarray | None = None
    segment_begin: int = 0
    search: SearchResult | None = None
    path: np.ndarray | None = None
    waypoints: np.ndarray | None = None
    stalled: bool = False  # the guide's last segment was cut where the policy stalled (`stall_start`)
    kind: str = "policy"  # what walked the guide's last segment: "policy" or "path" (`path_guide`)
    attempts: list = field(default_factory=list)
    best: tuple | None = None  # (final distance, plan, guide)
    unreachable: str | None = None  # the first search reason that the goal cannot be reached
    seconds: dict = field(default_factory=lambda: {"search": 0.0, "rollout": 0.0, "contact_planning": 0.0})
    done: NavigationResult | None = None


@functools.lru_cache(maxsize=1)
def _jitted_terms():
    """`reachability.terms` jitted (its config static), built once."""
    import jax

    from leas_jax.env import reachability

    return jax.jit(reachability.terms, static_argnums=2)


def stall_start(guide: np.ndarray, steps: int, radius: float) -> int | None:
    """Index of the pose where a guide [T, 4] stalls: the earliest pose i such that every pose
    from i to the end lies within `radius` (m, horizontally) of pose i, when those are at least
    `steps` poses after it; None where the guide's tail moves on (host, pure)."""
    xy = np.asarray(guide)[:, :2]
    begin = len(xy) - 1
    while begin > 0 and np.all(np.hypot(*(xy[begin:] - xy[begin - 1]).T) <= radius):
        begin -= 1
    return begin if len(xy) - 1 - begin >= steps else None


def _ahead(pose: np.ndarray, config: NavigateConfig) -> np.ndarray:
    """[2] world centre of the disk penalised after a failure at guide pose [4] (x, y, z, yaw):
    `failure_radius` / 2 ahead of it along its heading."""
    return pose[:2] + 0.5 * config.failure_radius * np.array([math.cos(pose[3]), math.sin(pose[3])])


def path_guide(pose: np.ndarray, path: np.ndarray, speed: float, timestep: float) -> np.ndarray:
    """Planar guide along a lattice path, walked at a constant speed.

    Args:
        pose: [4] (x, y, z, yaw) world, where the guide starts (its first pose is this one's
            x, y, yaw).
        path: [N, 3] (x, y, yaw) world, the search's path from the node nearest `pose`.
        speed: m/s along the path; timestep: s between guide poses.

    Returns:
        [T, 3] (x, y, yaw) world: positions by arc length from the pose through path[1:], yaw
        interpolated likewise (unwrapped from the pose's), the path's end last.
    """
    points = np.concatenate([np.asarray(pose, np.float64)[None, [0, 1, 3]], np.asarray(path, np.float64)[1:]])
    points[:, 2] = np.unwrap(points[:, 2])
    arc = planar_arc_length(points[:, :2])
    at = np.append(np.arange(0.0, arc[-1], speed * timestep), arc[-1])
    return np.stack([np.interp(at, arc, points[:, k]) for k in range(3)], axis=-1)


def policy_replans(attempts) -> int:
    """Searches after the first that the policy walked (what `max_replans` bounds), of `Attempt`s."""
    return sum(attempt.kind == "policy" for attempt in attempts) - 1


def _fmt(xy) -> str:
    return "(" + ", ".join(f"{float(v):.2f}" for v in np.asarray(xy).reshape(-1)) + ")"


class Navigator:
    """The terrain's lattice and the policy, ready for any number of queries (host).

    Args:
        policy: a `leas_jax.training.Policy` (its env fixes the heightfield, the
            reachability condition and the timestep).
        terrain: a `leas_jax.terrain.Terrain`.
        config: `NavigateConfig`.
        progress: None, or a function str -> None that receives one line per step.
    """

    def __init__(self, policy, terrain, config: NavigateConfig = NavigateConfig(), progress=None):
        from leas_jax.env import heightfield_from_terrain

        self.policy, self.terrain, self.config = policy, terrain, config
        self.env = policy.config.env
        self.say = progress or (lambda message: None)
        self.field = heightfield_from_terrain(terrain, self.env)
        self._lattice = None
        self.lattice_seconds = 0.0

    @property
    def lattice(self):
        """The terrain's `Lattice` (built on first use, with the penalty-free search graph)."""
        if self._lattice is None:
            began = time.perf_counter()
            cfg = self.config
            self._lattice = build_lattice(
                self.field,
                self.terrain.bounds,
                self.env.nominal_root_height,
                self.env.reachability,
                cfg.lattice,
            )
            self.graph = graph(self._lattice, None, cfg.search)
            self.lattice_seconds = time.perf_counter() - began
            nx, ny, nh = self._lattice.shape
            self.say(
                f"lattice: {nx} x {ny} cells x {nh} headings at {cfg.lattice.resolution:g} m, "
                f"{100 * self._lattice.node_valid.mean():.1f} % valid, {100 * self._lattice.doubtful.mean():.1f} % "
                f"doubtful ({self.lattice_seconds:.2f} s)"
            )
        return self._lattice

    # ---- inputs -------------------------------------------------------------------------
    def query(self, start, goal, speed: float = 0.0, via=None, name: str = "--start") -> Query:
        """A checked `Query` from (x, y, yaw) or (x, y, z, yaw) and a goal (x, y).

        Raises:
            UsageError: the start or the goal lies off the terrain, or the start pose fails
                the reachability condition (the message names the parts that fail).
        """
        from leas_jax.steering.leas import start_poses

        start = np.asarray(start, np.float64).reshape(-1)
        if len(start) not in (3, 4) or not np.isfinite(start).all():
            raise UsageError(f"{name}: expected x, y, yaw (finite), got {start.tolist()}")
        route = np.asarray([] if via is None else via, np.float64).reshape(-1, 2)
        route = np.concatenate([route, np.asarray(goal, np.float64).reshape(1, 2)])
        lo, hi = self.terrain.bounds
        for label, xy in [(name, start[:2])] + [("--goal", p) for p in route]:
            if not (np.isfinite(xy).all() and np.all(xy >= lo) and np.all(xy <= hi)):
                raise UsageError(
                    f"{label}: {_fmt(xy)} lies off the terrain {self.terrain.name} "
                    f"(bounds {lo.tolist()} .. {hi.tolist()})"
                )
        pose = start_poses(
            self.field, np.array([start[0], start[1], start[-1]]), self.env.nominal_root_height
        )[0]
        failing = self._failing_terms(pose)
        if failing:
            raise UsageError(
                f"{name}: the start {_fmt(start)} is in collision or unsupported: the root pose "
                f"fails the reachability condition ({', '.join(failing)})"
            )
        return Query(np.asarray(pose, np.float64), float(speed), route)

    def _start_condition(self):
        """The condition a start must pass: the lattice's plausible set where it offers doubtful
        ground (the generator judges the rest), else the env's reachability condition."""
        lattice = self.config.lattice
        if not lattice.offer_doubtful:
            return self.env.reachability
        return relaxed_reachability(self.env.reachability, lattice.relaxed_foothold_spread)

    def _failing_terms(self, pose) -> list[str]:
        """Names of the parts of the start condition a pose [4] fails (solid_ground: the void
        under it)."""
        import jax.numpy as jnp

        from leas_jax.steering.baselines import lift_checked

        condition = self._start_condition()
        parts = _jitted_terms()(self.field, jnp.asarray(pose, jnp.float32), condition)
        failing = [k for k, v in parts.items() if not bool(v)]
        _, ok = lift_checked(
            self.field, np.asarray(pose)[None, [0, 1, 3]], self.env.nominal_root_height, condition
        )
        if not ok[0] and not failing:
            failing = ["solid_ground"]
        return failing

    # ---- the parts of one attempt --------------------------------------------------------
    def _route_search(self, state: _State, pose, route) -> SearchResult:
        """Search leg by leg through the route points [R, 2] from a pose (x, y, z, yaw), each leg
        from where the last one ended; stops at the first leg that fails (its reason is the
        result's). Raises ValueError when the pose has no valid lattice node near it."""
        cfg = self.config.search
        lattice = self.lattice
        changed = state.penalty.any() or state.trusted.any()
        adjacency = graph(lattice, state.penalty, cfg, state.trusted) if changed else self.graph
        paths, waypoints, current, cost = [], [], np.asarray(pose, np.float64)[[0, 1, 3]], 0.0
        for point in route:
            leg = search(lattice, current, point, cfg, adjacency=adjacency)
            cost += leg.cost
            paths.append(leg.path if not paths else leg.path[1:])
            # a reached leg ends at the point itself (its goal node lies up to goal_radius off it,
            # and the policy stops within switch distance of its last waypoint)
            waypoints.append(
                np.concatenate([leg.waypoints[:-1], point[None]]) if leg.reached else leg.waypoints
            )
            current = leg.path[-1]
            if not leg.reached:
                break
        path = np.concatenate(paths)
        return SearchResult(
            reached=leg.reached,
            reason=leg.reason,
            path=path,
            waypoints=np.concatenate(waypoints),
            cost=cost,
            length=float(np.hypot(*np.diff(path[:, :2], axis=0).T).sum()) if len(path) > 1 else 0.0,
            end_distance=leg.end_distance,
        )

    def _rollout(self, poses: np.ndarray, speeds: np.ndarray, waypoints: list) -> list[np.ndarray]:
        """Guides of the policy from poses [N, 4] along each waypoint list [W_n, 2] (one jitted batch)."""
        from leas_jax.steering.horizon import leas_horizon
        from leas_jax.steering.leas import rollout_batch

        cfg = self.config
        width = 16 * math.ceil(max(len(w) for w in waypoints) / 16)
        padded = np.stack([np.concatenate([w, np.repeat(w[-1:], width - len(w), axis=0)]) for w in waypoints])
        steps = max(
            leas_horizon(
                p[:2],
                w,
                self.env.target_speed,
                self.env.timestep,
                self.env.episode_length,
                cfg.horizon_factor,
            )
            for p, w in zip(poses, waypoints)
        )
        steps = cfg.horizon_quantum * math.ceil(steps / cfg.horizon_quantum)
        out = rollout_batch(
            self.policy,
            self.field,
            poses,
            padded,
            speeds,
            max_steps=steps,
            stop_at_target=True,
            stop_at_invalid=False,
        )
        return [out.guide(n).astype(np.float64) for n in range(len(poses))]

    def _remaining_route(self, query: Query, prefix: np.ndarray) -> np.ndarray:
        """Route points not yet passed by the guide prefix [k, 4] (in order; the goal always stays)."""
        index = 0
        for xy in prefix[:, :2]:
            if index < len(query.route) - 1 and np.hypot(*(xy - query.route[index])) < self.config.via_radius:
                index += 1
        return query.route[index:]

    # ---- the loop ------------------------------------------------------------------------
    def run(
        self, queries, workers: int = 0, pool=None, address: str | None = None, done=None
    ) -> list[NavigationResult]:
        """Answer every query (host). Generator tasks of different queries run in parallel.

        Args:
            queries: `Query` objects (see `query`).
            workers: contact-generator processes when no `pool` is given (0: in this process).
            pool: a `ValidationPool` of this terrain with return_plans=True, or None.
            address: Ray address for a pool made here (None: local).
            done: None, or a function (query index, NavigationResult) -> None called as each
                query ends.

        Returns:
            One `NavigationResult` per query, in order.
        """
        from leas_jax.contacts.validation.pool import ValidationPool

        if pool is None:
            with ValidationPool(
                self.terrain,
                workers=workers,
                config=self.config.generator,
                address=address,
                return_plans=True,
            ) as own:
                return self.run(queries, pool=own, done=done)
        self._done = done or (lambda k, result: None)
        cells = self.lattice.shape[:2]
        states = [_State(q, np.zeros(cells), np.zeros(cells, bool)) for q in queries]
        for k, state in enumerate(states):
            began = time.perf_counter()
            try:
                state.search = self._route_search(state, state.query.start, state.query.route)
            except ValueError as exc:
                raise UsageError(f"--start: {_fmt(state.query.start[[0, 1, 3]])}: {exc}") from None
            state.seconds["search"] += time.perf_counter() - began
            self._said_search(k, state)
        began = time.perf_counter()
        guides = self._rollout(
            np.stack([s.query.start for s in states]),
            np.array([s.query.speed for s in states]),
            [s.search.waypoints for s in states],
        )
        share = (time.perf_counter() - began) / max(1, len(states))
        pending = {}
        for k, (state, guide) in enumerate(zip(states, guides)):
            state.seconds["rollout"] += share
            state.guide, state.segment_begin = self._cut_stall(k, state, guide), 0
            guide = state.guide
            state.path, state.waypoints = state.search.path, state.search.waypoints
            self.say(f"query {k}: rollout {len(guide)} poses ({share:.2f} s)")
            pending[pool.submit([guide], self.env.timestep)] = k
        while pending:
            done, _ = concurrent.futures.wait(list(pending), return_when=concurrent.futures.FIRST_COMPLETED)
            for future in sorted(done, key=lambda f: pending[f]):
                k = pending.pop(future)
                next_guide = self._after_validation(k, states[k], future.result()[0])
                if next_guide is not None:
                    pending[pool.submit([next_guide], self.env.timestep)] = k
        return [s.done for s in states]

    def _said_search(self, k: int, state: _State) -> None:
        found = state.search
        end = (
            "reaches the goal"
            if found.reached
            else f"ends {found.end_distance:.2f} m from the goal ({found.reason})"
        )
        self.say(
            f"query {k}: search {found.length:.2f} m, {len(found.waypoints)} waypoints, {end} "
            f"({state.seconds['search']:.2f} s so far)"
        )

    def _after_validation(self, k: int, state: _State, result) -> np.ndarray | None:
        """Record the generator's answer on the state's guide; return the next guide or None (done)."""
        from leas_jax.contacts import metrics

        guide, query, cfg = state.guide, state.query, self.config
        state.seconds["contact_planning"] += float(result.seconds)
        if state.search.reason is not None and state.unreachable is None:
            state.unreachable = state.search.reason
        if result.error is not None:
            return self._finish(
                state, reasons.GENERATOR_ERROR, f"contact generator failed: {result.error}", k
            )
        last, total = int(result.last_valid_index), len(guide)
        outcome = metrics.outcome(guide, query.goal, result.coverage, last, plan=result.plan)
        # the plan returned: a successful one, else the one whose valid part ends nearest the goal
        if outcome.success or (last >= 0 and (state.best is None or outcome.final_distance < state.best[0])):
            state.best = (outcome.final_distance, result.plan, guide)
        if last >= 0:
            state.trusted |= self._cells_under(guide[: last + 1, :2])
        # where the generator stopped (None: it covered the whole guide, the policy stopped short)
        failure = None
        # the generator covered the whole guide, cut where the policy stalled
        policy_stalled = not outcome.success and state.stalled and last >= total - 1
        if not outcome.success and 0 <= last < total - 1:
            generator = cfg.generator or GeneratorConfig()
            failure = _ahead(guide[min(last + generator.planning_stride(self.env.timestep), total - 1)], cfg)
        elif policy_stalled:
            failure = _ahead(guide[-1], cfg)
        state.attempts.append(
            Attempt(
                state.segment_begin,
                total,
                last,
                float(result.coverage),
                None if failure is None else (float(failure[0]), float(failure[1])),
                state.search.reason,
                state.kind,
            )
        )
        self.say(
            f"query {k}: contact planning covers {100 * result.coverage:.1f} % of {total} poses, "
            f"last valid {last} ({result.seconds:.2f} s)"
        )
        if outcome.success:
            return self._finish(state, reasons.REACHED, "reached the goal", k)
        if last < 0:
            return self._finish(
                state,
                reasons.NO_STANCE,
                f"the contact generator finds no first posture at the start {_fmt(guide[0, :2])}",
                k,
            )
        if last >= total - 1 and state.search.reason is not None:
            return self._finish(state, state.search.reason, self._unreachable_text(state), k)
        # the generator stopped on the policy's guide: its searched path is walked next, unpenalised
        fallback = cfg.path_fallback and failure is not None and not policy_stalled and state.kind == "policy"
        if policy_replans(state.attempts) >= cfg.max_replans and not fallback:
            if state.unreachable is not None:
                return self._finish(state, state.unreachable, self._unreachable_text(state), k)
            where = guide[-1, :2] if failure is None else failure
            who = "the policy still stalls" if policy_stalled else "the contact generator still stops"
            return self._finish(
                state,
                reasons.REPLAN_LIMIT,
                f"{who} near {_fmt(where)} after {cfg.max_replans} replans",
                k,
            )
        if failure is None:  # the whole guide is verified: walk on from its end
            begin = total - 1
        else:  # penalise the failed region (unless the path is tried first), search again before it
            if not fallback:
                self._penalise(state, failure)
            walked = planar_arc_length(guide[: last + 1, :2])
            begin = int(np.searchsorted(walked, walked[-1] - cfg.backoff_distance, side="right")) - 1
            begin = max(0, begin)
        pose = guide[begin]
        speed = (
            float(np.hypot(*(guide[begin, :2] - guide[begin - 1, :2])) / self.env.timestep)
            if begin > 0
            else query.speed
        )
        avoid = "walking on" if failure is None else f"avoiding {_fmt(failure)}"
        if fallback:
            avoid = f"along the searched path through {_fmt(failure)}"
        if policy_stalled:
            avoid += " (the policy stalled there)"
        self.say(f"query {k}: replan {len(state.attempts)} from guide pose {begin} {_fmt(pose[:2])}, {avoid}")
        began = time.perf_counter()
        try:
            state.search = self._route_search(state, pose, self._remaining_route(query, guide[: begin + 1]))
        except ValueError:  # the verified pose has no valid lattice node near it: nothing to search from
            return self._finish(
                state,
                reasons.REPLAN_LIMIT,
                f"no valid lattice node near the verified pose {_fmt(pose[:2])}",
                k,
            )
        state.seconds["search"] += time.perf_counter() - began
        self._said_search(k, state)
        began = time.perf_counter()
        if fallback:
            segment = self._path_segment(pose, state.search.path)
            state.stalled = False
        else:
            (rollout,) = self._rollout(pose[None], np.array([speed]), [state.search.waypoints])
            segment = self._cut_stall(k, state, rollout)
        state.seconds["rollout"] += time.perf_counter() - began
        state.kind = "path" if fallback else "policy"
        state.path, state.waypoints = state.search.path, state.search.waypoints
        state.guide = np.concatenate([guide[:begin], segment])
        state.segment_begin = begin
        return state.guide

    def _penalise(self, state: _State, failure: np.ndarray) -> None:
        """Add `failure_penalty` to the cells within `failure_radius` of failure [2] (world)."""
        cfg = self.config
        cells = self.lattice.position(
            np.stack(np.meshgrid(*map(np.arange, self.lattice.shape[:2]), indexing="ij"), -1)
        )
        state.penalty += cfg.failure_penalty * (
            np.hypot(*(cells - failure).transpose(2, 0, 1)) <= cfg.failure_radius
        )

    def _path_segment(self, pose: np.ndarray, path: np.ndarray) -> np.ndarray:
        """Guide segment [T, 4] from a verified guide pose [4] (kept as it is, first) along a
        searched path [N, 3] (`path_guide`), the root at the nominal height above the terrain."""
        from leas_jax.steering.baselines import lift

        planar = path_guide(pose, path, self.env.target_speed, self.env.timestep)
        segment = lift(self.field, planar, self.env.nominal_root_height)
        segment[0] = pose
        return segment

    def _cut_stall(self, k: int, state: _State, segment: np.ndarray) -> np.ndarray:
        """A new rollout segment [T, 4], cut after the pose where the policy stalled
        (`stall_start`; `state.stalled` says whether it was)."""
        cfg = self.config
        begin = None
        if cfg.stall_time is not None and np.hypot(*(segment[-1, :2] - state.query.goal)) > SUCCESS_RADIUS:
            steps = int(math.ceil(cfg.stall_time / self.env.timestep))
            begin = stall_start(segment, steps, cfg.stall_radius)
        state.stalled = begin is not None
        if begin is None:
            return segment
        self.say(
            f"query {k}: the policy stalls at {_fmt(segment[begin, :2])} for the last "
            f"{(len(segment) - 1 - begin) * self.env.timestep:.0f} s of its rollout: cut there"
        )
        return segment[: begin + 1]

    def _cells_under(self, xy: np.ndarray) -> np.ndarray:
        """[nx, ny] bool: lattice cells within `trust_radius` of any of the points [P, 2] (world)."""
        lattice, radius = self.lattice, self.config.trust_radius
        mask = np.zeros(lattice.shape[:2], bool)
        reach = int(math.ceil(radius / lattice.resolution))
        centre = lattice.cell_of(xy)  # [P, 2]
        for di in range(-reach, reach + 1):
            for dj in range(-reach, reach + 1):
                cells = centre + np.array([di, dj])
                near = lattice.inside(cells) & (np.hypot(*(lattice.position(cells) - xy).T) <= radius + 1e-9)
                mask[cells[near, 0], cells[near, 1]] = True
        return mask

    def _unreachable_text(self, state: _State) -> str:
        goal = state.query.goal
        if state.unreachable == reasons.GOAL_INVALID:
            return (
                f"goal {_fmt(goal)} cannot be reached: no valid root pose within "
                f"{self.config.search.goal_radius:g} m of it (inside an obstacle or over the void)"
            )
        return f"goal {_fmt(goal)} cannot be reached: no lattice path from the start leads there"

    def _finish(self, state: _State, reason: str, text: str, k: int) -> None:
        if state.best is None:
            plan, guide, distance = None, None, float("nan")
        else:
            distance, plan, guide = state.best
        if reason != reasons.REACHED:
            ends = (
                "no verified posture"
                if plan is None
                else f"the best verified plan ends {distance:.2f} m from the goal"
            )
            text = f"{text}; {ends}"
        state.seconds["lattice"] = self.lattice_seconds
        state.done = NavigationResult(
            success=reason == reasons.REACHED,
            reason=reason,
            message=text,
            plan=plan,
            guide=guide,
            waypoints=state.waypoints,
            path=state.path,
            replans=policy_replans(state.attempts),
            attempts=tuple(state.attempts),
            final_distance=float(distance),
            seconds=dict(state.seconds),
            timestep=self.env.timestep,
        )
        self.say(f"query {k}: {reason}: {text}")
        self._done(k, state.done)
        return None


def navigate(
    policy,
    terrain,
    start,
    goal,
    config: NavigateConfig = NavigateConfig(),
    *,
    speed: float = 0.0,
    via=None,
    workers: int = 0,
    progress=None,
) -> NavigationResult:
    """A verified whole-body contact plan from a start to a goal (host; JAX and the generator inside).

    Args:
        policy: a `leas_jax.training.Policy` (`leas_jax.training.load_policy`).
        terrain: a `leas_jax.terrain.Terrain`.
        start: (x, y, yaw) world, m and rad (or (x, y, z, yaw); z is set on the terrain).
        goal: (x, y) world, m.
        config: `NavigateConfig`.
        speed: initial speed along the heading, m/s.
        via: optional [V, 2] points to pass, in order, before the goal.
        workers: contact-generator processes (0: in this process).
        progress: None or a function str -> None (one line per step).

    Returns:
        `NavigationResult`; `seconds["total"]` is the wall time of the call.

    Raises:
        UsageError: the start or goal is off the terrain, or the start pose is in collision.
    """
    began = time.perf_counter()
    navigator = Navigator(policy, terrain, config, progress)
    (result,) = navigator.run([navigator.query(start, goal, speed, via)], workers=workers)
    result.seconds["total"] = time.perf_counter() - began
    return result
