"""Where and why does the contact generator stop on a policy's own arena guides?

For a trained policy (deterministic), run `--starts` episodes from the env's own random
resets on its training arena (`leas_jax.eval.geometric.arena_episodes`, 400 steps), plan
every guide with the contact generator (`--upper-bodies` sets its
`GeneratorConfig.upper_bodies`; "half_sitting" is the paper's rigid upper body), and for each guide it does not cover fully
describe the planning pose where it stopped (the first one after `last_valid_index`):

- the arena cell it lies in, by kind (the `# cell (i, j) [...]: kind` comments that
  `leas terrain generate` writes; "unknown" on other terrains);
- the guide's speed and yaw rate over the 0.5 s before it;
- why the generator stopped there (`ContactGenerator.stop_reasons`): the check that rejected
  most of the postures it tried at that pose ("leg IK", "terrain collision: arm", ...);
- with `--what-if`, whether the same guide, re-planned with each of a few other generator
  settings (`what_if_configs`) or slowed down, passes it.

`--spawns generator` starts the episodes at poses where the generator stands
(`EnvConfig.spawns`); the default keeps the policy's own setting. Writes
guide_failures.json and guide_failures.md into --out.

`--set NAME=VALUE` (repeatable) changes one GeneratorConfig field for the run, e.g. the
generator as it was before a change, to pair with it on other evaluation seeds.

`--compare BEFORE AFTER` runs nothing: it pairs two reports of the same policy (the same
file digest, or the same path in reports without one), starts, seed and spawns (so the same
guides, deterministic episodes), e.g. before and after a
generator change, and writes <out>/paired.json: the guides one covers fully and the other
does not ("fixed", "broken") and a two-sided sign test on those counts.

    python studies/guide_failures.py --policy checkpoints/leas_talos --starts 64 --workers 2 --what-if
    python studies/guide_failures.py --compare OLD/guide_failures.json NEW/guide_failures.json --out NEW

Results (the guides folders of): docs/results/2026-12-01-learned-paper, 2026-12-01-path-condition,
2026-12-01-verified-spawns, 2026-12-02-arms-in, 2026-12-02-column-sampling, 2026-12-02-planner-phase,
2026-12-02-refined-planning-poses, 2026-12-02-retry-settings, 2026-12-02-stance-arm-shifts,
2026-12-02-step-fallback, 2026-12-03-planner-phase-settings, 2026-12-04-ship-learned,
2026-12-05-higher-swing-retries, 2026-12-05-relabelled-condition, 2026-12-05-swing-lift-on-rise.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import re
import sys
from collections import Counter
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "benchmarks")]  # the other studies, benchmarks/common.py

CELL_COMMENT = re.compile(
    r"#\s*cell \((\d+), (\d+)\) \[([-\d.]+), ([-\d.]+)\] x \[([-\d.]+), ([-\d.]+)\]:\s*(\S+)"
)
WINDOW_S = 0.5  # s of guide before the failing pose whose speed and yaw rate are reported


def cell_kinds(terrain_text: str) -> list[tuple[float, float, float, float, str]]:
    """The arena's cells [(x0, x1, y0, y1, kind)] from its generator comments ([] when none)."""
    return [
        (float(m[3]), float(m[4]), float(m[5]), float(m[6]), m[7])
        for m in CELL_COMMENT.finditer(terrain_text)
    ]


def kind_at(cells, xy) -> str:
    """Kind of the cell holding world point `xy` [2] ("unknown" outside every cell)."""
    for x0, x1, y0, y1, kind in cells:
        if x0 <= xy[0] < x1 and y0 <= xy[1] < y1:
            return kind
    return "unknown"


def failing_index(last_valid: int, length: int, stride: int) -> int:
    """Guide index of the planning pose the generator could not pass (see ContactGenerator.plan)."""
    return min(max(last_valid, 0) + stride, length - 1) if last_valid >= 0 else 0


def motion_before(guide: np.ndarray, index: int, timestep: float) -> tuple[float, float]:
    """(speed m/s, |yaw rate| rad/s) of a [T, 4] guide over the WINDOW_S before `index`."""
    back = max(index - round(WINDOW_S / timestep), 0)
    if back == index:
        return 0.0, 0.0
    dt = (index - back) * timestep
    speed = float(np.linalg.norm(guide[index, :2] - guide[back, :2]) / dt)
    yaw = np.unwrap(guide[back : index + 1, 3])
    return speed, float(abs(yaw[-1] - yaw[0]) / dt)


