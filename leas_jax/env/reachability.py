"""Reachability condition of a root pose (DESIGN.md §5). Pure and jittable.

A pose is valid when
  - the trunk is collision-free: no terrain inside the vertical cylinder of
    radius `trunk_radius` spanning [z + trunk_bottom, z + trunk_top]. A
    heightfield has no overhangs, so this holds iff the highest terrain point
    within the radius is below z + trunk_bottom;
  - both legs touch: for each leg, the vertical cylinder of radius `leg_radius`
    centred at (0, ±leg_lateral_offset) in the root frame, spanning
    [z + leg_bottom, z + leg_top], contains solid terrain surface (the void
    under holes is no floor). We test that the band intersects
    [lowest, highest] solid terrain height within the disk. This is exact
    when the heights inside the disk are connected and over-accepts only when
    a vertical jump taller than the band (leg_top - leg_bottom) skips it
    entirely, e.g. a leg disk straddling a tall wall; the trunk test rejects
    most such poses.
Disk maxima and minima are precomputed rasters (`Heightfield`), so the test
costs three gathers per leg pair.
"""

import jax
import jax.numpy as jnp

from leas_jax.env.config import ReachabilityConfig
from leas_jax.env.field import Heightfield, sample_nearest
from leas_jax.env.kinematics import rotate_z


def leg_centers(pose: jax.Array, config: ReachabilityConfig = ReachabilityConfig()) -> jax.Array:
    """World (x, y) of the left and right leg cylinders. pose: [4] -> [2, 2] (left, right)."""
    offsets = jnp.array([[0.0, config.leg_lateral_offset], [0.0, -config.leg_lateral_offset]])
    return pose[:2] + rotate_z(offsets, pose[3])


def terms(field: Heightfield, pose: jax.Array, config: ReachabilityConfig = ReachabilityConfig()) -> dict:
    """The three parts of the condition.

    Args:
        field: terrain with its reachability rasters (built with the same radii as `config`).
        pose: [4] (x, y, z, yaw), world.

    Returns:
        dict of bool[]: trunk_free, left_touch, right_touch.
    """
    z = pose[2]
    trunk_free = sample_nearest(field, field.trunk_max, pose[:2]) < z + config.trunk_bottom
    legs = leg_centers(pose, config)
    highest = sample_nearest(field, field.leg_max, legs, outside=-jnp.inf)
    lowest = sample_nearest(field, field.leg_min, legs, outside=jnp.inf)
    touch = (highest >= z + config.leg_bottom) & (lowest <= z + config.leg_top)
    return {"trunk_free": trunk_free, "left_touch": touch[0], "right_touch": touch[1]}


def valid(field: Heightfield, pose: jax.Array, config: ReachabilityConfig = ReachabilityConfig()) -> jax.Array:
    """True when the root pose satisfies the reachability condition. pose: [4] -> bool[]."""
    t = terms(field, pose, config)
    return t["trunk_free"] & t["left_touch"] & t["right_touch"]
