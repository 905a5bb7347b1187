"""Reachability calibration machinery (studies/reachability_calibration.py) on obvious cases.

A 6 x 6 m slab with a 1.5 m wall: roots at the nominal height over open ground are
feasible for the contact generator and valid for the condition; roots far above the
ground or inside the wall are neither. Checks the ground truth (in-process and with a
2-process pool), the confusion counts, the NumPy threshold form of the condition
against the jitted one, the flat-ground constraint and a tiny grid search.
"""

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from leas_jax.contacts.planner.generator import ContactPosture, double_support_posture
from leas_jax.contacts.robot.model import NOMINAL_ROOT_HEIGHT
from leas_jax.env import ReachabilityConfig
from leas_jax.feasibility.poses import Z_OFFSETS, cylinder_verdicts, sample_poses
from leas_jax.feasibility.walking_truth import WALK_POSES, walking_guide
from leas_jax.stats import confusion
from leas_jax.terrain import load_terrain
from leas_jax.training.config import REACHABILITY_TERMS_OFF

# Imported by name from studies/ (on sys.path, which spawned pool workers inherit) so
# that the pool can pickle its functions.
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "studies"))
import reachability_calibration as rc  # noqa: E402

TERRAIN = load_terrain(Path(__file__).parent / "data" / "slab_with_wall.toml")  # wall: x 4.3-4.7, y 1-5


def _cases():
    """[40, 4] poses and [40] expected truth: 16 standing, 12 too high, 12 inside the wall."""
    rng = np.random.default_rng(3)
    stand = np.column_stack(
        [
            rng.uniform(1.0, 3.0, 16),
            rng.uniform(1.0, 5.0, 16),
            np.where(np.arange(16) % 2 == 0, 1.0, NOMINAL_ROOT_HEIGHT),
            rng.uniform(-math.pi, math.pi, 16),
        ]
    )
    high = np.column_stack(
        [
            rng.uniform(1.0, 3.0, 12),
            rng.uniform(1.0, 5.0, 12),
            np.full(12, 2.0),
            rng.uniform(-math.pi, math.pi, 12),
        ]
    )
    wall = np.column_stack(
        [
            rng.uniform(4.4, 4.6, 12),
            rng.uniform(1.5, 4.5, 12),
            np.full(12, 1.0),
            rng.uniform(-math.pi, math.pi, 12),
        ]
    )
    return np.concatenate([stand, high, wall]), np.repeat([True, False, False], [16, 12, 12])


POSES, EXPECTED = _cases()


@pytest.fixture(scope="module")
def truth():
    return rc.ground_truth(TERRAIN, POSES, workers=1)


def test_ground_truth_on_obvious_cases(truth):
    np.testing.assert_array_equal(truth, EXPECTED)
    posture = double_support_posture(TERRAIN, POSES[0])
    assert isinstance(posture, ContactPosture) and posture.guide_index == 0
    assert np.all(np.isfinite(posture.feet)) and posture.q.shape == (39,)
    np.testing.assert_allclose(posture.feet[:, 2], 0.0, atol=1e-9)  # both soles on the slab
    assert double_support_posture(TERRAIN, POSES[-1]) is None


def test_ground_truth_pool_matches_in_process(truth):
    # A few poses of each kind through 2 spawned workers, chunks of 3: same order.
    pick = np.r_[0:5, 16:19, 28:31]
    np.testing.assert_array_equal(rc.ground_truth(TERRAIN, POSES[pick], workers=2, chunk=3), truth[pick])


