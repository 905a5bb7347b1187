"""Contact-planner coverage of LeaS policies over the same starts (host).

Used to compare a geometric policy with its planner-in-the-loop fine-tuning
(docs/design.md §7): on the training arena (random starts and target directions from
the env's own reset) and on evaluation scenarios (their `[scenario]` starts,
through `leas_jax.eval.evaluate`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from leas_jax.eval.geometric import arena_episodes


@dataclass(frozen=True)
class Coverage:
    """Mean contact-plan coverage and fraction of fully covered guides over `n` paths."""

    n: int
    mean_coverage: float
    full_coverage_fraction: float

    def row(self) -> str:
        return f"{100 * self.mean_coverage:.1f} % | {100 * self.full_coverage_fraction:.1f} %"


def arena_coverage(
    policy, terrain, field, n: int = 64, seed: int = 7, workers: int = 2, steps: int = 400
) -> Coverage:
    """Roll the deterministic policy from `n` env resets (seeded) and plan contacts along each guide."""
    from leas_jax.contacts.validation.pool import validate_paths

    episodes = arena_episodes(policy, field, n=n, seed=seed, steps=steps)
    guides = [episodes.poses[k, : episodes.lengths[k]].astype(np.float64) for k in range(n)]
    results = validate_paths(terrain, guides, policy.config.env.timestep, workers=workers, return_plans=False)
    coverage = np.array([r.coverage for r in results])
    return Coverage(
        n=n, mean_coverage=float(coverage.mean()), full_coverage_fraction=float((coverage >= 1.0).mean())
    )


def scenario_coverage(run_dir, scenarios, n_starts: int, workers: int) -> dict:
    """{scenario: Coverage} of the LeaS policy in `run_dir` on evaluation scenarios (same seeded starts)."""
    from leas_jax.eval.evaluate import evaluate

    report = evaluate(
        list(scenarios),
        methods=["leas"],
        checkpoint=run_dir,
        out=None,
        n_starts=n_starts,
        workers=workers,
        progress=False,
        figures=False,
    )
    out = {}
    for name, scenario in report["scenarios"].items():
        coverage = np.array([t["coverage"] for t in scenario["trajectories"] if t["method"] == "leas"])
        out[name] = Coverage(
            n=len(coverage),
            mean_coverage=float(coverage.mean()),
            full_coverage_fraction=float((coverage >= 1.0).mean()),
        )
    return out