def what_if_configs(base) -> dict:
    """Generator settings tried on the failed guides, each one change from `base`."""
    return {
        "max_foot_yaw=0.8": dataclasses.replace(base, max_foot_yaw=0.8),
        "max_steps_per_pose=4": dataclasses.replace(base, max_steps_per_pose=4),
        "max_candidates=24": dataclasses.replace(base, max_candidates=24),
        "max_root_offset_xy=0.20": dataclasses.replace(base, max_root_offset_xy=0.20),
    }


def slowed(guide: np.ndarray, factor: int) -> np.ndarray:
    """The same path at 1/factor of its speed: [T, 4] -> [(T - 1) * factor + 1, 4], linear in x, y, z, yaw."""
    t = np.arange(len(guide), dtype=np.float64)
    fine = np.linspace(0.0, len(guide) - 1, (len(guide) - 1) * factor + 1)
    yaw = np.unwrap(guide[:, 3])
    return np.stack([np.interp(fine, t, c) for c in (guide[:, 0], guide[:, 1], guide[:, 2], yaw)], axis=1)


def main_reason(reasons: dict) -> str:
    """The check that rejected most postures at a failure ("none" when nothing was tried)."""
    return max(reasons, key=reasons.get) if reasons else "none"


def sign_test(fixed: int, broken: int) -> float:
    """Two-sided exact sign test p-value of `fixed` against `broken` (1.0 without either)."""
    n, k = fixed + broken, min(fixed, broken)
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, i) for i in range(k + 1)) / 2.0**n
    return min(1.0, 2.0 * tail)


def policy_digest(path) -> str:
    """sha256 hex digest of the policy file of a run directory or policy file: the same
    weights and config under another path (a run folder and the checkpoint copied from it)
    give the same digest."""
    import hashlib

    from leas_jax.training.checkpoint import policy_file

    return hashlib.sha256(Path(policy_file(Path(path))).read_bytes()).hexdigest()


def same_policy(before: dict, after: dict) -> bool:
    """Whether two reports judged the same policy: the same `policy_sha256` (`policy_digest`)
    where both hold one, else the same path."""
    if before.get("policy_sha256") and after.get("policy_sha256"):
        return before["policy_sha256"] == after["policy_sha256"]
    return before.get("policy") == after.get("policy")


def paired(before: dict, after: dict) -> dict:
    """Guide-by-guide comparison of two reports of the same episodes (policy, starts, seed,
    spawns): full coverage before and after, the guides fixed and broken, the sign test."""
    from leas_jax.errors import UsageError

    keys = ("policy", "starts", "seed", "spawns", "terrain")
    differ = [k for k in keys[1:] if before.get(k) != after.get(k)]
    if not same_policy(before, after):
        differ.insert(0, "policy")
    if differ:
        raise UsageError(
            f"--compare: the reports differ in {', '.join(differ)}; only reports of the same episodes pair"
        )
    failed_before = {f["start"] for f in before["failures"]}
    failed_after = {f["start"] for f in after["failures"]}
    fixed, broken = sorted(failed_before - failed_after), sorted(failed_after - failed_before)
    return {
        **{k: after[k] for k in keys},
        "full_coverage_before": before["full_coverage"],
        "full_coverage_after": after["full_coverage"],
        "fixed": fixed,
        "broken": broken,
        "p_sign_test": sign_test(len(fixed), len(broken)),
    }


def compare(paths, out: Path) -> dict:
    """`--compare`: pair two guide_failures.json reports, print and save <out>/paired.json."""
    import json

    from common import load_average, save

    from leas_jax.errors import UsageError

    reports = []
    for path in paths:
        try:
            reports.append(json.loads(Path(path).read_text()))
        except (OSError, ValueError) as error:
            raise UsageError(f"--compare: cannot read {path} ({error})") from None
    result = {"before": str(paths[0]), "after": str(paths[1]), **paired(*reports)}
    save("paired", result, load_average(), out)
    print(
        f"{result['policy']}: {100 * result['full_coverage_before']:.1f} -> "
        f"{100 * result['full_coverage_after']:.1f} % fully covered; fixed {len(result['fixed'])}, "
        f"broken {len(result['broken'])} (sign test p = {result['p_sign_test']:.2g})"
    )
    return result


