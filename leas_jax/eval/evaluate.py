"""The paper's experiments: starts, guides per steering method, contact-plan validation, metrics.

`evaluate(...)` runs scenarios end to end (host code; the guides of LeaS and
the RRT's validity checks are jitted JAX):

1. load the scenario's terrain, draw seeded starts per cell (`scenarios`);
2. build one guide per start and method: RBLin, RBKino (through the
   waypoints on the circuit), RBKino+RRT (one RRT per start, shared by
   `rbkino_rrt` and `leas_rrt`), LeaS to the target (or along the waypoints),
   LeaS along the RRT's waypoints; navigate (`leas_jax.navigate`: the lattice
   search's waypoints for LeaS, validated and replanned in its own closed loop,
   so its trajectories arrive with their outcome); RBKino's continuous paths (RBKino,
   RBKino+RRT) sampled every `BaselineConfig.rbkino_timestep` (0.01 s, as HPP's contact
   generator samples a path), the others one pose every env timestep;
3. validate every other guide with the contact generator in one worker pool per
   terrain, with a progress bar;
4. compute coverage and success per trajectory (`metrics`) and aggregate;
5. with `motion_plans`, make a few covered LeaS and navigate plans into whole-body
   motions and simulate them in MuJoCo (`leas_jax.eval.motions`).

A method that produces no guide for a start (the RRT found no path within
its budget) counts as coverage 0, not a success, with error "rrt: no path";
`leas_rrt` then has no waypoints to follow either, so both RRT methods are
compared on the same planner output (paper Fig. 8).
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import time
from dataclasses import dataclass
from dataclasses import field as dataclass_field
from pathlib import Path

import numpy as np

from leas_jax.contacts import metrics
from leas_jax.errors import UsageError
from leas_jax.eval.scenarios import (
    DEFAULT_METHODS,
    LEAS_METHODS,
    METHODS,
    RRT_METHODS,
    Cell,
    Starts,
    cells_for,
    draw_starts,
    route,
)
from leas_jax.steering.horizon import leas_horizon
from leas_jax.terrain.generate import SCENARIOS, scenario_file


@dataclass
class Trajectory:
    """One start, one method: its guide, the generator's answer, the metrics.

    Attributes:
        cell: index into the scenario's cells.
        method: steering method name.
        start: [4] (x, y, z, yaw) world.
        speed: initial speed (m/s).
        yaw_offset_deg: start yaw minus the direction to the first target (deg).
        guide: [T, 4] world, or None when the method produced none.
        waypoints: [W, 2] waypoints the method followed (RRT, circuit, navigate), or None.
        outcome: `metrics.Outcome` once validated.
        error: why the method produced no guide, or None.
        replans: navigate's searches after the first (None for the other methods).
        timestep: s between the guide's poses (None: the env's, `validate`'s `timestep`);
            RBKino's continuous paths are sampled finer (`BaselineConfig.rbkino_timestep`).
        plan: the generator's `ContactPlan` once validated (None: no plan).
    """

    cell: int
    method: str
    start: np.ndarray
    speed: float
    yaw_offset_deg: float
    guide: np.ndarray | None
    waypoints: np.ndarray | None = None
    outcome: metrics.Outcome | None = None
    error: str | None = None
    replans: int | None = None  # navigate: searches after the first
    timestep: float | None = None
    plan: object | None = None


@dataclass
class ScenarioResult:
    """All trajectories of one scenario, with its terrain and cells; `motions`: the executed
    plans' figures (`motions.run_motions`), None when no motion was asked for."""

    name: str
    terrain: object
    cells: list[Cell]
    methods: tuple[str, ...]
    trajectories: list[Trajectory] = dataclass_field(default_factory=list)
    seconds: dict = dataclass_field(default_factory=dict)
    motions: list | None = None

    def summary(self) -> dict:
        """{method: {cell name: metrics.summarize(...), "all": ...}}."""
        table = {}
        for method in self.methods:
            rows = {}
            for k, cell in enumerate(self.cells):
                rows[cell.name] = metrics.summarize(
                    t.outcome for t in self.trajectories if t.method == method and t.cell == k
                )
            rows["all"] = metrics.summarize(t.outcome for t in self.trajectories if t.method == method)
            table[method] = rows
        return table


