"""Transitions between key postures: lift-offs and landings checked as the generator plans."""

import dataclasses

import numpy as np
import pytest

from leas_jax.contacts import GeneratorConfig
from leas_jax.contacts.planner.config import TransitionConfig, motion_generator_config
from leas_jax.contacts.planner.generator import ContactGenerator
from leas_jax.contacts.planner.projection import ContactPosture
from leas_jax.contacts.planner.transitions import TransitionCheck
from leas_jax.contacts.robot.clearance import BodyClearance
from leas_jax.contacts.robot.model import LEFT, matrix_from_quat_xyzw
from leas_jax.motion import motion
from leas_jax.motion.config import MotionConfig
from leas_jax.terrain import loads_terrain
from tests.test_contacts_generator import DT, FLAT, HEAD, box, straight


def test_the_bounds_are_the_motions():
    """The generator asks of a transition what `make_motion` asks of it."""
    bounds, motion_config = TransitionConfig(), MotionConfig()
    assert bounds.min_knee == motion_config.min_knee
    assert bounds.body_clearance == motion_config.body_clearance
    assert bounds.apex_clearance == motion_config.swing_clearance
    assert (bounds.max_dip, bounds.max_rise) == (motion.MAX_DIP, motion.MAX_RISE)
    assert motion_generator_config().transitions == bounds
    assert GeneratorConfig().transitions is None


def test_root_offsets_lower_first_then_rise_as_the_motion_does():
    offsets = TransitionConfig(max_dip=0.05, max_rise=0.02, root_step=0.02).root_offsets()
    assert offsets == pytest.approx([0.0, -0.02, -0.04, -0.05, 0.02])
    wide = TransitionConfig().root_offsets()
    assert min(wide) == pytest.approx(-0.30) and max(wide) == pytest.approx(0.15)
    assert len(set(np.round(wide, 9))) == len(wide) == 1 + 15 + 8  # 0.14 m, then 0.15 m up


@pytest.fixture(scope="module")
def checked():
    """A flat-ground plan made with the transitions checked, and its generator."""
    generator = ContactGenerator(FLAT, motion_generator_config())
    return generator, generator.plan(straight(0.0, 2.0), DT)


def _step(plan):
    """(before, single, after, swing side) of the plan's first single support."""
    k = next(k for k in range(len(plan.q)) if np.isnan(plan.feet[k, :, 0]).any())
    swing = int(np.flatnonzero(np.isnan(plan.feet[k, :, 0]))[0])
    return k - 1, k, k + 1, swing


def _posture(plan, k) -> ContactPosture:
    return ContactPosture(q=plan.q[k], feet=plan.feet[k], guide_index=int(plan.guide_index[k]))


def _placement(plan, k, side):
    row = plan.feet[k, side]
    return row[:3].copy(), matrix_from_quat_xyzw(row[3:])


def test_flat_ground_plans_the_same_with_its_transitions_checked(checked):
    _, plan = checked
    unchecked = ContactGenerator(FLAT, GeneratorConfig()).plan(straight(0.0, 2.0), DT)
    assert plan.coverage == 1.0
    np.testing.assert_array_equal(plan.q, unchecked.q)


def test_a_plans_own_step_passes_and_a_far_or_crossed_landing_is_refused(checked):
    generator, plan = checked
    transitions = generator.walking.transitions
    before, k, after, swing = _step(plan)
    single, landed = _posture(plan, k), _posture(plan, after)
    assert transitions.lift_off(single, swing, _placement(plan, before, swing)) is None
    pos, rot = _placement(plan, after, swing)
    assert transitions.landing(single, swing, (pos, rot), landed) is None
    outward = np.array([0.0, 1.0 if swing == LEFT else -1.0, 0.0])  # the swing side, world
    # 0.8 m out on the swing side: no root height reaches it
    far = transitions.landing(single, swing, (pos + 0.8 * outward, rot), landed)
    assert far.startswith("halfway at the apex: the soles are out of the legs' reach")
    # beyond the stance sole: the swing leg would cross the stance leg
    stance_pos, _ = _placement(plan, after, 1 - swing)
    reason = transitions.landing(single, swing, (stance_pos - 0.2 * outward, rot), landed)
    assert reason is not None and "collides with" in reason


def test_a_landing_that_settles_a_knee_by_a_beam_is_refused(checked):
    """A beam at knee height 5 mm in front of the landing posture: collision-free, so a key
    posture, but within the 1 cm a motion shifting through it needs."""
    generator, plan = checked
    _, k, after, swing = _step(plan)
    single, landed = _posture(plan, k), _posture(plan, after)
    contact = _placement(plan, after, swing)

    def beam(x, floor=True):  # 0.3-0.6 m above the floor, its near face at x (m)
        ground = box([3, 0, -0.1], [8, 4, 0.2]) if floor else ""
        return loads_terrain(HEAD + ground + box([x + 0.05, 0, 0.45], [0.1, 4, 0.3]))

    far = float(landed.q[0]) + 1.0
    gap = BodyClearance(generator.projection.talos, beam(far, floor=False)).distance(landed.q, 1.5)
    near = TransitionCheck(beam(far - gap + 0.005), generator.projection, TransitionConfig())
    reason = near.landing(single, swing, contact, landed)
    assert reason.startswith("settled: ") and "comes within 1 cm of terrain box 1" in reason
    clear = TransitionCheck(beam(far - gap + 0.05), generator.projection, TransitionConfig())
    assert clear.landing(single, swing, contact, landed) is None


def test_a_lift_off_the_motion_cannot_make_stops_the_plan():
    """Knees held bent further than flat walking bends them, with the root not free to move:
    no single support can be left from where the feet stand, and the generator says why."""
    strict = dataclasses.replace(
        motion_generator_config(), transitions=TransitionConfig(min_knee=1.2, max_dip=0.0, max_rise=0.0)
    )
    plan, reasons = ContactGenerator(FLAT, strict).stop_reasons(straight(0.0, 2.0), DT)
    assert plan.coverage < 0.2
    assert reasons["transition: lift-off"] > 0
