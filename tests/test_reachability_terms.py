"""Hand-made cases for the optional terms of the reachability condition:
the lookahead leg cylinders (`leg_forward`), the foothold flatness term
(`foothold_radius`, `foothold_search`, `foothold_spread`) and the hands term
(`hand_radius`, `hand_forward`, `hand_lateral`, `hand_bottom`). The calibrated default
turns all three on; each term is tested here added to PLAIN, the default cylinders
alone.

Terrains are 4 x 4 m rasters (2 cm cells, void at -2 m, world origin at the raster's
corner); roots stand 1.0 m above the ground, where the default condition holds.
"""

import dataclasses
import math
import sys
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from leas_jax.env import EnvConfig, ReachabilityConfig, heightfield_from_raster, reachability
from leas_jax.env.field import foothold_raster
from leas_jax.training.config import REACHABILITY_TERMS_OFF

RES = 0.02
VOID = -2.0
SIZE = 201  # cells per side: 4 m
PLAIN = ReachabilityConfig(**REACHABILITY_TERMS_OFF)  # the default cylinders only


def plain_with(**terms) -> ReachabilityConfig:
    """PLAIN with the given optional terms."""
    return dataclasses.replace(PLAIN, **terms)


def cell(x):
    return int(round(x / RES))


def field_of(heights, reach: ReachabilityConfig, require_spawn=False):
    return heightfield_from_raster(
        heights, (0.0, 0.0), RES, VOID, EnvConfig(reachability=reach), require_spawn=require_spawn
    )


def pose(x, y, z=1.0, yaw=0.0):
    return jnp.array([x, y, z, yaw], dtype=jnp.float32)


def valid(field, p, reach):
    return bool(jax.jit(reachability.valid, static_argnums=2)(field, p, reach))


@pytest.fixture(scope="module")
def hole_terrain():
    """Flat ground at 0 with the void for x >= 2.0 m (a cliff edge along y)."""
    heights = np.zeros((SIZE, SIZE), np.float32)
    heights[cell(2.0) :, :] = VOID
    return heights