def parse_methods(text: str | None) -> tuple[str, ...] | None:
    """'rblin,leas' -> ('rblin', 'leas'); None stays None (each scenario's paper methods)."""
    if text is None:
        return None
    names = tuple(dict.fromkeys(m.strip() for m in text.split(",") if m.strip()))
    unknown = [m for m in names if m not in METHODS]
    if not names or unknown:
        raise UsageError(
            f"--methods: unknown method(s) {', '.join(unknown) or repr(text)} "
            f"(expected a comma-separated subset of {','.join(METHODS)})"
        )
    return names


def guide_timestep(method: str, config) -> float | None:
    """s between the poses of `method`'s guides where they are not the env's (None):
    RBKino's continuous paths, sampled as HPP's contact generator samples them."""
    return config.rbkino_timestep if method in ("rbkino", "rbkino_rrt") else None


def _baseline_guides(method: str, field, starts: Starts, points: np.ndarray, config) -> list:
    """RBLin's or RBKino's guide from every start to the route `points`, one pose every
    `guide_timestep(method, config)` (else `config.timestep`)."""
    from leas_jax.steering.rbkino import rbkino, rbkino_through
    from leas_jax.steering.rblin import rblin, rblin_through

    single, through = (rblin, rblin_through) if method == "rblin" else (rbkino, rbkino_through)
    config = dataclasses.replace(config, timestep=guide_timestep(method, config) or config.timestep)
    guides = []
    for pose, speed in zip(starts.poses, starts.speeds):
        if len(points) == 1:
            guides.append(single(field, pose, points[0], float(speed), config))
        else:
            guides.append(through(field, pose, points, float(speed), config))
    return guides


_RRT_FIELD = None  # the heightfield of an RRT worker process (built once by `_rrt_worker_start`)


def _rrt_worker_start(terrain, env) -> None:
    global _RRT_FIELD
    from leas_jax.env import heightfield_from_terrain

    _RRT_FIELD = heightfield_from_terrain(terrain, env)


def _rrt_worker_plan(job):
    from leas_jax.steering.rrt import plan_rrt

    pose, target, speed, bounds, config, rrt, reach = job
    return plan_rrt(_RRT_FIELD, pose, target, speed, bounds, config, rrt, reach)


def _rrt_plans(
    field, terrain, env, starts: Starts, target, config, rrt_config, workers: int, progress: bool
) -> list:
    """One RRT search per start (seed: rrt_config.seed + start index), in `workers` processes (0: here).

    Each search is seeded and bounded by iterations (its wall-time bound is a safety net far
    above them), so the plans do not depend on the number of processes.
    """
    from tqdm.auto import tqdm

    from leas_jax.steering.rrt import plan_rrt

    jobs = [
        (
            pose,
            target,
            float(speed),
            terrain.bounds,
            config,
            dataclasses.replace(rrt_config, seed=rrt_config.seed + k),
            env.reachability,
        )
        for k, (pose, speed) in enumerate(zip(starts.poses, starts.speeds))
    ]
    bar = dict(total=len(jobs), desc="RBKino+RRT", disable=not progress, leave=False)
    if workers <= 0 or len(jobs) == 1:
        return [plan_rrt(field, *job) for job in tqdm(jobs, **bar)]
    import multiprocessing

    with concurrent.futures.ProcessPoolExecutor(
        min(workers, len(jobs)),
        multiprocessing.get_context("spawn"),
        initializer=_rrt_worker_start,
        initargs=(terrain, env),
    ) as pool:
        return list(tqdm(pool.map(_rrt_worker_plan, jobs), **bar))


