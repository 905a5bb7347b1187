"""How many guides the contact generator follows to the target would a termination condition end?

Reads a `leas evaluate` output folder (results.json, guides.npz), keeps each scenario's
successful guides (the contact plan covers the whole guide and ends at the target), and
evaluates the termination condition of another policy's env (`--policy`: its
`EnvConfig.condition`, cylinders or the learned network, on that scenario's terrain) at
every pose of them. A condition that ends many of these guides teaches a policy trained
with it to avoid the terrain they cross: its per-pose false rejections compound along a
path. Writes condition_on_guides.json and .md into --out.

    leas evaluate --scenario bridge,stairs,stairs_side --methods leas \
        --checkpoint checkpoints/leas_talos/pretrain --out /tmp/cylinders_eval
    python studies/condition_on_guides.py --evaluation /tmp/cylinders_eval \
        --policy docs/results/2026-12-01-learned-paper/train_paper_learned --out DIR

Results: docs/results/2026-12-01-learned-paper, docs/results/2026-12-01-path-condition.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "benchmarks")]  # the other studies, benchmarks/common.py


def rejection_fn(field, env_config):
    """Jitted: [T, 4] guide poses (x, y, z, yaw), world -> bool [T], the condition rejects each."""
    import jax

    from leas_jax.env import condition

    valid = jax.jit(jax.vmap(lambda pose: condition.valid(field, pose, env_config)))
    return lambda guide: ~np.asarray(valid(np.asarray(guide, np.float32)))


def main(argv=None) -> dict:
    from common import add_out_argument, load_average, save, wilson

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--evaluation", type=Path, required=True, help="a `leas evaluate` --out folder")
    parser.add_argument(
        "--policy", required=True, help="run directory or policy.ckpt whose condition is applied"
    )
    add_out_argument(parser)
    args = parser.parse_args(argv)
    load_before = load_average()

    from leas_jax.env import heightfield_from_terrain
    from leas_jax.files import resolve_data_path
    from leas_jax.terrain import load_terrain
    from leas_jax.training.policy import load_policy

    env = load_policy(args.policy).config.env
    results = json.loads((args.evaluation / "results.json").read_text())
    rows = {}
    with np.load(args.evaluation / "guides.npz") as guides:
        for name, scenario in results["scenarios"].items():
            terrain = load_terrain(resolve_data_path(scenario["terrain"]))
            rejects = rejection_fn(heightfield_from_terrain(terrain, env), env)
            successful = [k for k, t in enumerate(scenario["trajectories"]) if t["success"]]
            per_guide = [rejects(guides[f"{name}/{k}"]) for k in successful]
            ended = int(sum(r.any() for r in per_guide))
            rows[name] = {
                "successful_guides": len(successful),
                "ended_by_condition": ended,
                "ended_fraction_95ci": list(wilson(ended, len(successful))),
                "poses_rejected": float(np.mean(np.concatenate(per_guide))) if per_guide else float("nan"),
            }
    report = {
        "evaluation": str(args.evaluation),
        "guides_policy": results.get("policy", {}).get("source") if results.get("policy") else None,
        "condition_policy": str(args.policy),
        "condition": env.condition,
        "scenarios": rows,
    }
    lines = [
        f"Condition of {args.policy} ({env.condition}) on the successful guides of "
        f"{report['guides_policy']} ({args.evaluation}).",
        "",
        "| scenario | successful guides | ended by the condition [95 % CI] | poses rejected |",
        "|---|---|---|---|",
    ]
    for name, row in rows.items():
        lo, hi = row["ended_fraction_95ci"]
        lines.append(
            f"| {name} | {row['successful_guides']} | {row['ended_by_condition']} "
            f"[{100 * lo:.1f}, {100 * hi:.1f} %] | {100 * row['poses_rejected']:.1f} % |"
        )
    text = "\n".join(lines) + "\n"
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "condition_on_guides.md").write_text(text)
    save("condition_on_guides", report, load_before, out)
    print(text)
    return report


if __name__ == "__main__":
    main()
