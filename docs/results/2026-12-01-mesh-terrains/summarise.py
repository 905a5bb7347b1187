"""95 % intervals of `leas evaluate` results: a Markdown table per results.json.

Coverage: mean over starts with a percentile bootstrap interval (10 000 resamples,
seed 0); success: Wilson score interval.

    python docs/results/2026-12-01-mesh-terrains/summarise.py DIR [DIR ...]
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np


def wilson(successes: int, trials: int, z: float = 1.96) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion."""
    if trials == 0:
        return 0.0, 1.0
    p = successes / trials
    centre = (p + z * z / (2 * trials)) / (1 + z * z / trials)
    half = z * math.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / (1 + z * z / trials)
    return max(0.0, centre - half), min(1.0, centre + half)


def bootstrap_mean(values: np.ndarray, resamples: int = 10_000, seed: int = 0) -> tuple[float, float]:
    """Percentile bootstrap 95 % interval of the mean."""
    rng = np.random.default_rng(seed)
    means = values[rng.integers(0, len(values), (resamples, len(values)))].mean(axis=1)
    return float(np.percentile(means, 2.5)), float(np.percentile(means, 97.5))


def rows(results: dict, label: str) -> list[str]:
    out = []
    for name, scenario in results["scenarios"].items():
        for method in scenario["methods"]:
            runs = [t for t in scenario["trajectories"] if t["method"] == method]
            coverage = np.array([t["coverage"] for t in runs], dtype=np.float64)
            success = sum(bool(t["success"]) for t in runs)
            lo, hi = bootstrap_mean(coverage)
            slo, shi = wilson(success, len(runs))
            out.append(
                f"| {label} | {name} | {method} | {len(runs)} | {100 * coverage.mean():.1f} "
                f"[{100 * lo:.1f}, {100 * hi:.1f}] | {100 * success / len(runs):.1f} "
                f"[{100 * slo:.1f}, {100 * shi:.1f}] |"
            )
    return out


def main(argv: list[str]) -> int:
    print("| policy | scenario | method | n | coverage % [95 % CI] | success % [95 % CI] |")
    print("|---|---|---|---|---|---|")
    for folder in argv:
        results = json.loads((Path(folder) / "results.json").read_text())
        print(
            "\n".join(
                rows(results, Path(results["policy"]["source"]).parent.name if results["policy"] else "-")
            )
        )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
