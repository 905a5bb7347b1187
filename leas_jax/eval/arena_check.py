"""`leas arena-check`: the foundation's speed and safety figures of a policy, and why episodes fail.

For a trained policy (deterministic): the mean speed along the target direction on
`eval_ground` from random headings, the fraction of random episodes on the training
arena that never reach an invalid pose (over several evaluation seeds), and for the
episodes that do, which reachability term fails, where the offending terrain lies
around the root and how fast it moved (`leas_jax.eval.geometric.failure_breakdown`).
Writes arena_check.json, arena_check.md and arena_failures.png (the arena with each
first invalid pose, coloured by the failed term, its heading as a tick).
"""

from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path

import numpy as np

from leas_jax.errors import UsageError
from leas_jax.eval.geometric import FailureBreakdown

TERM_COLORS = {"trunk_free": "tab:red", "left_touch": "tab:blue", "right_touch": "tab:green"}


def parse_seeds(text: str) -> tuple[int, ...]:
    """'0,1' -> (0, 1), unique, in order; a bad entry raises UsageError naming --seeds."""
    try:
        seeds = tuple(dict.fromkeys(int(s) for s in text.split(",") if s.strip()))
    except ValueError:
        raise UsageError(f"--seeds: expected comma-separated integers, got {text!r}") from None
    if not seeds or min(seeds) < 0:
        raise UsageError(f"--seeds: expected comma-separated integers >= 0, got {text!r}")
    return seeds


def arena_check(
    checkpoint, episodes: int = 2048, seeds=(0, 1), ground_episodes: int = 256, terrain_file=None, out=None
) -> dict:
    """Speed, safety and failure breakdown of a policy.

    Args:
        checkpoint: run directory or policy.ckpt.
        episodes: arena episodes per seed (400 steps each, the env's random resets).
        seeds: evaluation seeds of the arena episodes.
        ground_episodes: eval_ground episodes of the speed test (seed 2, as `make run`'s report).
        terrain_file: the arena (default: the policy's training terrain).
        out: directory for arena_check.json, arena_check.md and arena_failures.png (None: none).

    Returns:
        {"policy", "terrain", "episodes", "ground": {...}, "arena": {seed: {...}}, "targets", "seconds"}.
    """
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.eval.geometric import (
        ARENA_VALID_TARGET,
        GROUND_SPEED_TARGET,
        arena_episodes,
        failure_breakdown,
        ground_speed,
    )
    from leas_jax.feasibility.spawns import arena_field
    from leas_jax.files import resolve_data_path
    from leas_jax.terrain import load_terrain
    from leas_jax.training.policy import load_policy

    if episodes < 1:
        raise UsageError(f"--episodes: expected a positive integer, got {episodes}")
    if ground_episodes < 1:
        raise UsageError(f"ground_episodes: expected a positive integer, got {ground_episodes}")
    began = time.perf_counter()
    policy = load_policy(checkpoint)
    env = policy.config.env
    arena = load_terrain(terrain_file if terrain_file is not None else policy.config.terrain_path())
    field = arena_field(arena, env)
    ground = load_terrain(resolve_data_path("terrains/eval_ground.toml"))
    speed = ground_speed(policy, ground, heightfield_from_terrain(ground, env), n=ground_episodes, seed=2)
    report = {
        "format": "leas-arena-check-v1",
        "policy": {
            "source": policy.source,
            "env_steps": int(policy.env_steps),
            "preset": policy.config.preset,
            "seed": policy.config.seed,
        },
        "terrain": arena.path or arena.name,
        "episodes": episodes,
        "targets": {"ground_mean_speed": GROUND_SPEED_TARGET, "arena_valid_fraction": ARENA_VALID_TARGET},
        "ground": {
            "episodes": ground_episodes,
            "mean_speed": speed.mean_speed,
            "invalid_fraction": speed.invalid_fraction,
        },
        "arena": {},
    }
    first = None
    for seed in seeds:
        result = arena_episodes(policy, field, n=episodes, seed=seed)
        first = first or result
        report["arena"][str(seed)] = {
            "valid_fraction": result.valid_fraction,
            "stopped_fraction_of_valid": result.stopped_fraction,
            "mean_progress_m": result.mean_progress,
            "failures": dataclasses.asdict(failure_breakdown(field, result, env.reachability)),
        }
    report["seconds"] = round(time.perf_counter() - began, 3)
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "arena_check.json").write_text(json.dumps(report, indent=1) + "\n")
        (out / "arena_check.md").write_text(markdown(report))
        failures_figure(
            arena, field, first, out / "arena_failures.png", seed=seeds[0], config=env.reachability
        )
    return report


