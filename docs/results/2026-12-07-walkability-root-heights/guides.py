"""Would a walkability model, as the env's termination condition, end the guides the generator walks?

For each successful guide of `leas evaluate` folders (the plan covers the guide and ends at the
target), a pose is rejected where the plausible cylinders or the model's network reject it at the
guide's own root height (the env's `walkability` condition). Prints, per model and scenario, the
guides with a rejected pose (and those where the plausible cylinders reject one, whatever the
network says), the share of poses rejected, and the longest run of consecutive
rejected poses per guide (what a termination that waits that many steps would let pass), the range
over guides of the lowest network logit among its plausible poses (a threshold below it ends none
of them), and the
root height's distance from the lattice's nominal height (5 / 50 / 95 %).

    python docs/results/2026-12-07-walkability-root-heights/guides.py \
        --models before=/tmp/walk_nom/walkability.npz shipped=checkpoints/walkability/walkability.npz \
        --guides /tmp/cg_eval /tmp/cg_eval_hpp > docs/results/2026-12-07-walkability-root-heights/guides.md
"""

from __future__ import annotations

import argparse
import collections
import json
from pathlib import Path

import numpy as np

# `reachability.margins` of the plausible cylinders (no lookahead, no foothold): the trunk, the
# ground under each leg too far below (leg_bottom) and too high (leg_top), each hand
TERMS = (
    "trunk",
    "left leg's ground too low",
    "right leg's ground too low",
    "left leg's ground too high",
    "right leg's ground too high",
    "left hand",
    "right hand",
)


def runs(rejected: np.ndarray) -> list[int]:
    """Lengths of the runs of consecutive True in a bool [T]."""
    edges = np.diff(np.concatenate([[0], rejected.astype(int), [0]]))
    return (np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)).tolist()


def main() -> None:
    import jax
    import jax.numpy as jnp

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.env import reachability
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.env.field import sample_nearest
    from leas_jax.feasibility import walkability as wk
    from leas_jax.files import resolve_data_path
    from leas_jax.terrain import load_terrain

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", nargs="+", required=True, metavar="NAME=WEIGHTS.npz")
    parser.add_argument("--guides", nargs="+", required=True, metavar="EVALUATION_DIR")
    args = parser.parse_args()
    reach = ReachabilityConfig()
    relaxed = reachability.relaxed_reachability(reach)
    models = {n: wk.load_walkability(p, reach) for n, p in (s.split("=", 1) for s in args.models)}
    print(
        "| model | scenario | guides ended | of them by the plausible cylinders | poses rejected | "
        "longest rejected run per guide (poses) | lowest logit of a plausible pose per guide (range) |"
    )
    print("|---|---|---|---|---|---|---|")
    heights = {}
    failing = collections.defaultdict(collections.Counter)
    for name, model in models.items():
        for folder in map(Path, args.guides):
            results = json.loads((folder / "results.json").read_text())
            with np.load(folder / "guides.npz") as stored:
                for scenario, entry in results["scenarios"].items():
                    field = wk._field(load_terrain(resolve_data_path(entry["terrain"])))
                    verdicts = jax.jit(
                        jax.vmap(
                            lambda q, f=field, m=model: (
                                reachability.valid(f, q, relaxed),
                                lf.logit(m, f, q, reach),
                                reachability.margins(f, q, relaxed),
                            )
                        )
                    )
                    guides = [
                        jnp.asarray(stored[f"{scenario}/{k}"], jnp.float32)
                        for k, t in enumerate(entry["trajectories"])
                        if t["success"]
                    ]
                    plausible, logits, margins = zip(
                        *[map(np.asarray, verdicts(g)) for g in guides], strict=True
                    )
                    network = [lg >= float(model["threshold"]) for lg in logits]
                    lowest = [float(lg[p].min()) for lg, p in zip(logits, plausible, strict=True) if p.any()]
                    for p, m in zip(plausible, margins, strict=True):
                        failing[scenario].update(TERMS[int(np.argmin(row))] for row in m[~p])
                    rejected = [~(p & n) for p, n in zip(plausible, network, strict=True)]
                    implausible = sum((~p).any() for p in plausible)
                    longest = sorted(max(runs(r), default=0) for r in rejected)
                    share = 100 * np.mean(np.concatenate(rejected))
                    ended = sum(r.any() for r in rejected)
                    print(
                        f"| {name} | {scenario} | {ended} / {len(guides)} | {implausible} / {len(guides)} | "
                        f"{share:.1f} % | "
                        f"{', '.join(map(str, longest))} | {min(lowest):.1f} .. {max(lowest):.1f} |"
                    )
                    nominal = [
                        np.asarray(g[:, 2] - sample_nearest(field, field.leg_max, g[:, :2])) - 1.0
                        for g in guides
                    ]
                    heights[scenario] = np.percentile(np.concatenate(nominal), [5, 50, 95])
    print("\nPoses the plausible cylinders reject, by their most violated term (both models): ", end="")
    print("; ".join(f"{s} {dict(c)}" for s, c in failing.items() if c) or "none")
    print("\nRoot height minus the lattice's (m), 5 / 50 / 95 %: ", end="")
    print("; ".join(f"{s} {' / '.join(f'{v:+.3f}' for v in p)}" for s, p in heights.items()))


if __name__ == "__main__":
    main()
