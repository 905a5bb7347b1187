"""A navigate query as a report section (`leas run`'s report.md ends with one).

    lines, summary = navigate_section(policy_dir, out)   # out/navigate/plan.npz, navigate.png

Host function: loads the policy, runs one `navigate` query on an evaluation terrain (from
the centre of its start region, facing the target, to the target), writes the plan file
and its top-down figure, and returns markdown lines and a JSON-able summary.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def navigate_section(
    checkpoint, out, scenario: str = "bridge", workers: int = 2, terrain_file=None, allow_pickle: bool = False
) -> tuple[list[str], dict]:
    """One navigate query on terrains/eval_<scenario>.toml (or `terrain_file`, with a [scenario] table).

    Args:
        checkpoint: run directory or policy file (`leas_jax.training.load_policy`).
        out: the report's directory; the query writes `navigate/plan.npz` and `navigate/navigate.png`.
        scenario: evaluation scenario name (eval_bridge: the 0.30 m beam LeaS alone misses).
        workers: contact-generator processes.
        terrain_file: another terrain file with a [scenario] table instead.
        allow_pickle: also read a legacy pickle policy (`load_policy`).

    Returns:
        (markdown lines, summary dict).
    """
    from leas_jax.contacts.viewer import write_footsteps_png
    from leas_jax.navigate.loop import navigate
    from leas_jax.terrain import load_terrain
    from leas_jax.terrain.generate import scenario_file
    from leas_jax.training import load_policy

    terrain = load_terrain(terrain_file or scenario_file(scenario))
    region = np.asarray(terrain.scenario.start_region, np.float64)
    goal = np.asarray(terrain.scenario.target, np.float64)
    centre = region.mean(axis=0)
    start = (float(centre[0]), float(centre[1]), math.atan2(goal[1] - centre[1], goal[0] - centre[0]))
    result = navigate(
        load_policy(checkpoint, allow_pickle=allow_pickle), terrain, start, goal, workers=workers
    )
    folder = Path(out) / "navigate"
    folder.mkdir(parents=True, exist_ok=True)
    figure = None
    if result.plan is not None:
        result.plan.save(folder / "plan.npz")
        write_footsteps_png(result.plan, folder / "navigate.png")
        figure = "navigate/navigate.png"
    s = result.seconds
    summary = {
        "terrain": terrain.name,
        "start": list(start),
        "goal": goal.tolist(),
        "success": result.success,
        "reason": result.reason,
        "message": result.message,
        "replans": result.replans,
        "final_distance": result.final_distance,
        "postures": 0 if result.plan is None else len(result.plan),
        "seconds": s,
    }
    lines = [
        "## Navigate",
        "",
        f"`leas navigate` on {terrain.name} from ({start[0]:.2f}, {start[1]:.2f}) to "
        f"({goal[0]:.2f}, {goal[1]:.2f}): {result.message}, {result.replans} replans, "
        f"{summary['postures']} postures"
        + ("" if result.plan is None else " (`navigate/plan.npz`, checked by `leas verify`)")
        + f". Time {s['total']:.1f} s: lattice {s['lattice']:.1f}, search {s['search']:.1f}, "
        f"policy rollout {s['rollout']:.1f}, contact planning {s['contact_planning']:.1f} s.",
        "",
    ]
    if figure is not None:
        lines += [f"![navigate]({figure})", ""]
    return lines, summary
