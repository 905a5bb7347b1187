"""Reachability condition of a root pose (docs/design.md §5). Pure and jittable.

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
Three optional terms (the calibrated defaults of `ReachabilityConfig` turn all three
on; the training presets' `TRAINING_REACHABILITY` none; see
studies/reachability_false_positives.py for the false positives they target):
  - lookahead (`leg_forward` != 0): a second pair of leg cylinders centred at
    (leg_forward, ±leg_lateral_offset) in the root frame, same radius and band,
    must touch as well: ground where the next steps land along the heading;
  - foothold (`foothold_spread` not None): for each leg (and lookahead leg), within
    `foothold_search` of its centre, a sole disk of radius `foothold_radius` over
    solid terrain whose heights span at most `foothold_spread` (one raster,
    `Heightfield.foothold`).
  - hands (`hand_radius` not None): a disk of radius `hand_radius` centred at
    (hand_forward, ±hand_lateral) in the root frame around each gripper of the
    half-sitting arms holds no terrain above z + hand_bottom (one raster,
    `Heightfield.hand_max`).
Disk maxima and minima are precomputed rasters (`Heightfield`), so the test
costs three gathers per leg pair (and one more per leg for the foothold).
`margins` gives the same quantities as signed distances to their thresholds (the learned
condition of `learned_feasibility` reads them); `leas_jax.env.condition` selects the
environment's termination condition (these cylinders or the learned one).
"""

import dataclasses
import functools

import jax
import jax.numpy as jnp

from leas_jax.env.config import ReachabilityConfig
from leas_jax.env.field import Heightfield, sample_nearest, sample_nearest_xy
from leas_jax.env.kinematics import rotate_z, world_xy


def leg_centers(pose: jax.Array, config: ReachabilityConfig = ReachabilityConfig()) -> jax.Array:
    """World (x, y) of the left and right leg cylinders. pose: [4] -> [2, 2] (left, right)."""
    return all_leg_centers(pose, dataclasses.replace(config, leg_forward=0.0))


def all_leg_centers(pose: jax.Array, config: ReachabilityConfig = ReachabilityConfig()) -> jax.Array:
    """World (x, y) of every leg cylinder the condition tests: at (0, ±leg_lateral_offset) in
    the root frame, [2, 2] (left, right), then at (leg_forward, ±leg_lateral_offset) when the
    lookahead is enabled (`leg_forward` != 0): [4, 2] (left, right, left ahead, right ahead).
    pose: [4] (x, y, z, yaw), world."""
    return jnp.stack(_leg_xy(pose, config), axis=-1)


def _leg_xy(pose: jax.Array, config: ReachabilityConfig) -> tuple[jax.Array, jax.Array]:
    """`all_leg_centers` as two arrays, x [L] and y [L] (`kinematics.world_xy`)."""
    forwards = (0.0,) if config.leg_forward == 0.0 else (0.0, config.leg_forward)
    offsets = jnp.array([[x, side * config.leg_lateral_offset] for x in forwards for side in (1.0, -1.0)])
    return world_xy(pose, offsets)


def hand_centers(pose: jax.Array, config: ReachabilityConfig = ReachabilityConfig()) -> jax.Array:
    """World (x, y) of the hand disks, [2, 2] (left, right). pose: [4] (x, y, z, yaw), world."""
    return jnp.stack(_hand_xy(pose, config), axis=-1)


def _hand_xy(pose: jax.Array, config: ReachabilityConfig) -> tuple[jax.Array, jax.Array]:
    """`hand_centers` as two arrays, x [2] and y [2] (`kinematics.world_xy`)."""
    offsets = jnp.array(
        [[config.hand_forward, config.hand_lateral], [config.hand_forward, -config.hand_lateral]]
    )
    return world_xy(pose, offsets)


def _term_raster(field: Heightfield, raster: jax.Array, term: str) -> jax.Array:
    """The raster of an enabled optional term; ValueError if the field was built without it."""
    if raster.shape != field.heights.shape:
        raise ValueError(
            f"the {term} term is enabled but the heightfield has no {term} raster: "
            "build it with the same ReachabilityConfig"
        )
    return raster


def terms(field: Heightfield, pose: jax.Array, config: ReachabilityConfig = ReachabilityConfig()) -> dict:
    """The parts of the condition.

    Args:
        field: terrain with its reachability rasters (built with the same radii and the
            same foothold settings as `config`).
        pose: [4] (x, y, z, yaw), world.

    Returns:
        dict of bool[]: trunk_free, left_touch, right_touch, left_ahead_touch,
        right_ahead_touch (the lookahead legs; True when disabled), left_foothold,
        right_foothold (over the legs and lookahead legs of each side; True when disabled),
        left_hand_free, right_hand_free (True when disabled).
    """
    z = pose[2]
    trunk_free = sample_nearest(field, field.trunk_max, pose[:2]) < z + config.trunk_bottom
    legs = _leg_xy(pose, config)  # x [L], y [L]; L = 2 or 4
    highest = sample_nearest_xy(field, field.leg_max, *legs, outside=-jnp.inf)
    lowest = sample_nearest_xy(field, field.leg_min, *legs, outside=jnp.inf)
    touch = (highest >= z + config.leg_bottom) & (lowest <= z + config.leg_top)  # [L]
    yes = jnp.array(True)
    ahead = (touch[2], touch[3]) if len(touch) == 4 else (yes, yes)
    if config.foothold_spread is None:
        foothold = (yes, yes)
    else:
        flat = (
            sample_nearest_xy(field, _term_raster(field, field.foothold, "foothold"), *legs, outside=jnp.inf)
            <= config.foothold_spread
        )
        flat = flat.reshape(-1, 2).all(axis=0)  # [2]: left, right (over the leg and its lookahead leg)
        foothold = (flat[0], flat[1])
    if config.hand_radius is None:
        hands = (yes, yes)
    else:
        free = (
            sample_nearest_xy(
                field,
                _term_raster(field, field.hand_max, "hand"),
                *_hand_xy(pose, config),
                outside=-jnp.inf,
            )
            < z + config.hand_bottom
        )
        hands = (free[0], free[1])
    return {
        "trunk_free": trunk_free,
        "left_touch": touch[0],
        "right_touch": touch[1],
        "left_ahead_touch": ahead[0],
        "right_ahead_touch": ahead[1],
        "left_foothold": foothold[0],
        "right_foothold": foothold[1],
        "left_hand_free": hands[0],
        "right_hand_free": hands[1],
    }


