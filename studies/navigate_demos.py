"""Does navigate reach the HPP group's Talos demo queries with a verified plan, and how long does
each part take? Optionally on its rough scenes too.

Demo queries: every terrain of `--demos` (default terrains/hpp/demos/*.toml), each one
query of hpp-rbprm-corba's talos_*_path.py scripts (terrains/hpp/README.md): its
`[scenario]` holds one start at rest (start_region a point, start_yaw_deg one value
relative to the direction to the target) and the goal. Each query runs cold, as
`leas navigate` does: `leas_jax.navigate.navigate` builds the terrain's lattice, searches,
rolls the shipped policy out and plans contacts in this process. The policy is loaded
once, and JAX programs compiled for an earlier query are reused (the rollout's; the
lattice's for a raster of the same shape: demos on the same scene build theirs faster).
Every plan is then re-checked by `leas_jax.contacts.verify`. The table gives, per demo:
reached, the reason the query stopped, the wall time of each part (lattice, search,
rollout, contact planning, other = total less those four, total), replans, postures and
whether the plan verifies.

`--terrains GLOB [GLOB ...]` also runs every matching terrain's scenario: its seeded
starts (drawn as `leas evaluate --terrain FILE` draws them; `--starts N` keeps the first
N) to its target, one `Navigator` per scene (its lattice built once). A start succeeds
when the query is reached and its plan verifies; the success rate comes with its 95 %
Wilson interval.

    python studies/navigate_demos.py
    python studies/navigate_demos.py --terrains 'terrains/hpp/rough/*.toml' terrains/hpp/rubble.toml --starts 20

Writes <out>/navigate_demos.json.

Results: --out (default benchmarks/results/); a run to keep goes to docs/results/<date-topic>.
"""

from __future__ import annotations

import argparse
import glob
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))  # benchmarks/common.py

from common import REPO, add_out_argument, load_average, save, wilson  # noqa: E402

DEMOS = "terrains/hpp/demos/*.toml"
CHECKPOINT = "checkpoints/leas_talos"
PARTS = ("lattice", "search", "rollout", "contact_planning", "total")
# Columns of the demo table: the parts, and "other" = total less the four parts (loading the
# terrain's heightfield and the contact generator, compiling what the parts do not time).
COLUMNS = ("lattice", "search", "rollout", "contact_planning", "other", "total")


def demo_query(scenario) -> tuple[tuple[float, float, float], tuple[float, float]]:
    """The one query a demo terrain's `[scenario]` holds.

    Args:
        scenario: a `Scenario` whose start_region is a point, start_yaw_deg one value and
            n_starts 1.

    Returns:
        (start (x, y, yaw) world, m and rad; goal (x, y) world, m). The yaw is the
        direction from the start to the target plus the scenario's yaw offset.

    Raises:
        ValueError: the scenario draws starts from a range (not a single query).
    """
    (x0, y0), (x1, y1) = scenario.start_region
    low, high = scenario.start_yaw_deg
    if (x0, y0) != (x1, y1) or low != high or scenario.n_starts != 1:
        raise ValueError(
            "a demo scenario holds one query: a point start_region, one start_yaw_deg value "
            f"and n_starts = 1 (got start_region {scenario.start_region.tolist()}, "
            f"start_yaw_deg {scenario.start_yaw_deg.tolist()}, n_starts {scenario.n_starts})"
        )
    gx, gy = (float(v) for v in scenario.target)
    yaw = math.atan2(gy - y0, gx - x0) + math.radians(low)
    return (float(x0), float(y0), yaw), (gx, gy)


def result_row(result, verify_fn) -> dict:
    """What the table and the JSON keep of a `NavigationResult`; the plan is verified here.

    Args:
        result: a `NavigationResult`.
        verify_fn: `leas_jax.contacts.verify` (a plan -> report with `ok` and `failures`).

    Returns:
        {reached, reason, message, seconds (COLUMNS, None where missing), replans, postures,
        final_distance, verify_ok (None without a plan), verify_failures, verify_s}.
    """
    plan = result.plan
    seconds = {part: _finite(result.seconds.get(part)) for part in PARTS}
    row = {
        "reached": bool(result.success),
        "reason": result.reason,
        "message": result.message,
        "seconds": {**seconds, "other": other_seconds(seconds)},
        "replans": int(result.replans),
        "postures": 0 if plan is None else len(plan.q),
        "final_distance": _finite(result.final_distance),
        "verify_ok": None,
        "verify_failures": [],
        "verify_s": 0.0,
    }
    if plan is not None:
        began = time.perf_counter()
        report = verify_fn(plan)
        row["verify_s"] = time.perf_counter() - began
        row["verify_ok"] = bool(report.ok)
        row["verify_failures"] = [f"posture {k}: check {c}: {m}" for k, c, m in report.failures[:5]]
    return row


