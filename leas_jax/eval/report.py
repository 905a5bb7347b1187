"""`runs/<name>/report.md`: learning curves, geometric evaluation, rollout plots."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from leas_jax.training.checkpoint import atomic_write_text

GROUND_SPEED_TARGET = 0.12  # m/s, foundation issue acceptance figure
ARENA_VALID_TARGET = 0.90  # fraction of arena episodes without an invalid pose


def read_metrics(run_dir: Path) -> list[dict]:
    """Records of metrics.jsonl (empty list if none)."""
    path = Path(run_dir) / "metrics.jsonl"
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def plot_learning_curves(records: list[dict], path: Path) -> None:
    """PNG of episode return, episode length and invalid fraction against env steps."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    steps = np.array([r["env_steps"] for r in records], dtype=float)
    panels = [("episode_return", "episode return"), ("episode_length", "episode length (steps)"),
              ("invalid_fraction", "episodes ending invalid (fraction)"), ("sps", "env steps / s")]
    figure, axes = plt.subplots(1, len(panels), figsize=(4 * len(panels), 3.2), layout="constrained")
    for ax, (key, label) in zip(axes, panels):
        values = np.array([r.get(key, np.nan) for r in records], dtype=float)
        ax.plot(steps / 1e6, values, color="tab:blue")
        ax.set_xlabel("env steps (M)")
        ax.set_title(label, fontsize=10)
        ax.grid(alpha=0.3)
    figure.savefig(path, dpi=110)
    plt.close(figure)


def write_report(run_dir: Path, n_episodes: int = 256, eval_terrain: str = "terrains/eval_ground.toml") -> Path:
    """Evaluate the run's policy and write report.md, eval.json and PNGs into `run_dir`.

    Host function (loads files, runs jitted rollouts, writes files).
    """
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.eval.geometric import arena_episodes, ground_speed
    from leas_jax.steering.commands import plot_paths
    from leas_jax.terrain import load_terrain
    from leas_jax.training.config import resolve_data_path
    from leas_jax.training.policy import load_policy

    run_dir = Path(run_dir)
    policy = load_policy(run_dir)
    config = policy.config
    records = read_metrics(run_dir)
    if records:
        plot_learning_curves(records, run_dir / "learning_curves.png")

    arena = load_terrain(config.terrain_path())
    arena_field = heightfield_from_terrain(arena, config.env)
    episodes = arena_episodes(policy, arena_field, n=n_episodes, seed=1)
    show = min(24, n_episodes)
    colors = ["tab:blue" if episodes.lengths[k] == episodes.poses.shape[1] else "tab:red" for k in range(show)]
    plot_paths(arena, [episodes.poses[k, : episodes.lengths[k]] for k in range(show)],
               run_dir / "rollouts_arena.png", title=f"{arena.name}: {show} episodes (red: ended invalid)",
               colors=colors)

    ground = load_terrain(resolve_data_path(eval_terrain))
    ground_field = heightfield_from_terrain(ground, config.env)
    speed = ground_speed(policy, ground, ground_field, n=n_episodes, seed=2)
    plot_paths(ground, speed.guides[:16], run_dir / "rollouts_ground.png",
               title=f"{ground.name}: 16 random headings, 400 steps")

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
    atomic_write_text(run_dir / "eval.json", json.dumps(results, indent=2))
    ok = lambda good: "pass" if good else "FAIL"  # noqa: E731
    last = records[-1] if records else {}
    lines = [
        f"# LeaS run `{run_dir.name}`",
        "",
        f"Preset `{config.preset}`, seed {config.seed}, terrain `{config.terrain}`, "
        f"{policy.env_steps:,} env steps in {results['wall_s'] or 0:.0f} s "
        f"(last iteration {results['final_sps'] or 0:,.0f} env steps/s).",
        "",
        "## Learning curves",
        "",
        "![learning curves](learning_curves.png)",
        "",
        f"Last logged iteration: episode return {last.get('episode_return', float('nan')):.1f}, "
        f"episode length {last.get('episode_length', float('nan')):.0f} steps, "
        f"invalid fraction {last.get('invalid_fraction', float('nan')):.3f}.",
        "",
        "## Geometric evaluation (deterministic policy)",
        "",
        "| metric | value | target | |",
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
        "## Rollouts",
        "",
        "![arena](rollouts_arena.png)",
        "",
        "![ground](rollouts_ground.png)",
        "",
    ]
    path = run_dir / "report.md"
    atomic_write_text(path, "\n".join(lines))
    return path
