"""Are the poses the walkability model rejects on covered stair guides walkable by its own label?

For each covered guide of the paper-arena policy on a scenario (`leas evaluate --methods leas`,
seeded starts), takes the first pose the walkability network rejects and labels it with the
model's own walking truth (`walking_truth.walking_guide`: the generator on a 0.36 m straight guide
at the pose's height), and with the same guide lifted to follow the policy's own path (the next
0.36 m of the covered guide). A pose walkable by the first is a model error; walkable only by
the second, a label that cannot climb.

    python docs/results/2026-12-07-generalist-recipe/rejected_poses_walked.py --starts 10
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

SCENARIOS = {"eval_stairs": "terrains/eval_stairs.toml", "hpp_stairs": "terrains/hpp/stairs.toml"}


def main() -> None:
    from leas_jax.contacts.planner.generator import ContactGenerator
    from leas_jax.env import heightfield_from_terrain, learned_feasibility
    from leas_jax.eval.evaluate import evaluate
    from leas_jax.feasibility.walking_truth import WALK_POSES, WALK_TIMESTEP, walking_guide
    from leas_jax.terrain import load_terrain
    from leas_jax.training.config import preset

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--policy", default="checkpoints/leas_talos/pretrain")
    parser.add_argument("--starts", type=int, default=10)
    args = parser.parse_args()
    env = preset("generalist").env
    for label, terrain_file in SCENARIOS.items():
        with tempfile.TemporaryDirectory() as tmp:
            evaluate(
                [],
                methods=["leas"],
                checkpoint=args.policy,
                out=tmp,
                n_starts=args.starts,
                workers=1,
                terrain_file=terrain_file,
                progress=False,
                figures=False,
            )
            report = json.loads((Path(tmp) / "results.json").read_text())
            stored = np.load(Path(tmp) / "guides.npz")
            name = next(iter(report["scenarios"]))
            runs = report["scenarios"][name]["trajectories"]
            guides = [stored[f"{name}/{k}"] for k, t in enumerate(runs) if t["coverage"] >= 1.0]
        terrain = load_terrain(terrain_file)
        field = heightfield_from_terrain(terrain, env)
        params = field.condition
        network = jax.jit(
            jax.vmap(lambda q, p=params, f=field: learned_feasibility.valid(p, f, q, env.reachability))
        )
        generator = ContactGenerator(terrain)
        own, following = 0, 0
        for guide in guides:
            ok = np.asarray(network(jnp.asarray(guide, jnp.float32)))
            k = int(np.argmin(ok))
            pose = guide[k]
            own += generator.plan(walking_guide(pose), WALK_TIMESTEP).coverage >= 1.0
            ahead = guide[k : k + WALK_POSES]
            following += generator.plan(ahead, WALK_TIMESTEP).coverage >= 1.0
        print(
            f"{label}: {len(guides)} covered guides, each with a rejected pose; its label's flat guide "
            f"walked from {own}, the guide's own next 0.36 m from {following}",
            flush=True,
        )


if __name__ == "__main__":
    main()
