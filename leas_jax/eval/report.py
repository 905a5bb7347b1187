"""`runs/<name>/report.md`: learning curves, geometric evaluation, rollout plots."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from leas_jax.training.checkpoint import atomic_write_text


def read_metrics(run_dir: Path) -> list[dict]:
    """Records of metrics.jsonl (empty list if none)."""
    path = Path(run_dir) / "metrics.jsonl"
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def plot_curves(
    records: list[dict],
    panels: list[tuple[str, str]],
    path: Path,
    steps_scale: float = 1e6,
    steps_label: str = "env steps (M)",
    color: str = "tab:blue",
) -> None:
    """PNG with one panel per (metric key, title) against env steps."""
    from leas_jax.plotting import agg_figure

    steps = np.array([r["env_steps"] for r in records], dtype=float) / steps_scale
    figure = agg_figure(4 * len(panels), 3.2, layout="constrained")
    axes = figure.subplots(1, len(panels))
    for ax, (key, label) in zip(axes, panels):
        ax.plot(steps, np.array([r.get(key, np.nan) for r in records], dtype=float), color=color)
        ax.set_xlabel(steps_label)
        ax.set_title(label, fontsize=10)
        ax.grid(alpha=0.3)
    figure.savefig(path, dpi=110)


GEOMETRIC_PANELS = [
    ("episode_return", "episode return"),
    ("episode_length", "episode length (steps)"),
    ("invalid_fraction", "episodes ending invalid (fraction)"),
    ("sps", "env steps / s"),
]
PLANNER_PANELS = [
    ("mean_coverage", "mean contact-plan coverage"),
    ("full_coverage_fraction", "fully covered paths"),
    ("discarded_fraction", "steps discarded after failure"),
    ("wait_fraction", "learner waiting"),
]


def _geometric_section(run_dir: Path, out: Path, n_episodes: int) -> tuple[list[str], dict]:
    """Markdown lines and figures of a geometric run: learning curves, speed and safety, rollouts."""
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.eval.arena_check import failures_line
    from leas_jax.eval.geometric import (
        ARENA_VALID_TARGET,
        GROUND_SPEED_TARGET,
        arena_episodes,
        failure_breakdown,
        ground_speed,
    )
    from leas_jax.feasibility.spawns import arena_field
    from leas_jax.files import resolve_data_path
    from leas_jax.plotting import plot_paths
    from leas_jax.terrain import load_terrain
    from leas_jax.training.policy import load_policy

    policy = load_policy(run_dir)
    config = policy.config
    records = read_metrics(run_dir)
    if records:
        plot_curves(records, GEOMETRIC_PANELS, out / "learning_curves.png")
    arena = load_terrain(config.terrain_path())
    field = arena_field(arena, config.env)
    episodes = arena_episodes(policy, field, n=n_episodes, seed=1)
    failures = failure_breakdown(field, episodes, config.env.reachability)
    show = min(24, n_episodes)
    colors = [
        "tab:blue" if episodes.lengths[k] == episodes.poses.shape[1] else "tab:red" for k in range(show)
    ]
    plot_paths(
        arena,
        [episodes.poses[k, : episodes.lengths[k]] for k in range(show)],
        out / "rollouts_arena.png",
        title=f"{arena.name}: {show} episodes (red: ended invalid)",
        colors=colors,
    )
    ground = load_terrain(resolve_data_path("terrains/eval_ground.toml"))
    speed = ground_speed(policy, ground, heightfield_from_terrain(ground, config.env), n=n_episodes, seed=2)
    plot_paths(
        ground,
        speed.guides[:16],
        out / "rollouts_ground.png",
        title=f"{ground.name}: 16 random headings, 400 steps",
    )
    results = {
        "env_steps": policy.env_steps,
        "wall_s": records[-1]["wall_s"] if records else None,
        "final_sps": records[-1]["sps"] if records else None,
        "ground_mean_speed": speed.mean_speed,
        "ground_invalid_fraction": speed.invalid_fraction,
        "arena_valid_fraction": episodes.valid_fraction,
        "arena_stopped_fraction_of_valid": episodes.stopped_fraction,
        "arena_mean_progress_m": episodes.mean_progress,
        "episodes_per_metric": n_episodes,
    }
    ok = lambda good: "pass" if good else "FAIL"  # noqa: E731
    last = records[-1] if records else {}
    lines = [
        "## Geometric training",
        "",
        f"Preset `{config.preset}`, seed {config.seed}, terrain `{config.terrain}`, "
        f"{policy.env_steps:,} env steps in {results['wall_s'] or 0:.0f} s "
        f"(last iteration {results['final_sps'] or 0:,.0f} env steps/s).",
        "",
        "![learning curves](learning_curves.png)",
        "",
        f"Last logged iteration: episode return {last.get('episode_return', float('nan')):.1f}, "
        f"episode length {last.get('episode_length', float('nan')):.0f} steps, "
        f"invalid fraction {last.get('invalid_fraction', float('nan')):.3f}.",
        "",
        "| metric (deterministic policy) | value | target | |",
        "|---|---|---|---|",
        f"| {ground.name}: mean speed along the target direction, 400 steps, random headings "
        f"({n_episodes} episodes) | {speed.mean_speed:.3f} m/s | >= {GROUND_SPEED_TARGET} m/s "
        f"| {ok(speed.mean_speed >= GROUND_SPEED_TARGET)} |",
        f"| {arena.name}: episodes without an invalid configuration ({n_episodes} random episodes) "
        f"| {episodes.valid_fraction:.3f} | >= {ARENA_VALID_TARGET} | {ok(episodes.valid_fraction >= ARENA_VALID_TARGET)} |",
        f"| {arena.name}: valid episodes that stopped (last 50 steps < 0.1 m) | "
        f"{episodes.stopped_fraction:.3f} | | |",
        f"| {arena.name}: mean progress along the target direction | {episodes.mean_progress:.2f} m | | |",
        "",
        f"Episodes that end invalid (`leas arena-check` gives more seeds and a map): {failures_line(failures)}",
        "",
        "![arena](rollouts_arena.png)",
        "",
        "![ground](rollouts_ground.png)",
        "",
    ]
    return lines, results


def _planner_section(
    geometric_dir: Path, planner_dir: Path, out: Path, compare_starts: int, workers: int
) -> tuple[list[str], dict]:
    """Markdown lines of the planner phase: curves and coverage before/after over the same starts."""
    from leas_jax.eval.planner_compare import arena_coverage, scenario_coverage
    from leas_jax.feasibility.spawns import arena_field
    from leas_jax.terrain import load_terrain
    from leas_jax.training.policy import load_policy

    records = read_metrics(planner_dir)
    if records:
        plot_curves(
            records,
            PLANNER_PANELS,
            out / "planner_curves.png",
            steps_scale=1e3,
            steps_label="kept env steps (k)",
            color="tab:green",
        )
    rows, results = [], {}
    for label, run in (("geometric", geometric_dir), ("planner fine-tuned", planner_dir)):
        policy = load_policy(run)
        arena = load_terrain(policy.config.terrain_path())
        cov = {
            "training arena": arena_coverage(
                policy,
                arena,
                arena_field(arena, policy.config.env, workers=workers),
                n=compare_starts,
                workers=workers,
            )
        }
        cov.update(scenario_coverage(run, ["bridge", "stairs"], n_starts=compare_starts, workers=workers))
        results[label] = {k: vars(v) for k, v in cov.items()}
        rows += [f"| {label} | {name} | {c.n} | {c.row()} |" for name, c in cov.items()]
    last = records[-1] if records else {}
    lines = [
        "## Planner-in-the-loop fine-tuning",
        "",
        f"{last.get('env_steps', 0):,} kept env steps in {last.get('wall_s', 0):.0f} s; last iteration: "
        f"{last.get('sps', 0):,.0f} kept steps/s, learner waiting {100 * last.get('wait_fraction', 0):.0f} % "
        f"of the time, {100 * last.get('discarded_fraction', 0):.0f} % of the steps discarded.",
        "",
        "![planner curves](planner_curves.png)",
        "",
        "Contact-plan coverage of the deterministic policy, before and after, over the same starts:",
        "",
        "| policy | terrain | paths | mean coverage | fully covered |",
        "|---|---|---|---|---|",
        *rows,
        "",
    ]
    return lines, results


def _baseline_section(planner_dir: Path, out: Path, n_starts: int, workers: int) -> tuple[list[str], dict]:
    """Table II (ground scenario) with RBLin, RBKino and the trained policy, beside the paper."""
    from leas_jax.eval.evaluate import evaluate
    from leas_jax.eval.tables import table_ii_markdown

    report = evaluate(
        ["ground"],
        methods=["rblin", "rbkino", "leas"],
        checkpoint=planner_dir,
        out=out / "evaluation",
        n_starts=n_starts,
        workers=workers,
        progress=False,
    )
    lines = [
        "## Against the baselines",
        "",
        f"{n_starts} trajectories per Table II cell (the paper: 60), the policy above against RBLin and "
        "RBKino; full outputs in `evaluation/`.",
        "",
        table_ii_markdown(report["table_ii"]),
        "",
        *[f"![{name}](evaluation/{name})" for name in report.get("figures", [])],
        "",
    ]
    return lines, {"table_ii": report["table_ii"]}


def write_report(
    out: Path, n_episodes: int = 256, compare_starts: int = 24, baseline_starts: int = 10, workers: int = 2
) -> Path:
    """Evaluate a `leas run` directory and write report.md, eval.json and PNGs into it.

    The report ends with one `leas navigate` query on eval_bridge (plan, figure, time split).

    `out` holds `geometric/` (and, after planner fine-tuning, `planner/`), or
    is itself a single run directory (with `policy.ckpt`).

    Host function (loads files, runs jitted rollouts and contact planning, writes files).
    """
    out = Path(out)
    geometric = out / "geometric" if (out / "geometric").is_dir() else out
    planner = out / "planner" if (out / "planner" / "policy.ckpt").exists() else None
    lines = [f"# LeaS run `{out.name}`", ""]
    section, results = _geometric_section(geometric, out, n_episodes)
    lines += section
    summary = {"geometric": results}
    if planner is not None:
        section, results = _planner_section(geometric, planner, out, compare_starts, workers)
        lines += section
        summary["planner"] = results
    section, results = _baseline_section(planner or geometric, out, baseline_starts, workers)
    lines += section
    summary["baselines"] = results
    from leas_jax.navigate.report import navigate_section

    section, results = navigate_section(planner or geometric, out, workers=workers)
    lines += section
    summary["navigate"] = results
    atomic_write_text(out / "eval.json", json.dumps(summary, indent=2, default=float))
    path = out / "report.md"
    atomic_write_text(path, "\n".join(lines))
    return path
