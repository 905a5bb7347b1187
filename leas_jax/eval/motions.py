"""Whole-body execution of an evaluation's plans: `leas evaluate --motion` (host-only).

Per scenario and per method among `MOTION_METHODS`, a few of the plans that cover their
whole guide (`motion_candidates`: at most `plans`, spread evenly over the trajectories in
their order, so over the cells) are made into motions and simulated in MuJoCo
(`leas_jax.motion.execute.execute_plan`), in `workers` processes. `aggregate` gives per
method how many were made, executed without a fall, and passed every check, with the
worst landing error, slip and torque ratio; `markdown` is their table in table.md.
"""

from __future__ import annotations

import concurrent.futures

import numpy as np

MOTION_METHODS = ("leas", "navigate")


def covers_guide(trajectory) -> bool:
    """The trajectory's plan covers its whole guide (navigate: the goal is reached)."""
    outcome, plan = trajectory.outcome, trajectory.plan
    if plan is None or outcome is None or trajectory.guide is None or len(plan) < 2:
        return False
    return outcome.last_valid_index >= len(trajectory.guide) - 1


def motion_candidates(trajectories: list, plans: int) -> list[int]:
    """Indices into `trajectories` of the plans to execute: per method of MOTION_METHODS,
    at most `plans` of those that cover their guide, evenly spread in trajectory order."""
    chosen = []
    for method in MOTION_METHODS:
        covered = [i for i, t in enumerate(trajectories) if t.method == method and covers_guide(t)]
        if covered and plans > 0:
            picks = np.unique(
                np.round(np.linspace(0, len(covered) - 1, min(plans, len(covered)))).astype(int)
            )
            chosen.extend(covered[p] for p in picks)
    return sorted(chosen)


def _execution_summary(plan) -> dict:
    """`Execution.summary()` of one plan (the function a worker process runs)."""
    from leas_jax.motion.execute import execute_plan

    return execute_plan(plan).summary()


def run_motions(
    trajectories: list, plans: int, workers: int, progress: bool = True, desc: str = "motions"
) -> list:
    """Make and simulate the chosen plans' motions.

    Args:
        trajectories: a scenario's trajectories (with their `plan` kept by validation).
        plans: at most this many plans per method (`motion_candidates`).
        workers: processes (0 or 1: in this one).

    Returns:
        list of dicts, one per executed plan: trajectory (index), method, cell, and
        `Execution.summary()`'s figures.
    """
    from tqdm.auto import tqdm

    chosen = motion_candidates(trajectories, plans)
    bar = dict(total=len(chosen), desc=desc, disable=not progress, leave=False)
    jobs = [trajectories[i].plan for i in chosen]
    if workers <= 1 or len(jobs) <= 1:
        summaries = [_execution_summary(plan) for plan in tqdm(jobs, **bar)]
    else:
        import multiprocessing

        context = multiprocessing.get_context("spawn")
        with concurrent.futures.ProcessPoolExecutor(min(workers, len(jobs)), context) as pool:
            summaries = list(tqdm(pool.map(_execution_summary, jobs), **bar))
    return [
        {"trajectory": i, "method": trajectories[i].method, "cell": trajectories[i].cell} | s
        for i, s in zip(chosen, summaries)
    ]


def _worst(executions: list, key: str) -> float | None:
    values = [e[key] for e in executions if e.get(key) is not None]
    return max(values) if values else None


def aggregate(executions: list) -> dict:
    """Per method: n (plans tried), made, without_fall (made and the robot stays up),
    executed (every phase passes `simulate`'s checks) and the worst landing position (m)
    and angle (deg), slip (m) and torque ratio over the simulated ones (None: none)."""
    out = {}
    for method in dict.fromkeys(e["method"] for e in executions):
        mine = [e for e in executions if e["method"] == method]
        out[method] = {
            "n": len(mine),
            "made": sum(e["made"] for e in mine),
            "without_fall": sum(e["made"] and e["fallen"] is False for e in mine),
            "executed": sum(bool(e["success"]) for e in mine),
            **{
                key: _worst(mine, key)
                for key in (
                    "max_landing_position_m",
                    "max_landing_angle_deg",
                    "max_slip_m",
                    "max_torque_ratio",
                )
            },
        }
    return out


def _figure(value, scale: float = 1.0, digits: int = 2) -> str:
    return "-" if value is None else f"{value * scale:.{digits}f}"


def markdown(report: dict, labels: dict) -> list[str]:
    """table.md lines of the scenarios' motion summaries (empty when none ran)."""
    lines = []
    for name, scenario in report["scenarios"].items():
        for method, s in scenario.get("motion", {}).get("summary", {}).items():
            lines.append(
                f"| {name} | {labels.get(method, method)} | {s['n']} | {s['made']} | {s['without_fall']} "
                f"| {s['executed']} | {_figure(s['max_landing_position_m'], 100)} / "
                f"{_figure(s['max_landing_angle_deg'])} | {_figure(s['max_slip_m'], 100)} "
                f"| {_figure(s['max_torque_ratio'])} |"
            )
    if not lines:
        return []
    import math

    from leas_jax.motion.config import SimulationConfig

    bounds = SimulationConfig()
    return [
        "## Whole-body motions",
        "",
        "A few plans per method that cover their whole guide, made into Talos motions (`leas motion`) and "
        "simulated in MuJoCo (`leas simulate`): made, stayed up (no fall), executed (every phase passes: "
        f"landings within {bounds.landing_position * 100:g} cm and {math.degrees(bounds.landing_angle):.0f} deg, "
        f"slip under {bounds.max_slip * 100:g} cm, torques within limits, no other terrain contact); "
        "worst figures over the simulated plans.",
        "",
        "| scenario | method | plans | made | no fall | executed | max landing error (cm / deg) "
        "| max slip (cm) | max torque ratio |",
        "|---|---|---|---|---|---|---|---|---|",
        *lines,
        "",
    ]
