"""Where LeaS policies leave eval_bridge's 0.30 m bridge: each policy rolls out from the scenario's
seeded starts (`--starts`, drawn as `leas evaluate` draws them) towards the target, once ending each path at
its own termination (as in training) and once rolling through it (as `leas evaluate` does). For the
paths its termination ends within 0.5 m of the bridge's head (x 3.5-4.5 m, |y - 5| < 0.5 m), it
prints the last pose kept: the root's offset from the bridge's centre line, its yaw to the bridge
and its height above the bridge; for the rolled-through paths that reach the target, the lowest
root on the bridge and the largest offset and yaw there. First, the play its termination leaves on
the bridge: the largest offset from the centre line (0.01 m steps) at which a pose at mid-bridge,
along it, at the nominal height is accepted.

    python docs/results/2026-12-08-curriculum-clutter/bridge_entry.py \\
        --policy paper_arena=checkpoints/leas_talos/pretrain --policy LABEL=RUN ... > bridge_entry.md
"""

from __future__ import annotations

import argparse

import jax
import jax.numpy as jnp
import numpy as np

from leas_jax import load_policy, load_terrain
from leas_jax.env import condition, heightfield_from_terrain
from leas_jax.eval.scenarios import cells_for, draw_starts
from leas_jax.steering.leas import rollout_batch

TERRAIN = "terrains/eval_bridge.toml"
BRIDGE_Y = 5.0  # m, the bridge's centre line (x 4..7 m, 0.30 m wide, top at z = 0)
BRIDGE_X = (4.0, 7.0)
HEAD_X = (3.5, 4.5)
STEPS = 900  # the evaluation's horizon on this route (`leas_horizon`, 2 x the walk at 0.18 m/s)


def play(field, config) -> float:
    """m, the largest offset from the centre line, either side, that `config`'s condition
    accepts at mid-bridge (x 5.5 m, yaw 0, the nominal root height), in 0.01 m steps."""
    offsets = np.arange(0.0, 0.31, 0.01)
    z = config.nominal_root_height
    accepted = []
    for side in (1.0, -1.0):
        poses = np.stack(
            [np.full_like(offsets, 5.5), BRIDGE_Y + side * offsets, np.full_like(offsets, z), 0 * offsets], 1
        )
        ok = np.asarray(
            jax.vmap(lambda pose: condition.valid(field, pose, config))(jnp.asarray(poses, jnp.float32))
        )
        accepted.append(offsets[np.argmin(ok) - 1] if not ok.all() else offsets[-1])
    return float(min(accepted))


def row(label: str, run: str, n: int, seed: int) -> str:
    policy = load_policy(run)
    terrain = load_terrain(TERRAIN)
    env = policy.config.env
    field = heightfield_from_terrain(terrain, env)
    scenario = terrain.scenario
    drawn = draw_starts(
        scenario,
        cells_for(terrain.name, scenario)[0],
        n,
        seed,
        field,
        env.nominal_root_height,
        env.reachability,
    )
    poses, speeds = drawn.poses, drawn.speeds
    targets = np.tile(np.asarray(terrain.scenario.target, np.float32), (n, 1))
    ended = rollout_batch(policy, field, poses, targets, speeds, STEPS, stop_at_invalid=True)
    through = rollout_batch(policy, field, poses, targets, speeds, STEPS, stop_at_invalid=False)
    last = np.array([ended.poses[i, ended.lengths[i] - 1] for i in range(n)])
    at_head = (
        ended.invalid
        & (last[:, 0] > HEAD_X[0])
        & (last[:, 0] < HEAD_X[1])
        & (np.abs(last[:, 1] - BRIDGE_Y) < 0.5)
    )
    offset, yaw, height = np.abs(last[:, 1] - BRIDGE_Y), np.degrees(np.abs(last[:, 3])), last[:, 2]

    def spread(values):
        return f"{np.median(values):.2f} ({values.min():.2f}-{values.max():.2f})" if len(values) else "-"

    low, off, turn = [], [], []
    for i in np.flatnonzero(through.reached):
        path = through.poses[i, : through.lengths[i]]
        on = (path[:, 0] > BRIDGE_X[0]) & (path[:, 0] < BRIDGE_X[1])
        low.append(path[on, 2].min())
        off.append(np.abs(path[on, 1] - BRIDGE_Y).max())
        turn.append(np.degrees(np.abs(path[on, 3])).max())
    return (
        f"| {label} | {play(field, env):.2f} | {int(ended.reached.sum())} / {n} | {int(at_head.sum())} / {n} | "
        f"{spread(offset[at_head])} | {spread(yaw[at_head])} | {spread(height[at_head])} | "
        f"{int(through.reached.sum())} / {n} | {spread(np.array(low))} | {spread(np.array(off))} | "
        f"{spread(np.array(turn))} |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", action="append", required=True, metavar="LABEL=RUN")
    parser.add_argument("--starts", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0, help="the scenario's seed: `leas evaluate`'s starts")
    args = parser.parse_args()
    print(
        "| policy | its termination's play at mid-bridge (m) | reached, own termination | ended at the bridge's head | its offset from the centre "
        "line (m) | its yaw to the bridge (deg) | its root height (m) | reached, rolled through | lowest "
        "root on the bridge (m) | largest offset there (m) | largest yaw there (deg) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for item in args.policy:
        label, run = item.split("=", 1)
        print(row(label, run, args.starts, args.seed), flush=True)
    print(
        f"\n{args.starts} starts (seed {args.seed}); medians (ranges). Root heights are above the "
        "bridge's top (z = 0); Talos's nominal is 1.0 m."
    )


if __name__ == "__main__":
    main()