@pytest.fixture(scope="module")
def ridged_terrain():
    """Ground at 0 for x < 2 m; for x >= 2 m ridges along y, 4 cm wide, alternately 0 and 5 cm high."""
    heights = np.zeros((SIZE, SIZE), np.float32)
    for i in range(cell(2.0), SIZE):
        heights[i, :] = 0.05 if ((i - cell(2.0)) // 2) % 2 else 0.0
    return heights


def test_defaults_turn_on_every_optional_term(ridged_terrain):
    reach = ReachabilityConfig()
    assert reach.leg_forward == 0.30 and reach.hand_radius == 0.13 and reach.foothold_spread == 0.04
    heights = np.zeros((SIZE, SIZE), np.float32)
    field = field_of(heights, reach, require_spawn=True)
    assert field.foothold.shape == field.heights.shape
    assert field.hand_max.shape == field.heights.shape
    t = reachability.terms(field, pose(1.0, 1.0), reach)
    assert all(bool(v) for v in t.values())
    # 5 cm ridges under every leg: the cylinders touch, the foothold term refuses
    ridged = field_of(ridged_terrain, reach)
    t = reachability.terms(ridged, pose(3.0, 2.0), reach)
    assert bool(t["left_touch"]) and bool(t["right_touch"]) and bool(t["trunk_free"])
    assert not bool(t["left_foothold"]) and not bool(t["right_foothold"])
    plain = field_of(heights, PLAIN)
    assert plain.hand_max.shape == (1, 1)
    t = reachability.terms(plain, pose(1.0, 1.0), PLAIN)
    assert all(
        bool(t[k])
        for k in (
            "left_ahead_touch",
            "right_ahead_touch",
            "left_foothold",
            "right_foothold",
            "left_hand_free",
            "right_hand_free",
        )
    )


# -- lookahead legs -----------------------------------------------------------


def test_lookahead_rejects_a_root_facing_a_cliff(hole_terrain):
    plain = PLAIN
    ahead = dataclasses.replace(plain, leg_forward=0.15)
    field = field_of(hole_terrain, ahead)
    # 0.10 m from the edge, facing it: the legs stand on the ground, the lookahead legs over the void.
    facing = pose(1.90, 2.0, yaw=0.0)
    assert valid(field, facing, plain)
    assert not valid(field, facing, ahead)
    t = reachability.terms(field, facing, ahead)
    assert bool(t["left_touch"]) and bool(t["right_touch"])
    assert not bool(t["left_ahead_touch"]) and not bool(t["right_ahead_touch"])
    # Same place, back to the edge: the lookahead legs are 0.25 m inland.
    assert valid(field, pose(1.90, 2.0, yaw=math.pi), ahead)
    # Farther from the edge (0.25 m): leg_forward 0.15 + leg_radius 0.05 still reaches ground.
    assert valid(field, pose(1.75, 2.0, yaw=0.0), ahead)


def test_lookahead_centres_turn_with_the_yaw():
    reach = plain_with(leg_forward=0.2)
    centres = reachability.all_leg_centers(pose(1.0, 1.0, yaw=math.pi / 2), reach)
    np.testing.assert_allclose(
        centres, [[1.0 - 0.085, 1.0], [1.0 + 0.085, 1.0], [1.0 - 0.085, 1.2], [1.0 + 0.085, 1.2]], atol=1e-6
    )
    assert reachability.all_leg_centers(pose(1.0, 1.0), PLAIN).shape == (2, 2)


def test_lookahead_legs_use_the_band():
    # A step down 0.10 m ahead: the lookahead legs' ground is 1.10 m below the root, inside
    # the band [leg_bottom, leg_top] = [-1.175, -0.75]; a 0.20 m step down puts it 1.20 m
    # below, out of reach. The legs themselves stand on the upper ground (1.0 m below).
    heights = np.zeros((SIZE, SIZE), np.float32)
    heights[cell(2.0) :, :] = -0.10
    ahead = plain_with(leg_forward=0.15)
    assert valid(field_of(heights, ahead), pose(1.90, 2.0), ahead)
    heights[cell(2.0) :, :] = -0.20
    field = field_of(heights, ahead)
    assert not valid(field, pose(1.90, 2.0), ahead)
    assert valid(field, pose(1.90, 2.0), PLAIN)


# -- foothold -----------------------------------------------------------------


def test_foothold_raster_by_hand():
    heights = np.zeros((41, 41), np.float32)
    heights[20:, :] = 0.10  # a 10 cm step at x = 0.40 m
    heights[:, 35:] = VOID  # the void for y >= 0.70 m
    raster = foothold_raster(heights, VOID, RES, foothold_radius=0.04, foothold_search=0.0)
    assert raster[5, 10] == 0.0  # a sole disk on the low side
    assert raster[30, 10] == 0.0  # on the high side
    assert raster[19, 10] == pytest.approx(0.10)  # straddling the step
    assert raster[10, 33] == np.inf  # touching the void
    assert raster[10, 0] == np.inf  # leaving the grid
    # Searching 0.06 m around: a flat disk is found next to the step, not 2 cells from the void.
    searched = foothold_raster(heights, VOID, RES, foothold_radius=0.04, foothold_search=0.06)
    assert searched[19, 10] == 0.0 and searched[10, 33] == 0.0


def test_foothold_rejects_uneven_ground(ridged_terrain):
    reach = plain_with(foothold_radius=0.08, foothold_search=0.10, foothold_spread=0.02)
    field = field_of(ridged_terrain, reach)
    on_ridges = pose(3.0, 2.0, z=1.02)
    assert valid(field, on_ridges, PLAIN)  # the cylinders alone accept it
    assert not valid(field, on_ridges, reach)
    t = reachability.terms(field, on_ridges, reach)
    assert not bool(t["left_foothold"]) and not bool(t["right_foothold"]) and bool(t["left_touch"])
    assert valid(field, pose(1.0, 2.0), reach)  # flat ground
    # A looser spread accepts the 5 cm ridges.
    loose = dataclasses.replace(reach, foothold_spread=0.06)
    assert valid(field_of(ridged_terrain, loose), on_ridges, loose)
    # Near the border the search finds flat ground: 0.15 m from the ridges, one leg over them.
    assert valid(field, pose(1.90, 2.0, yaw=0.0), reach)


def test_foothold_beside_a_hole_needs_the_search(hole_terrain):
    # Legs 0.03 m from the void: a sole disk of 0.08 m there hangs over the void; searching
    # 0.10 m around finds one on the ground.
    at_edge = pose(1.97, 2.0, yaw=0.0)  # legs at (1.97, 2.0 +- 0.085), the edge at x = 2.0
    strict = plain_with(foothold_radius=0.08, foothold_search=0.0, foothold_spread=0.02)
    search = dataclasses.replace(strict, foothold_search=0.10)
    assert not valid(field_of(hole_terrain, strict), at_edge, strict)
    assert valid(field_of(hole_terrain, search), at_edge, search)


def test_foothold_needs_its_raster(ridged_terrain):
    reach = plain_with(foothold_spread=0.02)
    field = field_of(ridged_terrain, PLAIN)  # built without the term
    with pytest.raises(ValueError, match="foothold"):
        reachability.valid(field, pose(1.0, 2.0), reach)


def test_spawn_points_keep_the_foothold(ridged_terrain):
    reach = plain_with(foothold_spread=0.02, leg_forward=0.1)
    field = field_of(ridged_terrain, reach, require_spawn=True)
    spawn = np.asarray(field.spawn_xy)
    assert len(spawn) > 0 and np.all(spawn[:, 0] <= 2.0)  # never over the ridges
    plain = np.asarray(field_of(ridged_terrain, PLAIN, require_spawn=True).spawn_xy)
    assert np.any(plain[:, 0] > 2.2)  # which the plain condition accepts
    for xy in spawn[:: max(len(spawn) // 50, 1)]:
        for yaw in np.linspace(-math.pi, math.pi, 8, endpoint=False):
            assert valid(field, pose(float(xy[0]), float(xy[1]), yaw=float(yaw)), reach)


def test_calibration_numpy_form_matches_the_jitted_terms(hole_terrain):
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "studies"))
    import reachability_calibration as rc

    from leas_jax.feasibility.poses import cylinder_verdicts, sample_poses
    from leas_jax.terrain import loads_terrain

    terrain = loads_terrain("""name = "terms_cases"
bounds = [[0.0, 0.0], [4.0, 4.0]]
void_height = -2.0
resolution = 0.02
[[box]]
center = [1.0, 2.0, -0.1]
size = [2.0, 4.0, 0.2]
[[box]]
center = [3.0, 1.0, 0.025]
size = [2.0, 0.04, 0.05]
[[box]]
center = [3.0, 2.0, -0.1]
size = [2.0, 1.0, 0.2]
""")
    poses = sample_poses(terrain, 400, seed=3)
    for reach in (
        plain_with(leg_forward=0.15),
        plain_with(foothold_radius=0.065, foothold_search=0.10, foothold_spread=0.02),
        plain_with(leg_forward=0.1, foothold_spread=0.01, trunk_radius=0.2),
    ):
        jitted = cylinder_verdicts(terrain, poses, reach)
        foothold = None if reach.foothold_spread is None else (reach.foothold_radius, reach.foothold_search)
        samples = rc.raster_samples(
            terrain,
            poses,
            reach.trunk_radius,
            reach.leg_radius,
            reach.leg_lateral_offset,
            reach.leg_forward,
            foothold,
        )
        numpy = rc.thresholds(
            samples, reach.trunk_bottom, reach.leg_bottom, reach.leg_top, reach.foothold_spread
        )
        np.testing.assert_array_equal(numpy, jitted)
        # the term matters on these poses: it rejects some that the plain condition accepts
        assert np.sum(cylinder_verdicts(terrain, poses, PLAIN) & ~jitted) > 0


def test_default_spawn_points_are_valid_for_every_yaw():
    """A 0.20 m wide trench in flat ground: with the calibrated narrow legs (r 0.05 m at
    0.085 m) a leg disk fits inside it, so a root beside the trench is valid only for
    some yaws; no spawn point may be such a root."""
    heights = np.zeros((SIZE, SIZE), np.float32)
    heights[cell(2.0) : cell(2.2), :] = VOID
    reach = ReachabilityConfig()
    field = field_of(heights, reach, require_spawn=True)
    spawn = np.asarray(field.spawn_xy)
    assert len(spawn) > 100
    yaws = np.linspace(-math.pi, math.pi, 16, endpoint=False)
    xy = np.repeat(spawn, len(yaws), axis=0)
    poses = np.column_stack([xy, np.ones(len(xy)), np.tile(yaws, len(spawn))]).astype(np.float32)
    ok = np.asarray(jax.jit(jax.vmap(lambda p: reachability.valid(field, p, reach)))(poses))
    assert ok.all(), poses[~ok][:5]


@pytest.fixture(scope="module")
def wall_terrain():
    """Flat ground at 0 with a wall 1.0 m tall for y >= 2.5 m (its face along x)."""
    heights = np.zeros((SIZE, SIZE), np.float32)
    heights[:, cell(2.5) :] = 1.0
    return heights


def test_hands_term_rejects_a_wall_beside_the_grippers_only(wall_terrain):
    """Root 1.0 m up, heading +x: the left hand disk (centre 0.45 m to the left, radius
    0.13 m) reaches y + 0.58. The trunk (0.30 m) alone accepts the root 0.35 m from the
    wall; the hands term rejects it there, accepts it 0.65 m away, and turning the root
    to face the wall (hands along the face, 0.12 m ahead) accepts it at 0.35 m again."""
    reach = plain_with(hand_radius=0.13)
    field = field_of(wall_terrain, reach)
    assert field.hand_max.shape == field.heights.shape
    near, far = pose(2.0, 2.15), pose(2.0, 1.85)
    assert valid(field, near, PLAIN)  # the cylinders alone have no hands
    t = reachability.terms(field, near, reach)
    assert not bool(t["left_hand_free"]) and bool(t["right_hand_free"]) and bool(t["trunk_free"])
    assert not valid(field, near, reach)
    assert valid(field, far, reach)
    assert valid(field, pose(2.0, 2.15, yaw=math.pi / 2), reach)  # 0.35 - 0.12 - 0.13 = 0.10 m to spare
    # Lower hands pass over a lower wall: 1.0 m - 0.40 m = 0.60 m is the highest terrain they clear.
    low = field_of(np.where(wall_terrain > 0, 0.55, 0.0).astype(np.float32), reach)
    assert valid(low, near, reach)


def test_hands_term_needs_its_raster(wall_terrain):
    field = field_of(wall_terrain, PLAIN)
    with pytest.raises(ValueError, match="hand raster"):
        reachability.terms(field, pose(2.0, 1.0), plain_with(hand_radius=0.13))


def test_hands_term_spawn_points_keep_every_yaw_clear(wall_terrain):
    reach = plain_with(hand_radius=0.13)
    field = field_of(wall_terrain, reach, require_spawn=True)
    spawn = np.asarray(field.spawn_xy)
    below = spawn[spawn[:, 1] < 2.5]  # the wall's top, 1.5 m wide, is ground too
    assert len(below) and below[:, 1].max() <= 2.5 - (math.hypot(0.12, 0.45) + 0.13) + 1e-6
    z = wall_terrain[np.round(spawn[:, 0] / RES).astype(int), np.round(spawn[:, 1] / RES).astype(int)] + 1.0
    valid = jax.jit(jax.vmap(lambda p: reachability.valid(field, p, reach)))
    for yaw in np.linspace(0.0, 2 * math.pi, 9):
        batch = jnp.column_stack([jnp.asarray(spawn), jnp.asarray(z), jnp.full(len(spawn), yaw)])
        ok = valid(batch)
        assert bool(ok.all())