def main(argv=None) -> dict:
    from common import (
        add_generator_settings_argument,
        add_out_argument,
        generator_settings,
        load_average,
        save,
        wilson,
    )

    from leas_jax.contacts.planner.config import GeneratorConfig

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--policy", default="checkpoints/leas_talos", help="run directory or policy.ckpt")
    parser.add_argument("--starts", type=int, default=64)
    parser.add_argument("--seed", type=int, default=0, help="evaluation seed of the resets")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--spawns", choices=["policy", "condition", "generator"], default="policy")
    parser.add_argument(
        "--upper-bodies",
        default=",".join(GeneratorConfig().upper_bodies),
        help="comma-separated upper-body postures the generator may hold (GeneratorConfig.upper_bodies)",
    )
    add_generator_settings_argument(parser)
    parser.add_argument(
        "--what-if", action="store_true", help="re-plan the failed guides with other settings"
    )
    parser.add_argument(
        "--slow-factor", type=int, default=2, help="what-if: the failed guides this much slower"
    )
    parser.add_argument(
        "--compare", nargs=2, metavar=("BEFORE", "AFTER"), help="pair two reports (runs nothing)"
    )
    add_out_argument(parser)
    args = parser.parse_args(argv)
    if args.compare:
        return compare(args.compare, Path(args.out))
    settings = generator_settings(args.set, parser)
    try:
        base = GeneratorConfig(
            upper_bodies=tuple(name for name in args.upper_bodies.split(",") if name), **settings
        )
    except (TypeError, ValueError) as error:
        parser.error(f"--upper-bodies / --set: {error}")
    load_before = load_average()

    from leas_jax.contacts.planner.generator import ContactGenerator
    from leas_jax.contacts.validation.pool import validate_paths
    from leas_jax.eval.geometric import arena_episodes
    from leas_jax.feasibility.spawns import arena_field
    from leas_jax.terrain import load_terrain
    from leas_jax.training.policy import load_policy

    policy = load_policy(args.policy)
    env = policy.config.env
    if args.spawns != "policy":
        env = dataclasses.replace(env, spawns=args.spawns)
        policy = dataclasses.replace(policy, config=dataclasses.replace(policy.config, env=env))
    arena = load_terrain(policy.config.terrain_path())
    field = arena_field(arena, env, workers=args.workers)
    episodes = arena_episodes(policy, field, n=args.starts, seed=args.seed)
    guides = [episodes.poses[k, : episodes.lengths[k]].astype(np.float64) for k in range(args.starts)]
    results = validate_paths(
        arena, guides, env.timestep, workers=args.workers, config=base, return_plans=False
    )
    coverage = np.array([r.coverage for r in results])
    failed = [k for k in range(args.starts) if coverage[k] < 1.0]
    cells = cell_kinds(arena.text)
    failures = []
    explainer = ContactGenerator(arena, base)
    for k in failed:
        index = failing_index(results[k].last_valid_index, len(guides[k]), base.planning_stride(env.timestep))
        speed, yaw_rate = motion_before(guides[k], index, env.timestep)
        _, reasons = explainer.stop_reasons(guides[k], env.timestep)
        failures.append(
            {
                "start": k,
                "coverage": float(coverage[k]),
                "index": index,
                "pose": guides[k][index].tolist(),
                "cell": kind_at(cells, guides[k][index, :2]),
                "speed": speed,
                "yaw_rate": yaw_rate,
                "reasons": dict(reasons),
                "reason": main_reason(reasons),
            }
        )
    what_if = {}
    failed_guides = [guides[k] for k in failed]
    if args.what_if and failed:
        for name, config in what_if_configs(base).items():
            redo = validate_paths(
                arena, failed_guides, env.timestep, workers=args.workers, config=config, return_plans=False
            )
            what_if[name] = [float(r.coverage) for r in redo]
        redo = validate_paths(
            arena,
            [slowed(g, args.slow_factor) for g in failed_guides],
            env.timestep,
            workers=args.workers,
            config=base,
            return_plans=False,
        )
        what_if[f"guide {args.slow_factor}x slower"] = [float(r.coverage) for r in redo]
    full = int(np.sum(coverage >= 1.0))
    start = episodes.poses[:, 0, :2]
    final = episodes.poses[np.arange(args.starts), episodes.lengths - 1, :2]
    moved = np.linalg.norm(final - start, axis=1)
    report = {
        "policy": str(args.policy),
        "policy_sha256": policy_digest(args.policy),
        "terrain": arena.name,
        "upper_bodies": list(base.upper_bodies),
        "generator_settings": {name: repr(value) for name, value in settings.items()},
        "spawns": env.spawns,
        "starts": args.starts,
        "seed": args.seed,
        "full_coverage": full / args.starts,
        "full_coverage_95ci": list(wilson(full, args.starts)),
        "mean_coverage": float(coverage.mean()),
        "failed_at_first_pose": int(sum(f["index"] == 0 for f in failures)),
        "mean_progress_m": float(episodes.mean_progress),
        "mean_displacement_m": float(moved.mean()),
        "valid_fraction": float(episodes.valid_fraction),
        "failures": failures,
        "failures_by_cell": dict(Counter(f["cell"] for f in failures).most_common()),
        "failures_by_reason": dict(Counter(f["reason"] for f in failures).most_common()),
        "failures_with_an_arm_collision": int(
            sum(any(name.endswith(": arm") for name in f["reasons"]) for f in failures)
        ),
        "cells_visited": dict(
            Counter(
                kind_at(cells, p[:2]) for g in guides for p in g[:: base.planning_stride(env.timestep)]
            ).most_common()
        ),
        "what_if": {
            name: {
                "fully_covered_now": int(sum(c >= 1.0 for c in cov)),
                "of_failed": len(failed),
                "mean_coverage_gain": float(np.mean(np.array(cov) - coverage[failed])) if failed else 0.0,
            }
            for name, cov in what_if.items()
        },
    }
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "guide_failures.md").write_text(markdown(report))
    save("guide_failures", report, load_before, out)
    print(markdown(report))
    return report


