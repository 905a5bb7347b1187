"""Are the poses the walkability model rejects on stair guides walkable by its own label?

Reads `leas evaluate` output folders (results.json, guides.npz), keeps each scenario's successful
guides, takes the first pose of each that the walkability network rejects, and plans from it
with the contact generator: the model's own walking truth (`walking_truth.walking_guide`: a
0.36 m straight guide at the pose's height) and the guide's own next 0.36 m. A rejected pose
the generator walks from is the model's error.

    python docs/results/2026-12-07-generalist-recipe/rejected_poses_walked.py /tmp/cg_eval /tmp/cg_eval_hpp
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np


def main() -> None:
    from leas_jax.contacts.planner.generator import ContactGenerator
    from leas_jax.env import heightfield_from_terrain, learned_feasibility
    from leas_jax.feasibility.walking_truth import WALK_POSES, WALK_TIMESTEP, walking_guide
    from leas_jax.files import resolve_data_path
    from leas_jax.terrain import load_terrain
    from leas_jax.training.config import preset

    env = preset("generalist").env
    for folder in map(Path, sys.argv[1:]):
        results = json.loads((folder / "results.json").read_text())
        with np.load(folder / "guides.npz") as stored:
            for name, scenario in results["scenarios"].items():
                guides = [
                    stored[f"{name}/{k}"] for k, t in enumerate(scenario["trajectories"]) if t["success"]
                ]
                terrain = load_terrain(resolve_data_path(scenario["terrain"]))
                field = heightfield_from_terrain(terrain, env)
                network = jax.jit(
                    jax.vmap(
                        lambda q, f=field: learned_feasibility.valid(f.condition, f, q, env.reachability)
                    )
                )
                generator = ContactGenerator(terrain)
                rejected, own, ahead = 0, 0, 0
                for guide in guides:
                    ok = np.asarray(network(jnp.asarray(guide, jnp.float32)))
                    if ok.all():
                        continue
                    k = int(np.argmin(ok))
                    rejected += 1
                    own += generator.plan(walking_guide(guide[k]), WALK_TIMESTEP).coverage >= 1.0
                    ahead += generator.plan(guide[k : k + WALK_POSES], WALK_TIMESTEP).coverage >= 1.0
                print(
                    f"{name}: {len(guides)} successful guides, {rejected} with a pose the network rejects; "
                    f"from the first of each the generator walks the label's guide {own} times, "
                    f"the guide's own next 0.36 m {ahead} times",
                    flush=True,
                )


if __name__ == "__main__":
    main()