def test_condition_on_obvious_cases_old_and_new_defaults():
    old = ReachabilityConfig(
        trunk_radius=0.30,
        trunk_bottom=-0.63,
        trunk_top=0.60,
        leg_radius=0.25,
        leg_bottom=-1.06,
        leg_top=-0.54,
    )
    for config in (old, ReachabilityConfig()):
        predicted = cylinder_verdicts(TERRAIN, POSES, config)
        np.testing.assert_array_equal(predicted, EXPECTED)
        # The search's NumPy form agrees with the jitted condition, on these poses and on
        # the thresholds that flip them (the high roots become valid with a low enough leg_bottom).
        samples = rc.raster_samples(
            TERRAIN, POSES, config.trunk_radius, config.leg_radius, config.leg_lateral_offset
        )
        np.testing.assert_array_equal(
            rc.thresholds(samples, config.trunk_bottom, config.leg_bottom, config.leg_top), predicted
        )
        low = dataclasses.replace(config, leg_bottom=-2.1)
        np.testing.assert_array_equal(
            rc.thresholds(samples, low.trunk_bottom, low.leg_bottom, low.leg_top),
            cylinder_verdicts(TERRAIN, POSES, low),
        )
        assert cylinder_verdicts(TERRAIN, POSES, low)[16:28].all()


def test_confusion_counts_by_hand():
    truth = np.array([1, 1, 1, 1, 0, 0, 0, 0, 0, 0], dtype=bool)
    predicted = np.array([1, 1, 1, 0, 1, 0, 0, 0, 0, 0], dtype=bool)
    c = confusion(predicted, truth)
    assert (c["tp"], c["fn"], c["fp"], c["tn"]) == (3, 1, 1, 5)
    assert c["sensitivity"] == pytest.approx(0.75) and c["specificity"] == pytest.approx(5 / 6)
    batch = confusion(np.stack([predicted, truth, ~truth]), truth)  # [3, N]: rates per row
    np.testing.assert_allclose(batch["sensitivity"], [0.75, 1.0, 0.0])
    np.testing.assert_allclose(batch["specificity"], [5 / 6, 1.0, 0.0])
    assert math.isnan(confusion(predicted[4:], truth[4:])["sensitivity"])  # no feasible pose


def test_flat_ground_constraint():
    # Roots at 1.0 and 1.019 m above flat ground, 2 cm to spare on every threshold.
    assert rc.flat_ground_ok(-0.50, -1.175, -0.525)
    assert not rc.flat_ground_ok(-0.99, -1.175, -0.525)  # trunk bottom 1 cm above the ground
    assert not rc.flat_ground_ok(-0.50, -1.03, -0.525)  # 1.019 m root: ground 1.1 cm inside the band
    assert not rc.flat_ground_ok(-0.50, -1.175, -0.99)
    cfg = ReachabilityConfig()
    assert rc.flat_ground_ok(cfg.trunk_bottom, cfg.leg_bottom, cfg.leg_top)  # the defaults keep spawns valid


def test_tiny_grid_search_separates_the_cases(truth):
    grid = {
        "trunk_radius": (0.30,),
        "leg_radius": (0.05, 0.25),
        "trunk_bottom": (-0.5, -0.63),
        "leg_bottom": (-1.175, -2.1),
        "leg_top": (-0.525,),
    }
    fit = np.ones(len(POSES), dtype=bool)
    result = rc.grid_search(TERRAIN, POSES, truth, fit, ReachabilityConfig(), grid)
    assert result["met"] and result["candidates"] == 2 * 4
    chosen = result["config"]
    # leg_bottom -2.1 accepts the high roots (specificity 60 %): never chosen.
    assert chosen.leg_bottom == -1.175
    assert result["fit_figures"] == {"sensitivity": 1.0, "specificity": 1.0}


def test_sample_poses_seeded_and_in_range():
    poses = sample_poses(TERRAIN, 200, seed=5)
    np.testing.assert_array_equal(poses, sample_poses(TERRAIN, 200, seed=5))
    assert poses.shape == (200, 4)
    assert np.all((poses[:, :2] >= 0.3) & (poses[:, :2] <= 5.7))
    assert np.all(np.abs(poses[:, 3]) <= math.pi)
    # z: reference ground (highest within 0.15 m: 0 on the slab, 1.5 near the wall) + 1.0 + offset.
    on_slab = poses[:, 0] < 3.5
    offsets = poses[on_slab, 2] - 1.0
    assert offsets.min() >= Z_OFFSETS[0] and offsets.max() <= Z_OFFSETS[1]
    # 30 % near the wall (the only obstacle): within 0.35 m + a cell of its footprint.
    near = (poses[:, 0] > 4.3 - 0.37) & (poses[:, 0] < 4.7 + 0.37)
    assert near.sum() >= 0.3 * 200