def _leas_guides(
    policy, field, starts: Starts, routes: list[np.ndarray], max_steps: int, stop_at_invalid: bool
) -> list:
    from leas_jax.steering.leas import rollout_batch

    width = max(len(r) for r in routes)
    # Pad every route to the same length by repeating its last point (rollout_batch's convention).
    padded = np.stack([np.concatenate([r, np.repeat(r[-1:], width - len(r), axis=0)]) for r in routes])
    result = rollout_batch(
        policy,
        field,
        starts.poses,
        padded,
        starts.speeds,
        max_steps=max_steps,
        stop_at_invalid=stop_at_invalid,
    )
    return [result.guide(n).astype(np.float64) for n in range(len(starts.poses))]


def _navigate_trajectories(
    policy, terrain, starts: Starts, points: np.ndarray, workers: int, address, progress: bool, config=None
) -> tuple[list, dict]:
    """Navigate from every start through the route `points` (closed loop, its own pool;
    `config`: a `NavigateConfig`, None for its defaults).

    Returns:
        ([(guide or None, waypoints, outcome, replans, plan or None)] per start, seconds per
        navigate part summed).
    """
    from tqdm.auto import tqdm

    from leas_jax.navigate.loop import NavigateConfig, Navigator

    navigator = Navigator(policy, terrain, config or NavigateConfig())
    queries = [
        navigator.query(pose, points[-1], float(speed), points[:-1])
        for pose, speed in zip(starts.poses, starts.speeds)
    ]
    with tqdm(total=len(queries), desc="navigate", disable=not progress, leave=False) as bar:
        answers = navigator.run(queries, workers=workers, address=address, done=lambda k, r: bar.update(1))
    out, seconds = [], {"navigate_lattice": navigator.lattice_seconds}
    for answer in answers:
        for part in ("search", "rollout", "contact_planning"):
            seconds[f"navigate_{part}"] = seconds.get(f"navigate_{part}", 0.0) + answer.seconds[part]
        if answer.plan is None:
            outcome = metrics.outcome(None, points[-1], 0.0, -1, error=f"navigate: {answer.message}")
        else:
            plan = answer.plan
            outcome = metrics.outcome(
                answer.guide, points[-1], plan.coverage, plan.last_valid_index, plan=plan
            )
        out.append((answer.guide, answer.waypoints, outcome, answer.replans, answer.plan))
    return out, seconds


