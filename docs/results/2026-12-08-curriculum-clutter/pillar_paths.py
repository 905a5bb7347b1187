"""Draws one policy's LeaS guides on some of `studies/pillar_fields.py`'s fields, rolled through
the termination as `leas evaluate` rolls them (its 10 seeded starts per field and its horizon):
green guides reach the target, red ones do not; dotted circles mark 0.30 m (the trunk cylinder's
radius) round each pillar; a dot every 2 s.

    python docs/results/2026-12-08-curriculum-clutter/pillar_paths.py runs/generalist_clutter3_s0 2,13,16 paths.png
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "studies"))
from pillar_fields import START, TARGET, pillar_boxes, pillar_field  # noqa: E402

from leas_jax import load_policy, loads_terrain  # noqa: E402
from leas_jax.env import heightfield_from_terrain  # noqa: E402
from leas_jax.eval.scenarios import cells_for, draw_starts  # noqa: E402
from leas_jax.steering.horizon import leas_horizon  # noqa: E402
from leas_jax.steering.leas import rollout_batch  # noqa: E402

STARTS = 10
TRUNK_RADIUS = 0.30  # m


def draw(ax, policy, seed: int) -> None:
    """Field `seed`'s pillars and the policy's guides from its seeded starts."""
    env = policy.config.env
    terrain = loads_terrain(pillar_field(seed, STARTS))
    scenario = terrain.scenario
    field = heightfield_from_terrain(terrain, env)
    starts = draw_starts(
        scenario, cells_for(terrain.name, scenario)[0], STARTS, scenario.seed, field, env.nominal_root_height
    )
    steps = leas_horizon(START, np.array([TARGET]), env.target_speed, env.timestep, env.episode_length)
    result = rollout_batch(
        policy,
        field,
        starts.poses,
        np.tile(TARGET, (STARTS, 1)),
        starts.speeds,
        steps,
        stop_at_invalid=False,
    )
    for x, y, side, _ in pillar_boxes(seed):
        ax.add_patch(plt.Rectangle((x - side / 2, y - side / 2), side, side, color="k"))
        ax.add_patch(plt.Circle((x, y), side / 2 + TRUNK_RADIUS, fill=False, ls=":"))
    for n in range(STARTS):
        path = result.guide(n)
        ax.plot(path[:, 0], path[:, 1], "g-" if result.reached[n] else "r-", lw=0.8)
        ax.plot(path[::20, 0], path[::20, 1], "k.", ms=2)
    ax.plot(*TARGET, "b*")
    ax.set(
        xlim=(3.5, 11.0),
        ylim=(1.5, 6.5),
        aspect="equal",
        title=f"field {seed}: {result.reached.sum()} / {STARTS}",
    )


def main() -> None:
    run, seeds, out = sys.argv[1], [int(s) for s in sys.argv[2].split(",")], sys.argv[3]
    policy = load_policy(run)
    figure, axes = plt.subplots(1, len(seeds), figsize=(5 * len(seeds), 3.6), layout="constrained")
    for ax, seed in zip(np.atleast_1d(axes), seeds, strict=True):
        draw(ax, policy, seed)
    figure.savefig(out, dpi=80)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