def refused_row(reason: str, message: str) -> dict:
    """A row for a query `navigate` refused before running (its start off the terrain or in
    collision): not reached, no plan, no time."""
    return {
        "reached": False,
        "reason": reason,
        "message": message,
        "seconds": {part: None for part in COLUMNS},
        "replans": 0,
        "postures": 0,
        "final_distance": None,
        "verify_ok": None,
        "verify_failures": [],
        "verify_s": 0.0,
    }


def run_demo(policy, path: Path, workers: int) -> dict:
    """Navigate a demo terrain's query cold (lattice included) and verify the plan.

    Returns:
        `result_row` with "demo" (the file's stem), "terrain" (its path), "start", "goal".
    """
    from leas_jax.contacts import verify
    from leas_jax.errors import UsageError
    from leas_jax.navigate import navigate
    from leas_jax.terrain import load_terrain

    terrain = load_terrain(path)
    start, goal = demo_query(terrain.scenario)
    try:
        result = navigate(policy, terrain, start, goal, workers=workers)
    except UsageError as err:
        row = refused_row("refused", str(err))
    else:
        row = result_row(result, verify)
    return {"demo": path.stem, "terrain": str(path), "start": list(start), "goal": list(goal), **row}


def run_scene(policy, path: Path, starts: int | None, workers: int) -> dict:
    """Navigate from each of a terrain's scenario starts to its target; verify each plan.

    Args:
        policy: the loaded policy.
        path: a terrain file with a `[scenario]`.
        starts: the first this many of its seeded starts (None: its n_starts).
        workers: contact-generator processes (0: in this process).

    Returns:
        {"scene", "terrain", "lattice_s", "wall_s", "rows" (one `result_row` per start, with
        its "start"), and `scene_summary`'s keys}.
    """
    from leas_jax.contacts import verify
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.errors import UsageError
    from leas_jax.eval.scenarios import cells_for, draw_starts, route
    from leas_jax.navigate import Navigator
    from leas_jax.terrain import load_terrain

    began = time.perf_counter()
    terrain = load_terrain(path)
    scenario, env = terrain.scenario, policy.config.env
    field = heightfield_from_terrain(terrain, env)
    cell = cells_for(terrain.name, scenario)[0]
    n = int(starts or scenario.n_starts)
    drawn = draw_starts(scenario, cell, n, scenario.seed, field, env.nominal_root_height, env.reachability)
    points = route(scenario)
    navigator = Navigator(policy, terrain)
    rows, queries, index = [], [], []
    for k, (pose, speed) in enumerate(zip(drawn.poses, drawn.speeds)):
        start = [float(pose[0]), float(pose[1]), float(pose[3])]
        try:
            queries.append(navigator.query(start, points[-1], float(speed), points[:-1]))
            index.append(k)
            rows.append({"start": start})
        except UsageError as err:
            rows.append({"start": start, **refused_row("refused", str(err))})
    answers = navigator.run(queries, workers=workers) if queries else []
    for k, result in zip(index, answers):
        rows[k].update(result_row(result, verify))
    return {
        "scene": path.stem,
        "terrain": str(path),
        "lattice_s": navigator.lattice_seconds,
        "wall_s": time.perf_counter() - began,
        **scene_summary(rows),
        "rows": rows,
    }


def scene_summary(rows: list[dict]) -> dict:
    """Successes (reached and verified) over trials, the rate and its 95 % Wilson interval,
    and how many queries stopped for each reason."""
    successes = sum(1 for r in rows if r["reached"] and r["verify_ok"])
    low, high = wilson(successes, len(rows))
    reasons: dict[str, int] = {}
    for r in rows:
        reasons[r["reason"]] = reasons.get(r["reason"], 0) + 1
    return {
        "trials": len(rows),
        "successes": successes,
        "success_rate": successes / len(rows) if rows else math.nan,
        "wilson_95": [low, high],
        "reasons": reasons,
    }