def build_trajectories(
    name: str,
    terrain,
    field,
    cells: list[Cell],
    methods,
    policy,
    n_starts: int,
    config,
    rrt_config,
    progress: bool = True,
    env=None,
    rrt_workers: int = 0,
    leas_stop_at_invalid: bool = False,
    address: str | None = None,
    navigate_config=None,
) -> tuple[list[Trajectory], dict]:
    """Starts and guides of every cell and method of one scenario (no validation yet, except
    navigate's: its closed loop validates, its trajectories come with their outcome).

    `env` (default: the policy's, else EnvConfig()) is what `field` was built with;
    `rrt_workers` processes run the RRT searches and navigate's contact generator (0: in
    this process; `address`: navigate's generator on that Ray cluster);
    `leas_stop_at_invalid`: LeaS paths end before the first pose the reachability
    condition rejects (see `rollout_batch`; default: they roll on, see `evaluate`).

    Returns:
        (trajectories, seconds spent per method building guides).
    """
    from leas_jax.steering.rrt import path_guide

    env = env or policy_env(policy)
    scenario = terrain.scenario
    points = route(scenario)
    target = np.asarray(scenario.target, np.float64)
    trajectories, seconds = [], {m: 0.0 for m in methods}
    for k, cell in enumerate(cells):
        starts = draw_starts(
            scenario, cell, n_starts, scenario.seed + k, field, config.nominal_root_height, env.reachability
        )

        def add(method, guides, waypoints=None, errors=None, k=k, starts=starts):
            for n in range(len(starts.poses)):
                trajectories.append(
                    Trajectory(
                        cell=k,
                        method=method,
                        start=starts.poses[n],
                        speed=float(starts.speeds[n]),
                        yaw_offset_deg=float(starts.yaw_offsets_deg[n]),
                        guide=guides[n],
                        waypoints=None if waypoints is None else waypoints[n],
                        error=None if errors is None else errors[n],
                        timestep=guide_timestep(method, config),
                    )
                )

        for method in ("rblin", "rbkino"):
            if method in methods:
                began = time.perf_counter()
                add(
                    method,
                    _baseline_guides(method, field, starts, points, config),
                    [points] * n_starts if len(points) > 1 else None,
                )
                seconds[method] += time.perf_counter() - began
        plans = None
        if any(m in methods for m in RRT_METHODS):
            began = time.perf_counter()
            plans = _rrt_plans(field, terrain, env, starts, target, config, rrt_config, rrt_workers, progress)
            seconds["rrt_search"] = seconds.get("rrt_search", 0.0) + time.perf_counter() - began
        if "rbkino_rrt" in methods:
            fine = dataclasses.replace(config, timestep=guide_timestep("rbkino_rrt", config))
            add(
                "rbkino_rrt",
                [
                    path_guide(p.states, float(pose[3]), field, fine, env.reachability)[0]
                    if p.success
                    else None
                    for p, pose in zip(plans, starts.poses)
                ],
                [p.waypoints if p.success else None for p in plans],
                [None if p.success else "rrt: no path" for p in plans],
            )
        horizon = policy.config.env.episode_length if policy is not None else 400
        if "leas" in methods:
            began = time.perf_counter()
            steps = max(
                leas_horizon(p[:2], points, config.target_speed, config.timestep, horizon)
                for p in starts.poses
            )
            add(
                "leas",
                _leas_guides(policy, field, starts, [points] * n_starts, steps, leas_stop_at_invalid),
                [points] * n_starts if len(points) > 1 else None,
            )
            seconds["leas"] += time.perf_counter() - began
        if "leas_rrt" in methods:
            began = time.perf_counter()
            ok = [n for n, p in enumerate(plans) if p.success]
            guides = [None] * n_starts
            if ok:
                sub = Starts(starts.poses[ok], starts.speeds[ok], starts.yaw_offsets_deg[ok])
                routes = [plans[n].waypoints for n in ok]
                steps = max(
                    leas_horizon(
                        starts.poses[n, :2], plans[n].waypoints, config.target_speed, config.timestep, horizon
                    )
                    for n in ok
                )
                for n, guide in zip(
                    ok, _leas_guides(policy, field, sub, routes, steps, leas_stop_at_invalid)
                ):
                    guides[n] = guide
            add(
                "leas_rrt",
                guides,
                [p.waypoints if p.success else None for p in plans],
                [None if p.success else "rrt: no path" for p in plans],
            )
            seconds["leas_rrt"] += time.perf_counter() - began
        if "navigate" in methods:
            began = time.perf_counter()
            answers, parts = _navigate_trajectories(
                policy, terrain, starts, points, rrt_workers, address, progress, navigate_config
            )
            for n, (guide, waypoints, outcome, replans, plan) in enumerate(answers):
                trajectories.append(
                    Trajectory(
                        cell=k,
                        method="navigate",
                        start=starts.poses[n],
                        speed=float(starts.speeds[n]),
                        yaw_offset_deg=float(starts.yaw_offsets_deg[n]),
                        guide=guide,
                        waypoints=waypoints,
                        outcome=outcome,
                        error=outcome.error,
                        replans=replans,
                        plan=plan,
                    )
                )
            seconds["navigate"] += time.perf_counter() - began
            for part, value in parts.items():
                seconds[part] = seconds.get(part, 0.0) + value
    order = {m: i for i, m in enumerate(methods)}
    trajectories.sort(key=lambda t: (t.cell, order[t.method]))
    return trajectories, seconds