def _counts(table: dict) -> str:
    return ", ".join(f"{key} {value}" for key, value in sorted(table.items(), key=lambda kv: -kv[1])) or "-"


def markdown(report: dict) -> str:
    """The figures of an `arena_check` report as a Markdown table and a failure breakdown per seed."""
    targets, ground = report["targets"], report["ground"]
    policy = report["policy"]
    lines = [
        f"Policy `{policy['source']}` ({policy['env_steps']:,} env steps, preset `{policy['preset']}`, "
        f"seed {policy['seed']}); arena `{report['terrain']}`.",
        "",
        "| metric (deterministic policy) | value | target |",
        "|---|---|---|",
        f"| eval_ground: mean speed along the target direction, 400 steps, random headings "
        f"({ground['episodes']} episodes) | {ground['mean_speed']:.3f} m/s | >= {targets['ground_mean_speed']} |",
    ]
    for seed, arena in report["arena"].items():
        lines.append(
            f"| arena: episodes without an invalid pose ({report['episodes']} episodes, seed {seed}) "
            f"| {100 * arena['valid_fraction']:.1f} % | >= {100 * targets['arena_valid_fraction']:.0f} % |"
        )
    lines += ["", "Episodes that end invalid (first invalid pose):", ""]
    lines += [
        f"- seed {seed}: {failures_line(FailureBreakdown(**arena['failures']))}"
        for seed, arena in report["arena"].items()
    ]
    return "\n".join(lines) + "\n"


def failures_line(failures) -> str:
    """One Markdown sentence of a `FailureBreakdown`."""
    if failures.invalid == 0:
        return "none."
    return (
        f"{failures.invalid} episodes. Failed terms: {_counts(failures.terms)}. Terrain in the trunk cylinder: "
        f"{_counts(failures.trunk_bearing)}. Motion: {_counts(failures.motion_bearing)}. Speed quartiles "
        f"{failures.speed_quartiles} m/s, step quartiles {failures.step_quartiles}."
    )


def failures_figure(terrain, field, episodes, path: Path, seed: int, config) -> None:
    """PNG of the arena with each episode's first invalid pose, coloured by the failed term.

    field: the episodes' heightfield; config: their `ReachabilityConfig`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from leas_jax.eval.geometric import reachability_terms
    from leas_jax.plotting import draw_heightmap

    figure, axes = plt.subplots(figsize=(9, 9), layout="constrained")
    draw_heightmap(axes, terrain)
    failed = episodes.failure_poses[~np.isnan(episodes.failure_poses[:, 0])]
    if len(failed):
        terms = reachability_terms(field, failed, config)
        for name, color in TERM_COLORS.items():
            chosen = failed[~terms[name]]
            axes.plot(
                chosen[:, 0],
                chosen[:, 1],
                "o",
                color=color,
                markersize=4,
                label=f"{name} fails",
                markeredgecolor="black",
                markeredgewidth=0.4,
            )
            for x, y, _, yaw in chosen:
                axes.plot(
                    [x, x + 0.35 * np.cos(yaw)], [y, y + 0.35 * np.sin(yaw)], "-", color=color, linewidth=0.8
                )
        axes.legend(loc="upper right", fontsize=8)
    axes.set_title(
        f"{terrain.name}: first invalid pose of the {len(failed)} of {len(episodes.failure_poses)} "
        f"episodes that end invalid (seed {seed}; tick: heading)",
        fontsize=9,
    )
    figure.savefig(path, dpi=90)
    plt.close(figure)
