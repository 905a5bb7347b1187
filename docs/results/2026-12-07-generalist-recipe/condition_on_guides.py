"""Which termination conditions reject poses of guides the contact generator walks?

Runs `leas evaluate --methods leas` with a policy on scenarios, keeps the guides the generator
covers whole, and judges every pose of them with each env condition as a training episode
would: the `generalist` preset's (walkability model and its relaxed cylinders) and the
arena-fitted learned condition (`learned_condition_env`, the shipped policy's). A guide with a
rejected pose is one whose training episode would have ended there.

    python docs/results/2026-12-07-generalist-recipe/condition_on_guides.py \
        --policy checkpoints/leas_talos/pretrain --starts 10 --out OUT

Writes `condition_on_guides.json` and `.md` into --out.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

SCENARIOS = {
    "eval_stairs": "terrains/eval_stairs.toml",
    "eval_stairs_side": "terrains/eval_stairs_side.toml",
    "eval_circuit": "terrains/eval_circuit.toml",
    "hpp_stairs": "terrains/hpp/stairs.toml",
    "pillars_in_the_way": "terrains/checks/pillars_in_the_way.toml",
}


def conditions():
    from leas_jax.training.config import learned_condition_env, preset

    generalist = preset("generalist").env
    return {"walkability": generalist, "learned": learned_condition_env(generalist)}


def judge(terrain_file: str, guides: list[np.ndarray]) -> dict:
    """Per condition: guides with a rejected pose, share of poses rejected, the first
    rejected pose's distance along its guide (median, m)."""
    from leas_jax.env import condition, heightfield_from_terrain
    from leas_jax.terrain import load_terrain

    terrain = load_terrain(terrain_file)
    rows = {}
    for name, env in conditions().items():
        field = heightfield_from_terrain(terrain, env)
        valid = jax.jit(jax.vmap(lambda pose, f=field, e=env: condition.valid(f, pose, e)))
        rejected, poses, first = 0, [], []
        for guide in guides:
            ok = np.asarray(valid(jnp.asarray(guide, jnp.float32)))
            poses.append(1.0 - ok.mean())
            if not ok.all():
                rejected += 1
                k = int(np.argmin(ok))
                first.append(float(np.linalg.norm(np.diff(guide[: k + 1, :2], axis=0), axis=1).sum()))
        rows[name] = {
            "guides": len(guides),
            "guides_with_a_rejected_pose": rejected,
            "poses_rejected_percent": round(100 * float(np.mean(poses)), 2),
            "first_rejection_along_guide_m": round(float(np.median(first)), 2) if first else None,
        }
    return rows


def main() -> None:
    from leas_jax.eval.evaluate import evaluate

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--policy", required=True)
    parser.add_argument("--starts", type=int, default=10)
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results = {"policy": args.policy, "starts": args.starts, "scenarios": {}}
    for label, terrain_file in SCENARIOS.items():
        with tempfile.TemporaryDirectory() as tmp:
            evaluate(
                [],
                methods=["leas"],
                checkpoint=args.policy,
                out=tmp,
                n_starts=args.starts,
                workers=args.workers,
                terrain_file=terrain_file,
                progress=False,
                figures=False,
            )
            report = json.loads((Path(tmp) / "results.json").read_text())
            stored = np.load(Path(tmp) / "guides.npz")
            (scenario,) = report["scenarios"].values()
            name = next(iter(report["scenarios"]))
            guides = [
                stored[f"{name}/{k}"]
                for k, t in enumerate(scenario["trajectories"])
                if t["coverage"] >= 1.0 and f"{name}/{k}" in stored.files
            ]
        results["scenarios"][label] = judge(terrain_file, guides)
        print(label, json.dumps(results["scenarios"][label]), flush=True)
    (out / "condition_on_guides.json").write_text(json.dumps(results, indent=1))
    lines = [
        "| scenario | covered guides | condition | guides with a rejected pose | poses rejected % | first rejection along the guide (median, m) |",
        "|---|---|---|---|---|---|",
    ]
    for label, rows in results["scenarios"].items():
        for name, r in rows.items():
            lines.append(
                f"| {label} | {r['guides']} | {name} | {r['guides_with_a_rejected_pose']} | "
                f"{r['poses_rejected_percent']} | {r['first_rejection_along_guide_m']} |"
            )
    (out / "condition_on_guides.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