def validate(
    terrain,
    trajectories: list[Trajectory],
    timestep: float,
    workers: int,
    progress: bool = True,
    desc: str = "contact planning",
    address: str | None = None,
    config=None,
) -> None:
    """Run the contact generator on every guide (one pool), fill each trajectory's `outcome`
    (trajectories that arrive with one, navigate's, are left as they are). Host-only.

    `timestep`: s between guide poses, where a trajectory does not set its own.

    `address`: a Ray cluster for the pool (`ValidationPool(address=...)`); None for local processes.
    `config`: the generator's `GeneratorConfig` (None: its defaults).
    """
    from tqdm.auto import tqdm

    from leas_jax.contacts.validation.pool import ValidationPool

    target = np.asarray(terrain.scenario.target, np.float64)
    trajectories = [t for t in trajectories if t.outcome is None]
    todo = [t for t in trajectories if t.guide is not None and t.error is None]
    for t in trajectories:
        if t.guide is None or t.error is not None:
            t.outcome = metrics.outcome(None, target, 0.0, -1, error=t.error or "no guide")
    if not todo:
        return
    with ValidationPool(terrain, workers=workers, address=address, config=config, return_plans=True) as pool:
        futures = {pool.submit([t.guide], t.timestep or timestep): t for t in todo}
        with tqdm(total=len(todo), desc=desc, disable=not progress, leave=False) as bar:
            for future in concurrent.futures.as_completed(futures):
                t = futures[future]
                (result,) = future.result()
                t.plan = result.plan
                t.outcome = metrics.outcome(
                    t.guide,
                    target,
                    result.coverage,
                    result.last_valid_index,
                    plan=result.plan,
                    error=result.error,
                )
                bar.update(1)


def policy_for(methods, checkpoint):
    """The `Policy` of `checkpoint` when `methods` include leas, leas_rrt or navigate, else None;
    UsageError naming --checkpoint when they do and it is None."""
    if not any(m in LEAS_METHODS for m in methods):
        return None
    if checkpoint is None:
        raise UsageError("--checkpoint is required by the methods leas, leas_rrt and navigate")
    from leas_jax.training.policy import load_policy

    return load_policy(checkpoint)


def policy_env(policy):
    """The EnvConfig a scenario is run with: the policy's (None: no LeaS method), else the default."""
    from leas_jax.env import EnvConfig

    return policy.config.env if policy is not None else EnvConfig()


def default_workers() -> int:
    """Processes for the contact generator and the RRT searches: one per CPU this process may use
    (the main process only waits while they work)."""
    from leas_jax.contacts.validation.pool import available_cpus

    return available_cpus()


def run_scenario(
    name: str,
    terrain,
    methods,
    policy,
    n_starts: int | None,
    workers: int,
    config=None,
    rrt_config=None,
    progress: bool = True,
    address: str | None = None,
    leas_stop_at_invalid: bool = False,
    navigate_config=None,
    generator_config=None,
) -> ScenarioResult:
    """Starts, guides, validation and metrics of one scenario.

    Args:
        name: scenario name (`ground` runs Table II's nine cells).
        terrain: a `Terrain` with a `[scenario]` table.
        methods: method names.
        policy: a `Policy` (needed by leas and leas_rrt) or None.
        n_starts: starts per cell (default the scenario table's n_starts).
        workers: contact-generator processes (0: in-process).
        config: `BaselineConfig` (default: from the policy's env, else the env defaults).
        rrt_config: `RRTConfig` (the seed of start k is its seed + k).
        progress: show progress bars.
        address: a Ray cluster address for the contact generator (None: local processes).
        leas_stop_at_invalid: LeaS paths end before the first pose the reachability
            condition rejects (False: the contact generator alone judges them).
        navigate_config: `NavigateConfig` of the navigate method (None: its defaults).
        generator_config: `GeneratorConfig` of every method's contact planning, navigate's
            included (replacing its `NavigateConfig.generator`); None: the generator's defaults.
    """
    import dataclasses

    from leas_jax.env import heightfield_from_terrain
    from leas_jax.steering.baselines import BaselineConfig
    from leas_jax.steering.rrt import RRTConfig

    if terrain.scenario is None:
        raise UsageError(f"{terrain.path or terrain.name}: the terrain has no [scenario] table")
    env = policy_env(policy)
    config = config or BaselineConfig.from_env(env)
    field = heightfield_from_terrain(terrain, env)
    if generator_config is not None and "navigate" in methods:
        from leas_jax.navigate.loop import NavigateConfig

        navigate_config = dataclasses.replace(navigate_config or NavigateConfig(), generator=generator_config)
    cells = cells_for(name, terrain.scenario)
    n = int(n_starts or terrain.scenario.n_starts)
    result = ScenarioResult(name, terrain, cells, tuple(methods))
    result.trajectories, result.seconds = build_trajectories(
        name,
        terrain,
        field,
        cells,
        methods,
        policy,
        n,
        config,
        rrt_config or RRTConfig(),
        progress,
        env,
        rrt_workers=workers or 0,
        leas_stop_at_invalid=leas_stop_at_invalid,
        address=address,
        navigate_config=navigate_config,
    )
    began = time.perf_counter()
    validate(
        terrain,
        result.trajectories,
        config.timestep,
        workers,
        progress,
        desc=f"{name}: contact planning",
        address=address,
        config=generator_config,
    )
    result.seconds["contact_planning"] = time.perf_counter() - began
    return result