def other_seconds(seconds: dict) -> float | None:
    """total less lattice, search, rollout and contact_planning (None without a total)."""
    if seconds.get("total") is None:
        return None
    return seconds["total"] - sum(seconds[p] or 0.0 for p in PARTS if p != "total")


def _finite(value) -> float | None:
    """value as a float, None when missing or not finite (the JSON stays strict)."""
    return None if value is None or not math.isfinite(value) else float(value)


def _seconds(value: float | None) -> str:
    return "-" if value is None else f"{value:.1f}"


def demo_table(rows: list[dict]) -> str:
    """Markdown table of demo rows (`run_demo`)."""
    head = "| demo | reached | reason | " + " | ".join(f"{p} s" for p in COLUMNS)
    head += " | replans | postures | verify ok |"
    lines = [head, "|" + "---|" * (len(COLUMNS) + 6)]
    for r in rows:
        verified = "-" if r["verify_ok"] is None else ("yes" if r["verify_ok"] else "NO")
        cells = [r["demo"], "yes" if r["reached"] else "no", r["reason"]]
        cells += [_seconds(r["seconds"][p]) for p in COLUMNS]
        cells += [str(r["replans"]), str(r["postures"]), verified]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def scene_table(scenes: list[dict]) -> str:
    """Markdown table of scene results (`run_scene`): success rate with its 95 % interval."""
    lines = [
        "| scene | starts | reached and verified | 95 % interval | reasons | lattice s | wall s |",
        "|---|---|---|---|---|---|---|",
    ]
    for s in scenes:
        low, high = s["wilson_95"]
        reasons = ", ".join(f"{k} {v}" for k, v in sorted(s["reasons"].items()))
        lines.append(
            f"| {s['scene']} | {s['trials']} | {s['successes']} ({100 * s['success_rate']:.0f} %) | "
            f"[{100 * low:.0f}, {100 * high:.0f}] % | {reasons} | {s['lattice_s']:.1f} | {s['wall_s']:.0f} |"
        )
    return "\n".join(lines)


def expand(patterns: list[str]) -> list[Path]:
    """Files matching the glob patterns (relative ones from the repository root), sorted per
    pattern, each once, in pattern order.

    Raises:
        SystemExit: a pattern matches no file.
    """
    paths: list[Path] = []
    for pattern in patterns:
        base = pattern if Path(pattern).is_absolute() else str(REPO / pattern)
        matches = sorted(Path(p) for p in glob.glob(base))
        if not matches:
            raise SystemExit(f"navigate_demos: {pattern!r} matches no file")
        paths += [p for p in matches if p not in paths]
    return paths


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--demos", nargs="+", default=[DEMOS], metavar="GLOB", help=f"default {DEMOS}")
    parser.add_argument(
        "--terrains", nargs="+", default=[], metavar="GLOB", help="scenes whose scenario starts to run too"
    )
    parser.add_argument("--starts", type=int, default=None, help="starts per scene (default its n_starts)")
    parser.add_argument("--workers", type=int, default=0, help="contact-generator processes (0: in process)")
    parser.add_argument("--checkpoint", default=CHECKPOINT)
    add_out_argument(parser)
    args = parser.parse_args(argv)
    if args.starts is not None and args.starts < 1:
        parser.error(f"--starts: expected a positive integer, got {args.starts}")
    demos, scenes = expand(args.demos), expand(args.terrains)

    from leas_jax.training import load_policy

    load_before = load_average()
    checkpoint = Path(args.checkpoint)
    policy = load_policy(checkpoint if checkpoint.exists() else REPO / checkpoint)
    rows = []
    for path in demos:
        rows.append(run_demo(policy, path, args.workers))
        r = rows[-1]
        print(f"{r['demo']}: {r['reason']}, verify {r['verify_ok']}, {r['message']}", flush=True)
    results = []
    for path in scenes:
        results.append(run_scene(policy, path, args.starts, args.workers))
        s = results[-1]
        print(f"{s['scene']}: {s['successes']}/{s['trials']} reached and verified {s['reasons']}", flush=True)
    print(demo_table(rows))
    if results:
        print(scene_table(results))
    report = {
        "checkpoint": args.checkpoint,
        "workers": args.workers,
        "demos": rows,
        "scenes": results,
        "demo_table": demo_table(rows),
        "scene_table": scene_table(results) if results else None,
    }
    save("navigate_demos", report, load_before, args.out)


if __name__ == "__main__":
    main()
