"""Do verified contact plans execute in MuJoCo, within Talos's effort limits, and how fast?

Question: what fraction of the contact generator's verified plans does Talos execute in
MuJoCo physics (`leas_jax.motion.execute.execute_plan`: `make_motion`, then `simulate`)
without a fall and with every sole landing within 3 cm of its placement; how close do the
commanded torques come to the URDF's effort limits (peak ratio per joint group); and how
much CPU time do motion generation and simulation cost per second of motion?

Plans: each scenario's seeded starts (as `leas evaluate` draws them; `ground` is Table II's
nine cells of yaw range x initial speed, `--ground-starts` per cell there) steered by
RBLin (straight lines to the target, `leas_jax.steering.baselines`) or, where straight
lines do not reach (METHODS: bridges, holes, the Bauzil room), by `navigate` with the
shipped policy (`--checkpoint`), and planned by the contact generator in this process; a
plan counts when it covers its whole guide (the generator's verified plans,
`leas_jax.eval.motions.covers_guide`). The HPP group's demo queries
(terrains/hpp/demos/*.toml, `hpp_talos_<demo>`) hold one start each; a demo whose start the
evaluation's start check refuses is planned as `leas navigate` plans the query (counted when
reached and verified). The HPP rough scenes (terrains/hpp/rough/<scene>.toml as `hpp_<scene>`,
terrains/hpp/rubble.toml as `hpp_rubble`; ROUGH) and eval_circuit are steered by navigate.
Groups: TARGET (default), OTHERS (`--all` adds them). `--max-postures N` records plans of
more postures than N as not executed (not counted). Plans are cached in
`<plans>/<scenario>_<k>.npz` (default runs/motion_plans/, not committed), so a later run
(another `--variant`) executes the same plans.

Execution: one process, one plan at a time. Per plan: made (or the `MotionError` phase and
reason), fallen (and in which phase kind), success (every phase passes `simulate`'s checks:
landings within 3 cm / 5 deg, slip under 1 cm, torques within limits, no other terrain
contact), the largest landing error, the peak torque ratio per joint group, the motion's
duration and the CPU time (`time.process_time`) of `make_motion` and of `simulate`.
Rates come with 95 % Wilson intervals.

    python studies/motion_execution.py --out docs/results/2026-12-06-motion --starts 4 --ground-starts 1 --all
    python studies/motion_execution.py --out docs/results/2026-12-06-motion --variant baseline \\
        --motion-config '{"support_margin": 0.0}'

    python studies/motion_execution.py --out docs/results/2026-12-06-motion-every-scene --starts 2 \\
        --max-plans 2 --max-postures 1000 --variant new --scenarios circuit,hpp_darpa,hpp_talos_maze

`--transitions` plans with the generator's transition checks (`motion_generator_config`, as
`leas navigate --motion` plans: each single support's lift-off, apex and touchdown reachable
and clear as the motion moves the root); give it its own `--plans` folder.

`--also VARIANT=JSON` simulates each motion once more with other SimulationConfig overrides
(the motion made once), written as VARIANT.

`--motions DIR` keeps each made motion (`<plan>.npz`, `Motion.save`) and what making it cost or
why it could not be made (`<plan>.json`, with the commit that made it) in DIR; a later run with
the same DIR simulates those motions again instead of making them (its make figures are the
first run's). Empty DIR when the motion code changes.

Writes <out>/motion_execution_<variant>.json and <out>/motion_execution_<variant>.md.

Results: --out (default benchmarks/results/motion); the runs kept are docs/results/2026-12-06-motion/,
docs/results/2026-12-06-motion-landings/ and docs/results/2026-12-06-motion-every-scene/.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from leas_jax.stats import wilson

ROOT = Path(__file__).resolve().parents[1]

# The target group (90 %): Table II's flat ground, eval_stairs, eval_bridge and two HPP demos.
TARGET = ("ground", "stairs", "bridge", "hpp_talos_stairs10", "hpp_talos_navBauzil")
# The HPP group's rough scenes (terrains/hpp/rough/*.toml and terrains/hpp/rubble.toml), by name.
ROUGH_SCENES = (
    "bauzil_ramp_simplified",
    "bridge_towr",
    "cross_gap",
    "darpa",
    "rubbles_stairs_1",
    "rubbles_stairs_2",
    "rubbles_stairs_3",
    "rubbles_stairs_bridge_1",
    "slalom_debris",
    "stairs_towr",
)
ROUGH = tuple(f"hpp_{n}" for n in ROUGH_SCENES) + ("hpp_rubble",)
# The HPP demo queries besides the target group's two (terrains/hpp/demos/).
DEMOS = (
    "hpp_talos_flatGround",
    "hpp_talos_stairs15",
    "hpp_talos_maze",
    "hpp_talos_navBauzil_hard",
    "hpp_talos_navBauzil_obstacles",
    "hpp_talos_plateformes",
)
# The other evaluation scenarios and HPP scenes (75 % over all scenes with a verified plan).
OTHERS = ("hole", "stairs_side", "circuit", "hpp_stairs", "hpp_bridge", "hpp_hole") + DEMOS + ROUGH
# Steering method per scenario (default rblin): navigate where RBLin's straight lines meet
# no verified plan (eval_bridge: 0 of 4 starts; the Bauzil room's demo query), on the circuit
# (whose guide turns round its posts), the demo queries of rooms and mazes and the rough scenes
# (straight lines are covered only on darpa there: docs/results/2026-12-06-rough-scenes/).
METHODS = {
    "bridge": "navigate",
    "hole": "navigate",
    "circuit": "navigate",
    "hpp_talos_navBauzil": "navigate",
    "hpp_talos_maze": "navigate",
    "hpp_talos_navBauzil_hard": "navigate",
    "hpp_talos_navBauzil_obstacles": "navigate",
    "hpp_talos_plateformes": "navigate",
    "hpp_bridge": "navigate",
    "hpp_hole": "navigate",
} | {name: "navigate" for name in ROUGH}
# Scenario name -> terrain file for the HPP scenes (the evaluation scenarios by name).
HPP_FILES = {
    "hpp_talos_stairs10": "terrains/hpp/demos/talos_stairs10.toml",
    "hpp_talos_navBauzil": "terrains/hpp/demos/talos_navBauzil.toml",
    "hpp_talos_flatGround": "terrains/hpp/demos/talos_flatGround.toml",
    "hpp_talos_stairs15": "terrains/hpp/demos/talos_stairs15.toml",
    "hpp_talos_maze": "terrains/hpp/demos/talos_maze.toml",
    "hpp_talos_navBauzil_hard": "terrains/hpp/demos/talos_navBauzil_hard.toml",
    "hpp_talos_navBauzil_obstacles": "terrains/hpp/demos/talos_navBauzil_obstacles.toml",
    "hpp_talos_plateformes": "terrains/hpp/demos/talos_plateformes.toml",
    "hpp_stairs": "terrains/hpp/stairs.toml",
    "hpp_bridge": "terrains/hpp/bridge.toml",
    "hpp_hole": "terrains/hpp/hole.toml",
    "hpp_rubble": "terrains/hpp/rubble.toml",
} | {f"hpp_{n}": f"terrains/hpp/rough/{n}.toml" for n in ROUGH_SCENES}


def make_plans(
    name: str, starts: int, ground_starts: int, cache: Path, checkpoint=None, generator_config=None
) -> list[Path]:
    """Plan files of `name`'s covered RBLin plans, planned now unless cached.

    Args:
        name: an evaluation scenario (`leas_jax.eval.scenarios.SCENARIOS`) or a key of HPP_FILES.
        starts: starts of a one-cell scenario (HPP demos: their one start).
        ground_starts: starts per cell of `ground` (Table II's nine cells).
        cache: folder of the plan files.
        checkpoint: the policy of the navigate method (METHODS).
        generator_config: the contact generator's `GeneratorConfig` (None: its defaults).

    Returns:
        paths of the covered plans' files (world frame, the generator's ContactPlan format).
    """
    from leas_jax.errors import UsageError
    from leas_jax.eval.evaluate import run_scenario
    from leas_jax.eval.motions import covers_guide
    from leas_jax.terrain import load_terrain
    from leas_jax.terrain.generate import scenario_file

    marker = cache / f"{name}.json"
    if marker.is_file():
        return [cache / f for f in json.loads(marker.read_text())["plans"]]
    terrain = load_terrain(ROOT / HPP_FILES[name] if name in HPP_FILES else scenario_file(name))
    began = time.perf_counter()
    # ground: per cell of nine; the HPP demos: their one query; the other scenes: `starts`.
    per_cell = ground_starts if name == "ground" else (None if name.startswith("hpp_talos") else starts)
    method = METHODS.get(name, "rblin")
    policy = None
    if method == "navigate":
        from leas_jax.eval.evaluate import policy_for

        policy = policy_for((method,), checkpoint)
    files, note = [], None
    try:
        result = run_scenario(
            name, terrain, (method,), policy, per_cell, 0, progress=False, generator_config=generator_config
        )
    except UsageError as exc:
        if not (name.startswith("hpp_talos") and method == "navigate"):
            raise
        # A demo query whose start the evaluation's start check refuses (talos_plateformes:
        # the trunk over a platform's edge): the query as `leas navigate` and
        # studies/navigate_demos.py run it; its plan counts when reached and verified.
        note = f"evaluation start refused ({exc}); planned as `leas navigate` plans the query"
        starts = 1
        if demo_plan(terrain, policy, cache / f"{name}_0.npz", generator_config):
            files.append(f"{name}_0.npz")
    else:
        starts = len(result.trajectories)
        for k, trajectory in enumerate(result.trajectories):
            if covers_guide(trajectory):
                path = cache / f"{name}_{k}.npz"
                trajectory.plan.save(path)
                files.append(path.name)
    marker.write_text(
        json.dumps(
            {
                "method": method,
                "starts": starts,
                "plans": files,
                "planning_seconds": round(time.perf_counter() - began, 1),
            }
            | ({"note": note} if note else {})
        )
    )
    return [cache / f for f in files]


def demo_plan(terrain, policy, path: Path, generator_config=None) -> bool:
    """Navigate a demo terrain's one query (start at rest, yaw relative to the direction to the
    target) in this process; save the plan at `path` when the goal is reached and the plan
    passes `leas_jax.contacts.verify`. Returns whether it was saved."""
    from leas_jax.contacts import verify
    from leas_jax.navigate import navigate
    from leas_jax.navigate.loop import NavigateConfig

    scenario = terrain.scenario
    (x0, y0), _ = scenario.start_region
    gx, gy = (float(v) for v in scenario.target)
    yaw = math.atan2(gy - y0, gx - x0) + math.radians(float(scenario.start_yaw_deg[0]))
    config = NavigateConfig() if generator_config is None else NavigateConfig(generator=generator_config)
    result = navigate(policy, terrain, (float(x0), float(y0), yaw), (gx, gy), config, workers=0)
    if not (result.success and result.plan is not None and verify(result.plan).ok):
        return False
    result.plan.save(path)
    return True


def cause(summary: dict) -> str:
    """The failure cause of one execution: 'no motion: <check>', 'fell in <phase kind>',
    'landing > 3 cm', 'slip', 'torque clipped', 'terrain contact' (first that applies),
    None when the plan executes."""
    if not summary["made"]:
        error = summary["error"] or ""
        for key, label in (
            ("collisions fails", "collisions"),  # the motion's check, at a sample
            ("comes within", "terrain clearance"),  # a single support's ways all refused
            ("collides with", "collisions"),
            ("equilibrium", "equilibrium"),
            ("out of the legs' reach", "soles out of reach"),
            ("for the soles to reach", "soles out of reach"),
            ("torque", "torque"),
            ("velocity", "velocity"),
            ("joint limit", "joint limit"),
            ("IK", "IK"),
            ("inside the terrain", "swing sole in the terrain"),
            ("contacts", "transition"),
        ):
            if key.lower() in error.lower():
                return f"no motion: {label}"
        return "no motion: other"
    if summary["success"]:
        return None
    message = summary["message"] or ""
    if summary["fallen"]:
        kind = message.split(" ", 1)[0] if message else "?"
        return f"fell in {kind}"
    if "cm from its placement" in message or "deg off" in message:
        return "landing > 3 cm / 5 deg"
    if "slips" in message:
        return "slip"
    if "x its limit" in message:
        return "torque clipped"
    if "terrain touched" in message:
        return "terrain contact"
    return "other"


def made_motion(path: Path, motions: Path | None, motion_config, simulation_config, git: dict):
    """`execute_plan` of the plan file at `path`, or, where `motions` holds its motion (or the
    reason it could not be made) from an earlier run, that motion simulated again; `git`
    (`provenance.git_state()` when the run started: the code that makes the motion) is kept
    with it.

    Returns:
        `Execution`; its make figures are those of the run that made the motion.
    """
    from leas_jax.contacts.commands import load_plan_file
    from leas_jax.files import atomic_write_text
    from leas_jax.motion.execute import Execution, execute_plan
    from leas_jax.motion.motion import Motion
    from leas_jax.motion.simulate import simulate

    record = None if motions is None else motions / f"{path.stem}.json"
    if record is not None and record.is_file():
        made = json.loads(record.read_text())
        motion = Motion.load(motions / f"{path.stem}.npz") if made["error"] is None else None
        rollout = None if motion is None else simulate(motion, config=simulation_config)
        return Execution(motion, rollout, made["error"], made["make_seconds"], made["make_cpu_seconds"])
    execution = execute_plan(load_plan_file(path), motion_config, simulation_config)
    if record is not None:
        motions.mkdir(parents=True, exist_ok=True)
        if execution.motion is not None:
            execution.motion.save(motions / f"{path.stem}.npz")
        made = {
            "error": execution.error,
            "make_seconds": execution.make_seconds,
            "make_cpu_seconds": execution.make_cpu_seconds,
            "git": git,
        }
        atomic_write_text(record, json.dumps(made))
    return execution


def run(args) -> dict:
    from leas_jax.contacts.commands import load_plan_file
    from leas_jax.motion.config import MotionConfig, SimulationConfig
    from leas_jax.motion.execute import Execution
    from leas_jax.motion.simulate import simulate
    from leas_jax.provenance import git_state

    git = git_state()  # the code this process loaded, whatever the checkout holds later
    out = Path(args.out)
    motions = Path(args.motions) if args.motions else None
    cache = Path(args.plans)
    cache.mkdir(parents=True, exist_ok=True)
    motion_config = MotionConfig(**json.loads(args.motion_config))
    generator = None
    if args.transitions:
        from leas_jax.contacts.planner.config import motion_generator_config

        generator = motion_generator_config()
    # (variant, SimulationConfig overrides): the first's simulation is execute_plan's, the
    # others (--also) simulate the same motion again
    variants = [(args.variant, json.loads(args.simulation_config))]
    for item in args.also or []:
        name, _, overrides = item.partition("=")
        variants.append((name, json.loads(overrides or "{}")))
    names = list(TARGET) + (list(OTHERS) if args.all else [])
    if args.scenarios:
        names = args.scenarios.split(",")
    reports = {}
    for variant, overrides in variants:
        report = {
            "question": __doc__.split("\n\n")[1].replace("\n", " "),
            "variant": variant,
            "motion_config": json.loads(args.motion_config),
            "simulation_config": overrides,
            "starts": args.starts,
            "ground_starts_per_cell": args.ground_starts,
            "max_plans": args.max_plans,
            "max_postures": args.max_postures,
            "transitions_checked": args.transitions,
            "scenarios": {},
        }
        json_path = out / f"motion_execution_{variant}.json"
        if json_path.is_file() and args.scenarios:  # a run of some scenarios adds to the variant's others
            previous = json.loads(json_path.read_text())
            report["scenarios"] = {k: v for k, v in previous["scenarios"].items() if k not in names}
            for scenario in report["scenarios"].values():  # causes as this version names them
                for e in scenario["executions"]:
                    e["cause"] = cause(e)
        reports[variant] = report
    for name in names:
        plans = make_plans(name, args.starts, args.ground_starts, cache, args.checkpoint, generator)
        if args.max_plans:
            plans = plans[: args.max_plans]
        executions, skipped = {variant: [] for variant, _ in variants}, []
        for path in plans:
            plan = load_plan_file(path)
            if args.max_postures and len(plan) > args.max_postures:  # not executed, not counted
                skipped.append({"plan": path.name, "postures": len(plan)})
                print(f"{name} {path.name}: skipped ({len(plan)} postures)", flush=True)
                continue
            first = made_motion(path, motions, motion_config, SimulationConfig(**variants[0][1]), git)
            for variant, overrides in variants:
                execution = first
                if variant != variants[0][0] and first.motion is not None:
                    rollout = simulate(first.motion, config=SimulationConfig(**overrides))
                    execution = Execution(
                        first.motion, rollout, None, first.make_seconds, first.make_cpu_seconds
                    )
                s = {"plan": path.name, "postures": len(plan), "cause": None} | execution.summary()
                s["cause"] = cause(s)
                executions[variant].append(s)
                print(
                    f"{variant} {name} {path.name}: {s['cause'] or 'executed'} ({s.get('message') or s['error']})",
                    flush=True,
                )
        marker = json.loads((cache / f"{name}.json").read_text())
        for variant, report in reports.items():
            report["scenarios"][name] = {
                "method": marker.get("method", "rblin"),
                "starts": marker["starts"],
                "verified_plans": len(marker["plans"]),
                "executions": executions[variant],
            } | ({"skipped": skipped} if skipped else {})
            report["summary"] = summarise(report["scenarios"])
            (out / f"motion_execution_{variant}.json").write_text(json.dumps(report, indent=1))
    for variant, report in reports.items():
        (out / f"motion_execution_{variant}.md").write_text(markdown(report))
    return reports[args.variant]


def combine(args) -> dict:
    """Merge the scenarios of the variants named by --combine (later ones win) into --variant's
    JSON and markdown; the first variant's settings are kept, the others' noted."""
    out = Path(args.out)
    reports = [json.loads((out / f"motion_execution_{v}.json").read_text()) for v in args.combine.split(",")]
    report = dict(reports[0], variant=args.variant, combined_from=args.combine.split(","))
    report["scenarios"] = {}
    for part in reports:
        report["scenarios"].update(part["scenarios"])
    for scenario in report["scenarios"].values():
        for e in scenario["executions"]:
            e["cause"] = cause(e)
    report["summary"] = summarise(report["scenarios"])
    (out / f"motion_execution_{args.variant}.json").write_text(json.dumps(report, indent=1))
    (out / f"motion_execution_{args.variant}.md").write_text(markdown(report))
    return report


def _rate(ok: int, n: int) -> dict:
    if not n:
        return {"ok": ok, "n": n, "rate": None, "wilson95": None}
    low, high = wilson(ok, n)
    return {"ok": ok, "n": n, "rate": round(ok / n, 3), "wilson95": [round(low, 3), round(high, 3)]}


def summarise(scenarios: dict) -> dict:
    """Per scenario and over the target group / all scenes: executed rates, causes, peaks, CPU ratios."""
    rows, causes = {}, {}
    groups = {"target": [], "all": []}
    peaks: dict = {}
    make_ratio, sim_ratio = [], []
    for name, scenario in scenarios.items():
        ex = scenario["executions"]
        ok = sum(1 for e in ex if e["success"])
        upright = sum(1 for e in ex if e["made"] and e["fallen"] is False)
        rows[name] = {
            "executed": _rate(ok, len(ex)),
            "made_and_upright": _rate(upright, len(ex)),
            "causes": {},
        }
        for e in ex:
            if e["cause"]:
                rows[name]["causes"][e["cause"]] = rows[name]["causes"].get(e["cause"], 0) + 1
                causes[e["cause"]] = causes.get(e["cause"], 0) + 1
            for group, value in (e.get("torque_ratio_by_group") or {}).items():
                peaks[group] = max(peaks.get(group, 0.0), value)
            if e["made"] and e.get("duration_s"):
                make_ratio.append(e["make_cpu_seconds"] / e["duration_s"])
                sim_ratio.append(e["simulate_cpu_seconds"] / e["duration_s"])
        if ex:
            groups["all"].append((ok, len(ex)))
            if name in TARGET:
                groups["target"].append((ok, len(ex)))
    totals = {g: _rate(sum(o for o, _ in v), sum(n for _, n in v)) for g, v in groups.items()}
    return {
        "scenarios": rows,
        "totals": totals,
        "causes": causes,
        "peak_torque_ratio_by_group": {k: round(v, 3) for k, v in peaks.items()},
        "make_cpu_s_per_motion_s": _quantiles(make_ratio),
        "simulate_cpu_s_per_motion_s": _quantiles(sim_ratio),
    }


def _quantiles(values: list) -> dict | None:
    if not values:
        return None
    v = np.asarray(values)
    return {"median": round(float(np.median(v)), 3), "max": round(float(v.max()), 3), "n": len(v)}


def _pct(rate: dict) -> str:
    if not rate["n"]:
        return "-"
    low, high = rate["wilson95"]
    return f"{rate['ok']}/{rate['n']} ({100 * rate['rate']:.0f} %, {100 * low:.0f}-{100 * high:.0f} %)"


def markdown(report: dict) -> str:
    s = report["summary"]
    lines = [
        f"# Motion execution: variant `{report['variant']}`",
        "",
        f"MotionConfig overrides: `{json.dumps(report['motion_config'])}`; SimulationConfig overrides: "
        f"`{json.dumps(report['simulation_config'])}`. Plans of each scenario's method: {report['starts']} start(s) per scenario, {report['ground_starts_per_cell']} per cell of ground's nine"
        + (f"; at most {report['max_plans']} executed per scenario" if report.get("max_plans") else "")
        + (
            f"; merged from the variants {', '.join(report['combined_from'])}"
            if report.get("combined_from")
            else ""
        )
        + ". Rates: executed (no fall, every phase passes) over verified plans executed.",
        "",
        "| scenario | method | starts | verified plans | executed (95 % Wilson) | made, no fall | failures by cause |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, row in s["scenarios"].items():
        sc = report["scenarios"][name]
        causes = ", ".join(f"{k}: {v}" for k, v in sorted(row["causes"].items())) or "-"
        if sc.get("skipped"):
            causes = (
                ("" if causes == "-" else causes + "; ")
                + "not executed: "
                + ", ".join(f"{e['plan']} ({e['postures']} postures)" for e in sc["skipped"])
            )
        lines.append(
            f"| {name} | {sc.get('method', 'rblin')} | {sc['starts']} | {sc['verified_plans']} | {_pct(row['executed'])} "
            f"| {_pct(row['made_and_upright'])} | {causes} |"
        )
    lines += [
        f"| **target group** | | | | {_pct(s['totals']['target'])} | | |",
        f"| **all scenes** | | | | {_pct(s['totals']['all'])} | | |",
        "",
        "Peak commanded torque / effort limit over every simulated motion, per joint group: "
        + ", ".join(f"{k} {v:.2f}" for k, v in s["peak_torque_ratio_by_group"].items()),
        "",
    ]
    for key, label in (
        ("make_cpu_s_per_motion_s", "motion generation"),
        ("simulate_cpu_s_per_motion_s", "simulation"),
    ):
        q = s[key]
        if q:
            lines.append(
                f"- {label}: CPU s per s of motion, median {q['median']:.3f}, max {q['max']:.3f} over {q['n']} motions"
                + (
                    f" (real-time factor {1 / q['median']:.1f}x median, {1 / q['max']:.1f}x worst)"
                    if key.startswith("sim")
                    else ""
                )
            )
    lines.append("")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=str(ROOT / "benchmarks/results/motion"))
    parser.add_argument("--starts", type=int, default=4, help="starts of a one-cell scenario")
    parser.add_argument("--ground-starts", type=int, default=1, help="starts per cell of ground (9 cells)")
    parser.add_argument(
        "--checkpoint", default=str(ROOT / "checkpoints/leas_talos"), help="navigate's policy"
    )
    parser.add_argument("--plans", default=str(ROOT / "runs/motion_plans"), help="plan cache folder")
    parser.add_argument(
        "--transitions",
        action="store_true",
        help="plan with the transitions a motion needs checked (`motion_generator_config`, as "
        "`leas navigate --motion` plans); give another --plans folder",
    )
    parser.add_argument(
        "--all", action="store_true", help="also the other evaluation scenarios and HPP scenes"
    )
    parser.add_argument(
        "--scenarios", default=None, help="comma-separated scenario names (instead of the groups)"
    )
    parser.add_argument(
        "--max-plans", type=int, default=0, help="execute at most this many plans per scenario"
    )
    parser.add_argument(
        "--max-postures",
        type=int,
        default=0,
        help="skip (record, not execute or count) plans of more postures than this (0: none skipped)",
    )
    parser.add_argument("--variant", default="current", help="name of this configuration in the output files")
    parser.add_argument(
        "--combine",
        default=None,
        help="comma-separated variants whose JSON files in --out are merged into --variant's (nothing run)",
    )
    parser.add_argument(
        "--motions",
        default=None,
        help="folder keeping each made motion; a plan whose motion is there is simulated again, not made",
    )
    parser.add_argument("--motion-config", default="{}", help="JSON of MotionConfig overrides")
    parser.add_argument("--simulation-config", default="{}", help="JSON of SimulationConfig overrides")
    parser.add_argument(
        "--also",
        action="append",
        metavar="VARIANT=JSON",
        help="also simulate each motion with these SimulationConfig overrides, written as VARIANT (repeatable)",
    )
    args = parser.parse_args(argv)
    report = combine(args) if args.combine else run(args)
    print(markdown(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