def markdown(report: dict) -> str:
    """The report's tables: failures by cell kind, motion at the failure, the what-ifs."""
    lo, hi = report["full_coverage_95ci"]
    lines = [
        f"Policy {report['policy']} on {report['terrain']}, spawns {report['spawns']}, "
        f"generator upper bodies {', '.join(report['upper_bodies'])}"
        + "".join(f", {name}={value}" for name, value in report.get("generator_settings", {}).items())
        + f", {report['starts']} starts (seed {report['seed']}): "
        f"{100 * report['full_coverage']:.1f} % [{100 * lo:.1f}, {100 * hi:.1f}] of guides fully covered, "
        f"mean coverage {100 * report['mean_coverage']:.1f} %; {report['failed_at_first_pose']} guides "
        f"fail at their first pose; mean progress along the target direction "
        f"{report['mean_progress_m']:.2f} m; episodes without an invalid pose "
        f"{100 * report['valid_fraction']:.1f} %.",
        "",
        "| cell kind at the failure | failed guides | planning poses visited |",
        "|---|---|---|",
    ]
    for kind, count in report["failures_by_cell"].items():
        lines.append(f"| {kind} | {count} | {report['cells_visited'].get(kind, 0)} |")
    if report["failures"]:
        lines += [
            "",
            "| why it stopped (the check rejecting most postures there) | failed guides |",
            "|---|---|",
        ]
        lines += [f"| {reason} | {count} |" for reason, count in report["failures_by_reason"].items()]
        lines += [
            "",
            f"Failed guides where an arm or gripper met the terrain or the legs at the failure: "
            f"{report['failures_with_an_arm_collision']} / {len(report['failures'])}.",
        ]
        speed = np.array([f["speed"] for f in report["failures"]])
        yaw = np.array([f["yaw_rate"] for f in report["failures"]])
        lines += [
            "",
            f"Before the failure (0.5 s): speed median {np.median(speed):.3f} m/s (max {speed.max():.3f}), "
            f"|yaw rate| median {np.degrees(np.median(yaw)):.1f} deg/s (max {np.degrees(yaw.max()):.1f}).",
        ]
    if report["what_if"]:
        lines += ["", "| what if | failed guides now fully covered | mean coverage gain |", "|---|---|---|"]
    for name, entry in report["what_if"].items():
        lines.append(
            f"| {name} | {entry['fully_covered_now']} / {entry['of_failed']} | {100 * entry['mean_coverage_gain']:+.1f} pts |"
        )
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
