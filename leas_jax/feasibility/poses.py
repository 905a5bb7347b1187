"""Root poses on a terrain for the feasibility conditions' data, and the cylinders' verdicts there.

Two seeded pose sets (host, NumPy):

* `sample_poses`, fresh poses: x, y uniform over the terrain (70 %) or near obstacles (30 %:
  grid points whose 0.35 m neighbourhood spans more than 5 cm of height, away from the raster
  border, jittered), yaw uniform, z = reference height + the nominal root height (EnvConfig,
  1.0 m) + an offset uniform in `Z_OFFSETS`. The reference height is the highest terrain point
  within `REFERENCE_RADIUS` (the ground a foot would stand on, so that poses beside holes stand
  over the ground). The offsets reach further than +-0.3 m below the nominal so that they
  bracket both ends of the generator's flat-ground range (root 0.53 to 1.18 m above the soles).
  The reachability calibration (studies/reachability_calibration.py) and the learned
  condition's data (`condition_build`) draw them.
* `policy_poses`: poses on the guides a policy draws on the terrain from the env's own random
  resets (deterministic policy): where a termination condition matters.

`cylinder_verdicts` is the reachability cylinders' condition at poses (jitted, vmapped).
"""

from __future__ import annotations

import numpy as np

from leas_jax.files import REPO_ROOT

ARENA = REPO_ROOT / "terrains" / "training_arena.toml"
Z_OFFSETS = (-0.55, 0.35)  # m, root height offsets about the nominal
NEAR_FRACTION = 0.3  # share of poses drawn near obstacles
REFERENCE_RADIUS = 0.15  # m, reference ground: highest point within this radius


def sample_poses(
    terrain,
    count: int,
    seed: int = 0,
    nominal: float = 1.0,
    near_fraction: float = NEAR_FRACTION,
    z_offsets=Z_OFFSETS,
) -> np.ndarray:
    """Seeded fresh root poses on a terrain (see the module docstring).

    Args:
        terrain: a leas_jax.terrain.Terrain.
        count: number of poses.
        seed: numpy default_rng seed.
        nominal: nominal root height above the reference ground, m.
        near_fraction: share of the poses drawn near obstacles.
        z_offsets: (low, high) m, the root height's offset about `nominal`.

    Returns:
        [count, 4] (x, y, z, yaw), world frame.
    """
    from leas_jax.env.field import disk_filter

    rng = np.random.default_rng(seed)
    heights = terrain.raster()
    res = terrain.resolution
    (x0, y0), (x1, y1) = terrain.bounds
    margin = 0.3  # m, keep the legs' disks on the raster
    n_near = int(round(near_fraction * count))
    xy = np.column_stack(
        [
            rng.uniform(x0 + margin, x1 - margin, count - n_near),
            rng.uniform(y0 + margin, y1 - margin, count - n_near),
        ]
    )
    if n_near:
        spread = disk_filter(heights, 0.35 / res, "max", terrain.void_height) - disk_filter(
            heights, 0.35 / res, "min", terrain.void_height
        )
        # Not the raster border, where the void outside makes every point look "near".
        border = int(np.ceil((margin + 0.35) / res))
        spread[:border], spread[-border:], spread[:, :border], spread[:, -border:] = 0, 0, 0, 0
        ij = np.argwhere(spread > 0.05)
        pick = ij[rng.integers(0, len(ij), n_near)] if len(ij) else np.zeros((n_near, 2), int)
        near = terrain.bounds[0] + pick * res + rng.uniform(-res / 2, res / 2, (n_near, 2))
        near = np.clip(near, [x0 + margin, y0 + margin], [x1 - margin, y1 - margin])
        xy = np.concatenate([xy, near])
    reference = disk_filter(heights, REFERENCE_RADIUS / res, "max", terrain.void_height)
    ij = np.clip(np.round((xy - terrain.bounds[0]) / res).astype(int), 0, np.array(heights.shape) - 1)
    z = reference[ij[:, 0], ij[:, 1]] + nominal + rng.uniform(*z_offsets, len(xy))
    yaw = rng.uniform(-np.pi, np.pi, len(xy))
    poses = np.column_stack([xy, z, yaw])
    return poses[rng.permutation(len(poses))]


def policy_poses(policy, terrain, count: int, seed: int, per_guide: int = 4, steps: int = 400) -> np.ndarray:
    """[count, 4] poses on a policy's own guides on a terrain (deterministic policy, env resets, seeded).

    `count / per_guide` episodes (`leas_jax.eval.geometric.arena_episodes`); `per_guide` poses
    drawn uniformly (seeded) among each guide's valid poses.
    """
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.eval.geometric import arena_episodes

    n = -(-count // per_guide)
    field = heightfield_from_terrain(terrain, policy.config.env)
    episodes = arena_episodes(policy, field, n=n, seed=seed, steps=steps)
    rng = np.random.default_rng(seed)
    picks = [episodes.poses[k, rng.integers(0, episodes.lengths[k], per_guide)] for k in range(n)]
    return np.concatenate(picks)[:count].astype(np.float64)


def cylinder_verdicts(terrain, poses: np.ndarray, config) -> np.ndarray:
    """[N] bool `reachability.valid` (jitted, vmapped) at poses [N, 4] with `config` (a
    `ReachabilityConfig`), on the terrain's heightfield built for that config."""
    import jax.numpy as jnp

    from leas_jax.env import EnvConfig, heightfield_from_terrain, reachability

    field = heightfield_from_terrain(terrain, EnvConfig(reachability=config))
    return np.asarray(reachability.valid_poses(field, jnp.asarray(poses, dtype=jnp.float32), config))