def evaluate(
    scenarios,
    methods=None,
    checkpoint=None,
    out=None,
    n_starts: int | None = None,
    workers: int | None = None,
    terrain_file=None,
    progress: bool = True,
    rrt_config=None,
    figures: bool = True,
    address: str | None = None,
    leas_stop_at_invalid: bool = False,
    rbkino_timestep: float | None = None,
    motion_plans: int = 0,
    navigate_config=None,
    generator_config=None,
) -> dict:
    """Run scenarios and write results.json, table.md, table.csv and figures into `out`.

    Args:
        scenarios: names from SCENARIOS, or ["all"]; ignored when `terrain_file` is given.
        methods: method names, or None for each scenario's paper methods.
        checkpoint: run directory or policy.ckpt (required by leas / leas_rrt).
        out: output directory (None: write nothing).
        n_starts: starts per cell (default each scenario table's).
        workers: contact-generator and RRT processes (None: one per CPU, or the Ray
            cluster's CPUs with `address`; 0: in-process).
        terrain_file: any terrain file with a [scenario] table, run as one scenario.
        progress: progress bars.
        rrt_config: `RRTConfig`.
        figures: write PNG figures.
        address: contact generator on a Ray cluster ("ray://HOST:PORT", "auto",
            "local"; see `leas_jax.contacts.validation.ray_backend`); None: local processes.
        leas_stop_at_invalid: end LeaS paths before the first pose the reachability
            condition rejects, as training episodes end. By default (False) the policy
            rolls on through such poses and the contact generator alone judges its
            path, as it judges the baselines' paths, which nothing cuts either (the
            paper's RBLin paths "lead inside the hole", §IV-B.2). The condition is a
            training proxy of the generator (studies/reachability_calibration.py:
            ~85 % specificity, and it rejects poses the generator walks through: 8 of
            the shipped policy's 10 circuit paths meet a rejected pose on a step down
            that the generator then walks).
        rbkino_timestep: s between the poses of RBKino's and RBKino+RRT's paths (None:
            `BaselineConfig.rbkino_timestep`, 0.01 s as HPP's contact generator samples a path).
        motion_plans: per scenario and method among leas and navigate, make at most this
            many plans that cover their guide into motions and simulate them in MuJoCo
            (`leas_jax.eval.motions`; results.json's `motion`, table.md's motion table; 0: none).
        navigate_config: `NavigateConfig` of the navigate method (None: its defaults).
        generator_config: `GeneratorConfig` of every method's contact planning (`run_scenario`;
            None: its defaults). `leas evaluate --motion` checks the transitions a motion needs.

    Returns:
        the results dictionary written to results.json.
    """
    from leas_jax.eval import figures as figures_module
    from leas_jax.eval import tables
    from leas_jax.steering.baselines import BaselineConfig
    from leas_jax.terrain import load_terrain

    began = time.perf_counter()
    if terrain_file is not None:
        terrain = load_terrain(terrain_file)
        if terrain.scenario is None:
            raise UsageError(f"--terrain {terrain_file}: no [scenario] table (docs/design.md §4)")
        jobs = [(terrain.name, terrain)]
    else:
        names = list(SCENARIOS) if "all" in scenarios else list(dict.fromkeys(scenarios))
        jobs = [(name, load_terrain(scenario_file(name))) for name in names]
    wanted = {
        name: tuple(methods) if methods else DEFAULT_METHODS.get(name, ("rblin", "rbkino", "leas"))
        for name, _ in jobs
    }
    if n_starts is not None and n_starts < 1:
        raise UsageError(f"--n-starts: expected a positive integer, got {n_starts}")
    policy = policy_for({m for ms in wanted.values() for m in ms}, checkpoint)
    if workers is None and address is None:
        workers = default_workers()  # on a Ray cluster, None: one actor per cluster CPU
    if workers is not None and int(workers) < 0:
        raise UsageError(f"--workers: expected an integer >= 0, got {workers}")
    config = None  # run_scenario's default, from the policy's env
    if rbkino_timestep is not None:
        config = BaselineConfig.from_env(policy_env(policy), rbkino_timestep=float(rbkino_timestep))
    results = []
    for name, terrain in jobs:
        results.append(
            run_scenario(
                name,
                terrain,
                wanted[name],
                policy,
                n_starts,
                workers,
                config,
                rrt_config=rrt_config,
                progress=progress,
                address=address,
                leas_stop_at_invalid=leas_stop_at_invalid,
                navigate_config=navigate_config,
                generator_config=generator_config,
            )
        )
        if motion_plans > 0:
            from leas_jax.eval.motions import run_motions

            began_motions = time.perf_counter()
            results[-1].motions = run_motions(
                results[-1].trajectories, motion_plans, workers or 0, progress, desc=f"{name}: motions"
            )
            results[-1].seconds["motion"] = time.perf_counter() - began_motions
    report = tables.results_dict(
        results, policy=policy, seconds=time.perf_counter() - began, leas_stop_at_invalid=leas_stop_at_invalid
    )
    # whether the plans had their lift-offs and landings checked as they were made (`--motion`)
    report["transitions_checked"] = generator_config is not None and generator_config.transitions is not None
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        tables.write_outputs(out, results, report)
        if figures:
            report["figures"] = [str(p.name) for p in figures_module.scenario_figures(results, out)]
            tables.write_json(out / "results.json", report)
    return report