def test_walking_truth_rejects_crouched_roots_the_static_truth_accepts():
    """Talos stands crouched 0.6 m above the ground, but the generator does not walk that low."""
    rng = np.random.default_rng(5)
    crouched = np.column_stack(
        [
            rng.uniform(1.0, 3.0, 3),
            rng.uniform(1.5, 4.5, 3),
            np.full(3, 0.6),
            rng.uniform(-math.pi, math.pi, 3),
        ]
    )
    poses = np.concatenate([POSES[:3], crouched])
    static = rc.ground_truth(TERRAIN, poses, workers=1)
    walking = rc.ground_truth(TERRAIN, poses, workers=1, truth="walking")
    np.testing.assert_array_equal(static, [True] * 6)
    np.testing.assert_array_equal(walking, [True] * 3 + [False] * 3)
    guide = walking_guide(POSES[0])
    assert guide.shape == (WALK_POSES, 4)
    np.testing.assert_allclose(np.hypot(*(guide[-1, :2] - guide[0, :2])), 0.36, atol=1e-9)


def test_hands_term_catches_grippers_beside_the_wall():
    """Roots 0.22 m from the wall's face, heading along it: a trunk cylinder of 0.20 m is
    clear, but a half-sitting gripper (0.55 m sideways) is in the wall, and so are the
    shoulders (0.37 m) with the arms held in and the root shifted its 0.12 m off: the
    generator cannot stand there. The hands term rejects them; its NumPy form in the search
    agrees with the jitted condition, and a search over the hands grid turns the term on."""
    rng = np.random.default_rng(4)
    side = np.column_stack(
        [
            np.full(6, 4.3 - 0.22),
            rng.uniform(2.0, 4.0, 6),
            np.full(6, 1.0),
            rng.choice([-math.pi / 2, math.pi / 2], 6),
        ]
    )
    poses = np.concatenate([POSES[:16], side])
    truth = rc.ground_truth(TERRAIN, poses, workers=1)
    assert truth[:16].all() and not truth[16:].any()
    base = ReachabilityConfig(trunk_radius=0.20, **REACHABILITY_TERMS_OFF)  # cylinders alone
    assert cylinder_verdicts(TERRAIN, poses, base).all()  # every pose passes without the hands
    hands = dataclasses.replace(base, hand_radius=0.13)
    predicted = cylinder_verdicts(TERRAIN, poses, hands)
    np.testing.assert_array_equal(predicted, truth)
    samples = rc.raster_samples(
        TERRAIN, poses, base.trunk_radius, base.leg_radius, base.leg_lateral_offset, hand_radius=0.13
    )
    np.testing.assert_array_equal(
        rc.thresholds(
            samples, base.trunk_bottom, base.leg_bottom, base.leg_top, hand_bottom=hands.hand_bottom
        ),
        predicted,
    )
    grid = {
        "trunk_radius": (0.20,),
        "leg_radius": (0.05,),
        "trunk_bottom": (base.trunk_bottom,),
        "leg_bottom": (base.leg_bottom,),
        "leg_top": (base.leg_top,),
    }
    terms = {
        "trunk_radius": (0.20,),
        "leg_radius": (0.05,),
        "leg_forward": (0.0,),
        "foothold": (None,),
        "foothold_spread": (0.02,),
        "hand": (None, 0.13),
        "hand_bottom": (-0.40,),
    }
    result = rc.grid_search(TERRAIN, poses, truth, np.ones(len(poses), dtype=bool), base, grid, terms)
    assert result["met"] and result["config"].hand_radius == 0.13 and result["config"].hand_bottom == -0.40
