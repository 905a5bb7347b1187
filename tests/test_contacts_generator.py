"""Contact generator: coverage on feasible guides, failure before obstacles, plan format."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from leas_jax.contacts import ContactPlan, GeneratorConfig, plan_contacts, verify
from leas_jax.contacts.plan import PLAN_KEYS
from leas_jax.contacts.planner.generator import ContactGenerator
from leas_jax.contacts.robot.model import NOMINAL_ROOT_HEIGHT as H
from leas_jax.errors import UsageError
from leas_jax.terrain import loads_terrain

DT = 0.1  # s, paper Table I
SPEED = 0.18  # m/s, paper §IV
HEAD = 'name = "t"\nbounds = [[-1.0, -2.0], [7.0, 2.0]]\nvoid_height = -2.0\nresolution = 0.02\n'


def box(center, size):
    return f"[[box]]\ncenter = {list(map(float, center))}\nsize = {list(map(float, size))}\n"


def straight(x0, x1, z=None):
    """Guide along +x at SPEED, one pose per DT; z(x) root height (default: flat ground)."""
    count = int(round(abs(x1 - x0) / (SPEED * DT))) + 1
    x = np.linspace(x0, x1, count)
    height = np.full(count, H) if z is None else z(x)
    return np.stack([x, np.zeros(count), height, np.zeros(count)], axis=1)


FLAT = loads_terrain(HEAD + box([3, 0, -0.1], [8, 4, 0.2]))


def stairs_terrain(rise, steps=6, tread=0.3, start=1.5):
    text = HEAD + box([start - 1.25, 0, -0.1], [2.5, 4, 0.2])
    for k in range(steps):
        top = rise * (k + 1)
        text += box([start + tread * (k + 0.5), 0, (top - 0.2) / 2], [tread, 4, top + 0.2])
    top = rise * steps
    text += box([start + tread * steps + 1.5, 0, (top - 0.2) / 2], [3.0, 4, top + 0.2])
    return loads_terrain(text)


def x_at(plan, index):
    return float(plan.guide[index, 0])


@pytest.fixture(scope="module")
def flat_plan():
    return plan_contacts(FLAT, straight(0.0, 4.0), DT)


def test_flat_straight_guide_fully_covered_and_verified(flat_plan, tmp_path):
    plan = flat_plan
    assert plan.coverage == 1.0 and plan.last_valid_index == len(plan.guide) - 1
    assert plan.q.shape[1] == 39 and plan.feet.shape[1:] == (2, 7)
    assert np.all(np.diff(plan.guide_index) >= 0)
    # Quasi-static walking: single-support postures (one NaN row) between placements.
    in_air = np.isnan(plan.feet[:, :, 0])
    assert not in_air[0].any() and in_air.sum(axis=1).max() == 1
    assert in_air[:, 0].sum() >= 10 and in_air[:, 1].sum() >= 10  # both feet step, 4 m
    contact = ~in_air
    np.testing.assert_allclose(plan.feet[:, :, 2][contact], 0.0, atol=1e-9)  # soles on the ground
    # Saved, reloaded, verified from the file alone.
    path = tmp_path / "flat.plan.npz"
    plan.save(path)
    with np.load(path) as data:
        assert sorted(data.files) == sorted(PLAN_KEYS)
    loaded = ContactPlan.load(path)
    np.testing.assert_array_equal(loaded.q, plan.q)
    np.testing.assert_array_equal(loaded.feet, plan.feet)
    assert loaded.coverage == plan.coverage and loaded.last_valid_index == plan.last_valid_index
    assert loaded.terrain == FLAT.text
    report = verify(loaded)
    assert report.ok, str(report)


@pytest.mark.parametrize("rise", [0.10, 0.15])
def test_stairs_climbed(rise):
    terrain = stairs_terrain(rise)
    top = 6 * rise

    def height(x):
        # Root rises with the flight (1.8 m long from x = 1.5), starting 0.15 m before it.
        return H + np.clip((x - 1.35) / 1.8 * top, 0.0, top)

    plan = plan_contacts(terrain, straight(0.0, 4.5, height), DT)
    assert plan.coverage == 1.0
    heights = plan.feet[:, :, 2][np.isfinite(plan.feet[:, :, 2])]
    assert heights.max() == pytest.approx(top)  # reached the landing
    report = verify(plan)
    assert report.ok, str(report)


def test_wall_stops_before_it():
    wall = loads_terrain(HEAD + box([3, 0, -0.1], [8, 4, 0.2]) + box([2.0, 0, 1.0], [0.2, 4, 2.0]))
    plan = plan_contacts(wall, straight(0.0, 4.0), DT)
    assert plan.coverage < 1.0
    assert 1.0 < x_at(plan, plan.last_valid_index) < 1.9  # wall face at x = 1.9
    assert verify(plan).ok


def test_narrow_bridge_crossed_on_its_centre_line():
    """A 0.30 m bridge (the narrowest of the paper's 0.30-0.45 m): two soles side by side just fit."""
    bridge = loads_terrain(
        HEAD
        + box([0.5, 0, -0.1], [3, 4, 0.2])
        + box([3.0, 0, -0.1], [2.0, 0.30, 0.2])
        + box([5.5, 0, -0.1], [3, 4, 0.2])
    )
    plan = plan_contacts(bridge, straight(0.0, 5.0), DT)
    assert plan.coverage == 1.0
    feet = plan.feet[:, :, :2][np.isfinite(plan.feet[:, :, 0])]
    on_bridge = (feet[:, 0] > 2.1) & (feet[:, 0] < 3.9)
    assert on_bridge.sum() >= 4 and np.abs(feet[on_bridge, 1]).max() <= 0.15 - 0.13 / 2
    assert verify(plan).ok


def test_bridge_crossed_by_a_guide_off_its_centre_line():
    """A guide 4 cm right of the 0.30 m bridge's centre line (LeaS guides run that far off it):
    the step targets move into the foot's lane of the beam, so both soles stay centred and
    the root's balancing shift absorbs the offset. At nominal places, the left sole took the
    centre line and the right one found no room beside it: the plan stopped at the bridge."""
    bridge = loads_terrain(
        HEAD
        + box([0.5, 0, -0.1], [3, 4, 0.2])
        + box([3.0, 0, -0.1], [2.0, 0.30, 0.2])
        + box([5.5, 0, -0.1], [3, 4, 0.2])
    )
    guide = straight(0.0, 5.0)
    guide[:, 1] = -0.04
    plan = plan_contacts(bridge, guide, DT)
    assert plan.coverage == 1.0 and verify(plan).ok
    feet = plan.feet[:, :, :2]
    on_bridge = np.isfinite(feet[..., 0]) & (feet[..., 0] > 2.1) & (feet[..., 0] < 3.9)
    assert np.all(feet[:, 0, 1][on_bridge[:, 0]] > 0.0) and np.all(feet[:, 1, 1][on_bridge[:, 1]] < 0.0)
    without_lanes = plan_contacts(bridge, guide, DT, _narrow(beam_align_yaw=0.0))
    assert without_lanes.coverage < 1.0 and x_at(without_lanes, without_lanes.last_valid_index) < 2.2


@pytest.mark.parametrize(
    "sides, lane",
    [
        ("void", True),  # the bridge: void on both sides
        ("level", False),  # a narrow box of flat ground between two others
        ("tread", False),  # a stair tread walked along: one side higher, one lower
    ],
)
def test_beam_lanes_only_where_the_beam_drops_on_both_sides(sides, lane):
    side_tops = {"void": None, "level": (0.0, 0.0), "tread": (0.15, -0.15)}[sides]
    text = (
        HEAD
        + box([0.5, 0, -0.1], [3, 4, 0.2])
        + box([3.0, 0, -0.1], [2.0, 0.30, 0.2])
        + box([5.5, 0, -0.1], [3, 4, 0.2])
    )
    if side_tops is not None:
        for y, top in zip((1.075, -1.075), side_tops):
            text += box([3.0, y, (top - 1.0) / 2], [2.0, 1.85, top + 1.0])
    generator = ContactGenerator(loads_terrain(text))
    target = np.array(
        [3.0, 0.045, 0.0]
    )  # the left sole's nominal place under a root 4 cm right of the centre line
    moved = generator.footholds.beam_lane(0, target, 0.0)
    expected = [3.0, 0.13 / 2 + 0.01 / 2, 0.0] if lane else target  # half a sole and half the feet gap
    np.testing.assert_allclose(moved, expected, atol=1e-9)
    # walking the other way, the left foot's lane is the other half
    back = generator.footholds.beam_lane(0, np.array([3.0, -0.045, 0.0]), np.pi)
    np.testing.assert_allclose(back, [3.0, -0.07, 0.0] if lane else [3.0, -0.045, 0.0], atol=1e-9)


def test_hole_stops_before_it():
    hole = loads_terrain(HEAD + box([0.5, 0, -0.1], [3, 4, 0.2]) + box([5, 0, -0.1], [4, 4, 0.2]))
    plan = plan_contacts(hole, straight(0.0, 4.0), DT)
    assert plan.coverage < 1.0
    assert 1.0 < x_at(plan, plan.last_valid_index) < 2.2  # hole from x = 2.0 to 3.0
    feet_x = plan.feet[:, :, 0][np.isfinite(plan.feet[:, :, 0])]
    assert feet_x.max() < 2.0
    assert verify(plan).ok


def test_crouched_walk_is_covered_and_too_low_stops():
    """Talos walks with its root 0.85 m above flat ground (the swing foot lifted under its hip
    used to be placed at the half-sitting sole height, 12 cm underground there: coverage
    0.17); at 0.70 m no step is possible."""
    crouched = straight(0.0, 2.0)
    crouched[:, 2] = 0.85
    plan = plan_contacts(FLAT, crouched, DT)
    assert plan.coverage == 1.0
    assert verify(plan).ok
    too_low = crouched.copy()
    too_low[:, 2] = 0.70
    assert plan_contacts(FLAT, too_low, DT).coverage < 0.2


def test_guide_too_high_stops():
    guide = straight(0.0, 4.0)
    guide[:, 2] = H + np.clip((guide[:, 0] - 2.0) * 0.5, 0.0, 0.4)  # rises from x = 2
    plan, why = ContactGenerator(FLAT).stop_reasons(guide, DT)
    assert plan.coverage < 1.0
    assert set(why) == {"root height"}  # every posture tried there: a leg overstretched
    # Legs (0.812 m hip to sole + 0.10 m root lowering) give out about 0.15 m above nominal.
    last_height = plan.guide[plan.last_valid_index, 2] - H
    assert 0.0 < last_height < 0.2
    assert verify(plan).ok


def test_single_support_with_a_shorter_root_shift_passes_a_pillar():
    """A pillar whose face is 0.61 m left of the path: with the CoM over the stance sole's
    centre, the left gripper meets it in single support on the left foot; a CoM target
    3 cm inside the sole's edge, nearer the guide, shifts the root less and passes."""
    terrain = loads_terrain(HEAD + box([3, 0, -0.1], [8, 4, 0.2]) + box([2.0, 0.76, 0.7], [0.3, 0.3, 1.6]))
    guide = straight(0.0, 4.0)
    centred = plan_contacts(
        terrain,
        guide,
        DT,
        _narrow(single_support_com_inset=None, upper_bodies=("half_sitting",), arm_clearance_shifts=()),
    )
    assert centred.coverage < 0.6
    plan = plan_contacts(terrain, guide, DT)
    assert plan.coverage == 1.0
    assert verify(plan).ok


def test_arms_held_in_pass_a_pillar_beside_the_path():
    """A pillar whose face is 0.48 m left of the path: the half-sitting gripper (0.55 m out)
    meets it and the rigid upper body stops; the arms held in (0.38 m) pass, only there."""
    terrain = loads_terrain(HEAD + box([3, 0, -0.1], [8, 4, 0.2]) + box([2.0, 0.63, 0.7], [0.3, 0.3, 1.6]))
    guide = straight(0.0, 4.0)
    paper = GeneratorConfig(upper_bodies=("half_sitting",), arm_clearance_shifts=())
    rigid, why = ContactGenerator(terrain, paper).stop_reasons(guide, DT)
    assert rigid.coverage < 0.5
    assert 1.2 < x_at(rigid, rigid.last_valid_index) < 1.85
    assert why.most_common(1)[0][0] == "terrain collision: arm"
    plan, why = ContactGenerator(terrain).stop_reasons(guide, DT)
    assert plan.coverage == 1.0 and not why
    np.testing.assert_array_equal(plan.q, plan_contacts(terrain, guide, DT).q)
    assert verify(plan).ok
    talos = ContactGenerator(FLAT).projection.talos
    shoulder_roll = talos.model.joints[talos.model.getJointId("arm_left_2_joint")].idx_q
    held_in = plan.q[:, shoulder_roll] == talos.upper_refs["arms_in"][shoulder_roll]
    x = plan.q[:, 0]
    assert held_in.any() and not held_in[x < 1.0].any() and not held_in[x > 3.0].any()
    np.testing.assert_array_equal(
        plan.q[: len(rigid.q)][x[: len(rigid.q)] < 1.0], rigid.q[rigid.q[:, 0] < 1.0]
    )


def test_upper_bodies_must_be_known_postures():
    with pytest.raises(ValueError, match="GeneratorConfig.upper_bodies"):
        GeneratorConfig(upper_bodies=("arms_up",))
    with pytest.raises(ValueError, match="GeneratorConfig.upper_bodies"):
        GeneratorConfig(upper_bodies=())


def test_turning_too_fast_stops():
    """4 rad/s while walking: 0.4 rad per guide pose, more than two steps can follow even
    at every guide pose (hip yaw 0.35 rad inward); 1.5 rad/s, 0.75 rad per planning pose
    (stride 5), is followed only through the guide poses between (`refine_stride`); pi/9
    rad/s (paper's omega_max) passes."""

    def turning(rate, count=100):
        yaw = rate * DT * np.arange(count)
        x = np.cumsum(0.1 * DT * np.cos(yaw))
        y = np.cumsum(0.1 * DT * np.sin(yaw))
        return np.stack([x, y, np.full(count, H), yaw], axis=1)

    assert plan_contacts(FLAT, turning(4.0), DT).coverage < 0.5
    fast = plan_contacts(FLAT, turning(1.5), DT)
    assert fast.coverage == 1.0
    assert verify(fast).ok
    assert plan_contacts(FLAT, turning(1.5), DT, GeneratorConfig(refine_stride=None)).coverage < 0.5
    slow = plan_contacts(FLAT, turning(np.pi / 9), DT)
    assert slow.coverage == 1.0
    assert verify(slow).ok


def test_start_over_a_hole_gives_an_empty_plan():
    hole = loads_terrain(HEAD + box([5, 0, -0.1], [4, 4, 0.2]))
    plan = plan_contacts(hole, straight(0.0, 1.0), DT)
    assert len(plan) == 0 and plan.last_valid_index == -1 and plan.coverage == 0.0
    assert verify(plan).ok


def test_single_pose_guide():
    plan = plan_contacts(FLAT, straight(0.0, 0.0), DT)
    assert len(plan) == 1 and plan.last_valid_index == 0 and plan.coverage == 1.0


def test_bad_inputs():
    with pytest.raises(UsageError, match="shape"):
        plan_contacts(FLAT, np.zeros((5, 3)), DT)
    with pytest.raises(UsageError, match="NaN"):
        plan_contacts(FLAT, np.full((5, 4), np.nan), DT)
    with pytest.raises(UsageError, match="timestep"):
        plan_contacts(FLAT, straight(0, 1), 0.0)


def test_config_is_frozen_and_used():
    config = GeneratorConfig(planning_interval=10 * DT)
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.planning_interval = 3 * DT
    generator = ContactGenerator(FLAT, config)
    plan = generator.plan(straight(0.0, 1.0), DT)
    assert set(np.unique(plan.guide_index)) <= set(range(0, len(plan.guide), 10)) | {len(plan.guide) - 1}


def test_planning_interval_is_in_seconds_whatever_the_guide_timestep():
    """The same straight walk sampled every DT and every DT / 10 is planned at the same
    times (every 0.5 s), and both plans are covered."""
    coarse = straight(0.0, 1.0)
    t = np.arange(10 * (len(coarse) - 1) + 1) / 10.0
    fine = np.column_stack([np.interp(t, np.arange(len(coarse)), coarse[:, k]) for k in range(4)])
    generator = ContactGenerator(FLAT)
    a, b = generator.plan(coarse, DT), generator.plan(fine, DT / 10)
    assert a.coverage == b.coverage == 1.0
    assert np.array_equal(10 * np.unique(a.guide_index), np.unique(b.guide_index))
    assert GeneratorConfig().planning_stride(DT) == 5 and GeneratorConfig().planning_stride(DT / 10) == 50
    for bad in (0.0, -0.5, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="planning_interval"):
            GeneratorConfig(planning_interval=bad)


def test_slow_leas_climb_of_eval_stairs_is_covered():
    """A guide of the shipped policy on eval_stairs (start 1.82, 3.87, yaw 0.18 rad; up to
    the top platform): it climbs at ~0.06 m/s with its root rising tread by tread. With a
    0.10 m step trigger the trailing foot stayed a tread lower until its leg was
    overstretched, and the plan stopped at 69 % of the guide."""
    from leas_jax.terrain import load_terrain
    from leas_jax.terrain.generate import scenario_file

    data = np.load(Path(__file__).parent / "data" / "eval_stairs_slow_leas_guide.npz")
    plan = plan_contacts(load_terrain(scenario_file("stairs")), data["guide"], float(data["timestep"]))
    assert plan.coverage == 1.0
    assert verify(plan).ok


def test_the_foot_that_can_lead_steps_first_beside_a_void():
    """A shipped-policy guide of eval_bridge (start 0) sidles left along the start platform,
    facing the void 2-13 cm ahead, towards the bridge. The right foot's place lies past the
    left foot: it could only step in place, 1 cm at a time, and being the most lagging it kept
    doing so while the left foot never moved; at x = 3.87 both feet then lagged out of reach
    (last valid index 230). Steps that bring a foot nearer its target come first now: the
    left foot leads, the right follows, and the whole guide is covered."""
    from leas_jax.terrain import load_terrain
    from leas_jax.terrain.generate import scenario_file

    data = np.load(Path(__file__).parent / "data" / "eval_bridge_sidestep_leas_guide.npz")
    bridge = load_terrain(scenario_file("bridge"))
    plan = plan_contacts(bridge, data["guide"], float(data["timestep"]))
    assert plan.coverage == 1.0
    assert verify(plan).ok
    # Without it (and without the later step fallback and single-support root bound, which
    # get past this place by other steps) the plan stops there.
    any_step = plan_contacts(bridge, data["guide"], float(data["timestep"]), _earlier(min_step_gain=None))
    assert any_step.last_valid_index == 230 and data["guide"][230, 0] < 4.0


def test_soles_turn_to_a_narrow_bridge_axis():
    """Crossing the 0.30 m bridge with the root turned 0.3 rad off its axis: soles at the
    guide's yaw take 0.183 m across each, so they fit only staggered; soles turned to the
    beam's axis fit; with the turning disabled this plan stops on the bridge. (At 0.2 rad
    staggered soles at the guide's yaw cross too, once a sole may rest across the
    platform's and the bridge's coplanar tops; at 0.3 rad they cross too with the step
    fallback and the single-support root bound, so those are off here: `_earlier`.)"""
    bridge = loads_terrain(
        HEAD
        + box([0.5, 0, -0.1], [3, 4, 0.2])
        + box([3.0, 0, -0.1], [2.0, 0.30, 0.2])
        + box([5.5, 0, -0.1], [3, 4, 0.2])
    )
    guide = straight(0.0, 5.0)
    guide[:, 3] = 0.3
    plan = plan_contacts(bridge, guide, DT)
    assert plan.coverage == 1.0
    assert verify(plan).ok
    feet = plan.feet[np.isfinite(plan.feet[:, :, 0])]
    on_bridge = feet[(feet[:, 0] > 2.1) & (feet[:, 0] < 3.9)]
    yaws = np.arctan2(
        2 * (on_bridge[:, 6] * on_bridge[:, 5]), 1 - 2 * on_bridge[:, 5] ** 2
    )  # quaternion xyzw
    assert len(on_bridge) >= 4 and np.abs(yaws).max() < 1e-6
    stiff = plan_contacts(bridge, guide, DT, _earlier(beam_align_yaw=0.0))
    assert stiff.coverage < 1.0
    assert 2.0 < x_at(stiff, stiff.last_valid_index) < 4.0


def test_ground_of_narrow_coplanar_boxes_is_walked():
    """Flat ground built from 0.10 m wide boxes along the guide, narrower than a sole
    (0.13 m): no sole fits inside one box's top; soles rest across their coplanar tops."""
    strips = "".join(box([3, y, -0.1], [8, 0.1, 0.2]) for y in np.arange(-1.95, 2.0, 0.1))
    plan = plan_contacts(loads_terrain(HEAD + strips), straight(0.0, 2.0), DT)
    assert plan.coverage == 1.0
    assert verify(plan).ok


def test_start_on_rubble_tries_other_soles():
    """A training-arena start on rubble tiles (the pose of a shipped-policy-like rollout):
    the best candidate of each foot gives a stance that fails its checks; a pair of
    lower-ranked candidates stands, and the one-posture plan passes `verify`."""
    from leas_jax.contacts.planner.generator import LEFT, RIGHT
    from leas_jax.terrain import load_terrain

    arena = load_terrain(Path(__file__).parents[1] / "terrains" / "training_arena.toml")
    pose = np.array([2.715, 7.48, 1.046, 2.169])
    generator = ContactGenerator(arena)
    left = generator.footholds.first_candidate(LEFT, pose, *generator.footholds.nominal_placement(pose, LEFT))
    right = generator.footholds.first_candidate(
        RIGHT, pose, *generator.footholds.nominal_placement(pose, RIGHT), left
    )
    assert generator.projection.posture(pose, 0, [(LEFT, *left), (RIGHT, *right)]) is None
    plan = plan_contacts(arena, pose[None], DT)
    assert plan.last_valid_index == 0 and len(plan.q) == 1
    assert verify(plan).ok


def test_lifted_foot_clears_a_stance_sole_near_the_guide_line():
    """The first 30 s of a shipped-policy guide on eval_circuit's slabs (its root 1.05 m above
    the stance sole, which a slab's edge put 4 cm from the guide's line instead of 8.5 cm):
    held under its hip, the lifted foot met the stance shin at every root shift and the
    plan stopped at pose 160; held `swing_clearance` farther out, it passes."""
    from leas_jax.terrain import load_terrain
    from leas_jax.terrain.generate import scenario_file

    data = np.load(Path(__file__).parent / "data" / "eval_circuit_slabs_leas_guide.npz")
    circuit = load_terrain(scenario_file("circuit"))
    plan = plan_contacts(circuit, data["guide"], float(data["timestep"]))
    assert plan.coverage == 1.0
    assert verify(plan).ok
    held_under = plan_contacts(
        circuit,
        data["guide"],
        float(data["timestep"]),
        _narrow(swing_clearance=0.0, refine_stride=None),
    )
    assert held_under.last_valid_index == 160


def test_a_step_falls_back_to_the_place_under_the_root():
    """The first 16 s of a shipped-policy guide on the training arena's stairs pit (start 236
    of studies/guide_failures.py, evaluation seed 0): at pose 120 the left foot lags
    0.30 m behind its place and no foothold within `candidate_radius` of its place 0.7 s
    ahead gives a posture, nor does the right foot's step; the plan stopped at pose 115.
    A step toward the foot's place under the planning pose itself
    (`GeneratorConfig.fallback_lookahead`) passes, and the whole guide is covered."""
    guide, timestep = _arena_guide("stairs_pit_fallback")
    plan = plan_contacts(_arena(), guide, timestep)
    assert plan.coverage == 1.0
    assert verify(plan).ok
    no_fallback = plan_contacts(
        _arena(), guide, timestep, _narrow(fallback_lookahead=None, refine_stride=None)
    )
    assert no_fallback.last_valid_index == 115


def test_single_support_over_a_far_stance_sole():
    """The first 24.5 s of a shipped-policy guide across the training arena's rubble (start
    160, evaluation seed 0): at pose 205 each foot's single support needs the root more than
    0.12 m off the guide to bring the CoM over the stance sole, which stands within its
    comfort region but far from the guide root. Held to `max_root_offset_xy` (0.12 m) the plan stopped
    at pose 200; with `max_single_support_offset_xy` the whole guide is covered, and `verify`
    holds every single-support root to that bound."""
    guide, timestep = _arena_guide("rubble_single_support")
    plan = plan_contacts(_arena(), guide, timestep)
    assert plan.coverage == 1.0
    assert verify(plan).ok
    in_air = ~np.all(np.isfinite(plan.feet[:, :, 0]), axis=1)
    offsets = np.hypot(*(plan.q[:, :2] - guide[plan.guide_index, :2]).T)
    assert offsets[~in_air].max() <= GeneratorConfig().max_root_offset_xy + 1e-6
    assert 0.12 < offsets[in_air].max() <= GeneratorConfig().max_single_support_offset_xy + 1e-6
    held = plan_contacts(
        _arena(), guide, timestep, _narrow(max_single_support_offset_xy=0.12, refine_stride=None)
    )
    assert held.last_valid_index == 200


def _earlier(**changes) -> GeneratorConfig:
    """The generator before its step fallback, single-support root bound and refined planning
    poses, with `changes`: for tests that show what an earlier feature was needed for."""
    return _narrow(fallback_lookahead=None, max_single_support_offset_xy=0.12, refine_stride=None, **changes)


def _narrow(**changes) -> GeneratorConfig:
    """The generator's step search before its wider candidates and comfort region and its
    retries (`retry_settings`), with `changes`: for tests that show what a feature is needed
    for; the wider search passes some of their counterfactuals by another way."""
    settings = dict(
        max_foot_offset=0.25,
        max_single_support_offset_xy=0.20,
        candidate_radius=0.15,
        max_candidates=12,
        retry_settings=(),
    )
    return GeneratorConfig(**{**settings, **changes})


def _arena_guide(what: str) -> tuple[np.ndarray, float]:
    """(guide [T, 4] float64, timestep s) of tests/data/training_arena_<what>_leas_guide.npz."""
    data = np.load(Path(__file__).parent / "data" / f"training_arena_{what}_leas_guide.npz")
    return data["guide"].astype(np.float64), float(data["timestep"])


def _arena():
    """The training arena (loaded once per test module)."""
    from leas_jax.terrain import load_terrain

    if "arena" not in _ARENA:
        _ARENA["arena"] = load_terrain(Path(__file__).parents[1] / "terrains" / "training_arena.toml")
    return _ARENA["arena"]


_ARENA: dict = {}


def test_candidates_keep_the_foot_out_of_a_riser_behind_the_heel():
    """A step down at x = 1.0 (0.15 m). A left sole on the lower tread with its rectangle's
    back edge 6 mm from the riser fits its face (5 mm margin), but the foot's collision
    geometry overhangs the heel by 1.6 cm and would meet the riser: `screen` drops it, and
    keeps the same sole 3 cm farther on."""
    from leas_jax.contacts.planner.generator import LEFT
    from leas_jax.contacts.robot.collision import foot_footprint, robot_collision

    terrain = loads_terrain(HEAD + box([0.0, 0, 0.0], [2.0, 4, 0.3]) + box([3.0, 0, -0.1], [4.0, 4, 0.2]))
    generator = ContactGenerator(terrain)
    heel = -float(foot_footprint(robot_collision(generator.talos), LEFT)[:, 0].min())
    assert 0.11 < heel < 0.12  # the sole's half length is 0.10 m
    xs = np.array([1.106, 1.136])
    pos = np.stack([xs, np.full(2, 0.1), np.zeros(2)], axis=1)
    rot = np.repeat(np.eye(3)[None], 2, axis=0)
    pose = np.array([1.12, 0.0, H, 0.0])
    assert generator.footholds.screen(LEFT, pose, pos, rot).tolist() == [False, True]


def test_first_stance_steps_away_from_a_box_beside_a_shin():
    """A 0.09 m box 4 cm beside the right sole's nominal place: the shin's ankle linkage
    (4 cm above the sole, out past its side) meets it at the nominal stance and at every
    candidate near it, so without `stance_shifts` the plan has no first posture; with them
    both soles' places move a few cm away, the root follows, and the plan verifies."""
    ground = box([3, 0, -0.1], [8, 4, 0.2])
    # nominal soles at y = +-0.085, 0.14 m wide: the right one's outer edge at y = -0.155
    beside = box([0.0, -0.295, 0.045], [0.6, 0.2, 0.09])
    terrain = loads_terrain(HEAD + ground + beside)
    guide = straight(0.0, 1.5)
    plan = plan_contacts(terrain, guide, DT)
    assert plan.coverage == 1.0
    assert verify(plan).ok
    assert plan_contacts(terrain, guide, DT, GeneratorConfig(stance_shifts=())).last_valid_index < 0
    with pytest.raises(ValueError, match="stance_shifts"):
        GeneratorConfig(stance_shifts=(0.5,))


def test_root_steps_sideways_off_a_pillar_the_arms_meet():
    """The first 3 s of a shipped-policy guide starting beside one of the training arena's
    pillars (start 12 of studies/guide_failures.py, evaluation seed 0): the policy turns
    on the spot with the pillar's face inside the reach of the shoulders (0.38 m to the side
    of the root even with the arms held in), so every posture from pose 10 on met it and the
    plan stopped at pose 5. With the root shifted sideways off the guide
    (`GeneratorConfig.arm_clearance_shifts`, within the usual root bounds) the whole guide is
    covered and verified."""
    guide, timestep = _arena_guide("pillars_arm_clearance")
    plan = plan_contacts(_arena(), guide, timestep)
    assert plan.coverage == 1.0
    assert verify(plan).ok
    held = plan_contacts(_arena(), guide, timestep, _narrow(arm_clearance_shifts=(), refine_stride=None))
    assert held.last_valid_index == 5
    with pytest.raises(ValueError, match="arm_clearance_shifts"):
        GeneratorConfig(arm_clearance_shifts=(0.0,))


def test_a_fast_turn_is_followed_through_the_poses_between():
    """RBKino (HPP's kinodynamic steering) from rest turned 90 degrees away from a goal 4 m
    off, setting off at 0.04 m/s: its root turns by most of that within the first 0.5 s,
    so at the first planning pose the feet, still at the start yaw, are past the hip-yaw
    and comfort limits and the plan stopped at the first pose. Planned again at every guide
    pose of that half-second (`GeneratorConfig.refine_stride`), the feet turn through the
    yaws on the way and the whole guide is covered and verified."""
    from leas_jax.steering.rbkino import rbkino_planar

    planar = rbkino_planar((0.0, 0.0, np.pi / 2), (4.0, 0.0), initial_speed=0.04)
    guide = np.column_stack([planar[:, :2], np.full(len(planar), H), planar[:, 2]])
    assert abs(guide[5, 3] - guide[0, 3]) > 0.8  # rad turned in the first 0.5 s
    plan = plan_contacts(FLAT, guide, DT)
    assert plan.coverage == 1.0
    assert verify(plan).ok
    assert plan_contacts(FLAT, guide, DT, GeneratorConfig(refine_stride=None)).last_valid_index == 0


def test_retry_settings_name_only_step_settings():
    """A retry may change how feet step, not how far the root may leave the guide
    (what `verify` checks) nor what the stages are built from."""
    retried = GeneratorConfig().retried((("lookahead", 0.9), ("max_candidates", 48)))
    assert (retried.lookahead, retried.max_candidates, retried.retry_settings) == (0.9, 48, ())
    for bad in ((("max_root_offset_xy", 0.2),), (("mu", 0.5),), ("lookahead",)):
        with pytest.raises(ValueError, match="retry_settings"):
            GeneratorConfig(retry_settings=(bad,))
    with pytest.raises(ValueError, match="retry_backtrack"):
        GeneratorConfig(retry_backtrack=-1)


def test_a_stuck_plan_goes_back_and_retries_with_other_step_settings():
    """A shipped-policy guide into the arena's stairs pit: with its own settings the
    generator stops at guide pose 37, whatever it tries there; going back 4 planning poses
    and planning them again with the other step settings of `retry_settings` in turn
    places the feet so that pose 37 and the rest of the guide pass, within the root's usual
    bounds (the plan verifies)."""
    guide, timestep = _arena_guide("stairs_pit_retry")
    assert plan_contacts(_arena(), guide, timestep, GeneratorConfig(retry_settings=())).last_valid_index == 37
    plan = plan_contacts(_arena(), guide, timestep)
    assert plan.coverage == 1.0
    assert verify(plan).ok


def test_a_wider_step_search_finds_the_tread_a_foot_can_take():
    """A shipped-policy guide climbing the arena's stairs: with candidates within 0.15 m of
    the step target and a 0.25 m comfort region the plan stops at guide pose 63; the 0.30 m
    candidate radius and 0.32 m comfort region (no retries needed) cover it."""
    guide, timestep = _arena_guide("stairs_up_wide_search")
    assert plan_contacts(_arena(), guide, timestep, _narrow()).last_valid_index == 63
    plan = plan_contacts(_arena(), guide, timestep, GeneratorConfig(retry_settings=()))
    assert plan.coverage == 1.0
    assert verify(plan).ok


def test_rise_is_the_terrain_a_swing_passes_above_the_foot():
    """A 0.12 m step at x = 1.0: a foot at x = 0.7 stepping to x = 1.2 passes 0.12 m of
    terrain above its sole; one stepping on the flat, or down from the step, passes none; a
    target short of the riser still meets it within a sole's half length beyond."""
    step = loads_terrain(HEAD + box([0, 0, -0.1], [2, 4, 0.2]) + box([3, 0, -0.04], [4, 4, 0.32]))
    footholds = ContactGenerator(step).footholds
    assert footholds.rise([0.7, 0.0, 0.0], [1.2, 0.0, 0.12]) == pytest.approx(0.12)
    assert footholds.rise([0.2, 0.0, 0.0], [0.5, 0.1, 0.0]) == pytest.approx(0.0)
    assert footholds.rise([1.5, 0.0, 0.12], [0.8, 0.0, 0.0]) == pytest.approx(0.0)
    assert footholds.rise([0.6, 0.0, 0.0], [0.95, 0.0, 0.0]) == pytest.approx(0.12)
    assert footholds.rise([0.3, 0.0, 0.0], [0.3, 0.0, 0.0]) == pytest.approx(0.0)


def test_a_swing_held_high_over_a_rise_climbs_where_the_low_one_meets_the_riser():
    """A shipped-policy guide climbing the arena's stairs at 0.10 m/s (its first 13 s):
    with the 6 retries before `swing_lift_on_rise` the plan stops at guide pose 90, a leg
    meeting the terrain; the retry holding the foot in the air 0.15 m above its last contact
    where a riser is ahead covers it, and the plan verifies. On flat ground that retry is the
    default settings again: `test_turning_too_fast_stops` still stops."""
    guide, timestep = _arena_guide("stairs_up_swing_lift_on_rise")
    base = GeneratorConfig()
    without = tuple(r for r in base.retry_settings if dict(r).keys() != {"swing_lift_on_rise"})
    assert len(without) == len(base.retry_settings) - 1
    stopped = plan_contacts(_arena(), guide, timestep, dataclasses.replace(base, retry_settings=without))
    assert stopped.last_valid_index == 90
    plan = plan_contacts(_arena(), guide, timestep)
    assert plan.coverage == 1.0
    assert verify(plan).ok