def checkpoint_policies(run_dir, limit: int | None = None) -> list:
    """Deterministic policies of a run's saved training states (paper Fig. 4's learning progression).

    Args:
        run_dir: a `leas train` run directory (config.json, checkpoints/step_*.ckpt).
        limit: keep at most this many, evenly spread from first to last (None: all).

    Returns:
        list of `Policy`, oldest first; `env_steps` is the checkpoint's step count.
    """
    import json

    from leas_jax.training.checkpoint import list_checkpoints, load_state
    from leas_jax.training.config import TrainConfig
    from leas_jax.training.policy import Policy

    run_dir = Path(run_dir)
    config_file = run_dir / "config.json"
    if not config_file.is_file():
        raise UsageError(f"{run_dir}: no config.json (give a `leas train` run directory)")
    found = list_checkpoints(run_dir)
    if not found:
        raise UsageError(f"{run_dir}: no checkpoints/step_*.ckpt")
    if limit is not None and len(found) > limit:
        picks = np.unique(np.round(np.linspace(0, len(found) - 1, limit)).astype(int))
        found = [found[i] for i in picks]
    config = TrainConfig.from_dict(json.loads(config_file.read_text()))
    policies = []
    for steps, path in found:
        state = load_state(path)
        policies.append(
            Policy(
                config=config,
                normalizer=state.normalizer,
                params=state.params.policy,
                env_steps=int(steps),
                source=str(path),
            )
        )
    return policies