def valid(
    field: Heightfield, pose: jax.Array, config: ReachabilityConfig = ReachabilityConfig()
) -> jax.Array:
    """True when the root pose satisfies the reachability condition. pose: [4] -> bool[].

    A chain of ands rather than `all` over the stacked terms: the disabled terms' constant True
    fold away, where stacked, XLA spent seconds constant-folding them over large vmapped batches
    (a 65 536-pose chunk of the navigate lattice)."""
    return functools.reduce(jnp.logical_and, terms(field, pose, config).values())


@functools.partial(jax.jit, static_argnums=2)
def valid_poses(field: Heightfield, poses: jax.Array, config: ReachabilityConfig) -> jax.Array:
    """`valid` of many poses, jitted and vmapped. poses: [N, 4] (x, y, z, yaw), world -> bool [N]."""
    return jax.vmap(lambda pose: valid(field, pose, config))(poses)


MARGIN_CLIP = 1.0  # m, |margin| kept (an infinite raster value, e.g. no solid ground, reads as 1 m)


def margins(
    field: Heightfield, pose: jax.Array, config: ReachabilityConfig = ReachabilityConfig()
) -> jax.Array:
    """How far each test of `terms` is from its threshold, positive when it holds (m, clipped to
    +-MARGIN_CLIP). pose: [4] (x, y, z, yaw), world -> [M].

    Order: trunk (z + trunk_bottom - trunk_max); for each leg of `all_leg_centers` (L = 2 or 4),
    leg_max - (z + leg_bottom), then for each, (z + leg_top) - leg_min; with the foothold term,
    foothold_spread - foothold per leg; with the hands term, z + hand_bottom - hand_max per hand.
    M = 1 + 2 L (+ L) (+ 2). `valid` holds iff every margin is > 0 or, for the legs and the
    foothold, >= 0.
    """
    z = pose[2]
    legs = _leg_xy(pose, config)
    parts = [
        (z + config.trunk_bottom - sample_nearest(field, field.trunk_max, pose[:2]))[None],
        sample_nearest_xy(field, field.leg_max, *legs, outside=-jnp.inf) - (z + config.leg_bottom),
        (z + config.leg_top) - sample_nearest_xy(field, field.leg_min, *legs, outside=jnp.inf),
    ]
    if config.foothold_spread is not None:
        foothold = _term_raster(field, field.foothold, "foothold")
        parts.append(config.foothold_spread - sample_nearest_xy(field, foothold, *legs, outside=jnp.inf))
    if config.hand_radius is not None:
        hand = _term_raster(field, field.hand_max, "hand")
        parts.append(
            z + config.hand_bottom - sample_nearest_xy(field, hand, *_hand_xy(pose, config), outside=-jnp.inf)
        )
    # each part clipped before the concatenation: vmapped, clipping the concatenated [B, M]
    # array instead made XLA:CPU take 0.75 us per pose against 0.09 us (2 cores)
    return jnp.concatenate([jnp.clip(part, -MARGIN_CLIP, MARGIN_CLIP) for part in parts])


def shifted_poses(pose: jax.Array, margin: float) -> jax.Array:
    """The six poses shifted by `margin` (m) along the root frame's x, y and z axes, both ways.
    pose: [4] (x, y, z, yaw), world -> [6, 4]."""
    shifts = margin * jnp.concatenate([jnp.eye(3), -jnp.eye(3)])  # [6, 3], root frame
    world = jnp.concatenate([rotate_z(shifts[:, :2], pose[3]), shifts[:, 2:]], axis=1)
    return pose + jnp.concatenate([world, jnp.zeros((6, 1))], axis=1)


def clearance_shortfall(
    field: Heightfield, pose: jax.Array, margin: float, config: ReachabilityConfig = ReachabilityConfig()
) -> jax.Array:
    """Fraction of the six poses shifted by `margin` (m) along the root frame's x, y and z
    axes, both ways, that violate the condition: 0 when the pose keeps `margin` of room in
    every direction, up to 1. pose: [4] (x, y, z, yaw), world -> float[]."""
    ok = jax.vmap(lambda probe: valid(field, probe, config))(shifted_poses(pose, margin))
    return 1.0 - ok.mean()


def relaxed_reachability(reach, relaxed_foothold_spread: float | None = None):
    """The plausible poses' condition: `reach` (a `ReachabilityConfig`) without its lookahead
    legs (a step model bounds height changes instead) and, unless `relaxed_foothold_spread` is
    given, without its sole-flatness term (the leg disks must still touch solid ground)."""
    spread = reach.foothold_spread
    if spread is not None:
        spread = None if relaxed_foothold_spread is None else max(spread, relaxed_foothold_spread)
    return dataclasses.replace(reach, leg_forward=0.0, foothold_spread=spread)
