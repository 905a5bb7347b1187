"""Single support where no root height over the key posture reaches: the root moves
horizontally too (`shifted_support`), the CoM kept inside the stance sole; and long phases'
height profiles solved at fewer samples (`dip_profile`)."""

import dataclasses

import numpy as np
import pytest
from motion_helpers import straight_plan

from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion import motion
from leas_jax.motion.config import MotionConfig
from leas_jax.motion.motion import (
    MotionError,
    contact_weight,
    dip_profile,
    held_root_support,
    posture_frames,
    profiled_support,
    shift_candidates,
    shifted_support,
    sole_corners,
    support_margins,
)
from leas_jax.motion.paths import LAND_WINDOWS, swing_path


def wide_landing(talos, outward: float):
    """A landing of the left sole `outward` m to the left of its place in straight_plan's first
    one-foot posture, on flat ground: (q [39], feet [81, 2, 4, 4], rotations [81, 3, 3])."""
    q = straight_plan(0.3).q[1]
    feet, _, rotation = posture_frames(talos, q)
    start = feet[0][:3, 3]
    end = start + np.r_[0.0, outward, 0.0]
    path = np.repeat(feet[None], 81, axis=0)
    path[:, 0, :3, 3] = swing_path(start, end, start[2] + 0.05, np.linspace(0.0, 1.0, 81), LAND_WINDOWS)
    return q, path, np.repeat(rotation[None], 81, axis=0)


def test_a_wide_landing_is_made_by_shifting_the_root_with_the_com_over_the_stance_sole():
    """0.25 m outward: no root height over the key posture reaches the landing (the swing hip
    and ankle roll past their limits), a root moved a few centimetres does; the CoM stays
    `single_support_margin` inside the stance (right) sole and the key posture's root is kept."""
    talos, config = load_talos(), MotionConfig()
    q, feet, rotations = wide_landing(talos, 0.25)
    with pytest.raises(MotionError):
        held_root_support(talos, q, feet, rotations, 0, False, config)
    with pytest.raises(MotionError):
        profiled_support(talos, q, feet, rotations, 0, False, config)
    coms, configurations = shifted_support(talos, q, feet, rotations, 0, False, config)
    np.testing.assert_allclose(configurations[0][:3], q[:3], atol=1e-9)  # the key posture's root
    shift = configurations[-1][:2] - q[:2]
    assert 0.01 < np.linalg.norm(shift) <= config.root_shift + 1e-9
    assert shift[1] > 0.0  # towards the swing sole (left, +y)
    stance = sole_corners(feet[0], np.array([False, True]))
    assert support_margins(stance, coms[:, :2]).min() >= config.single_support_margin
    with pytest.raises(MotionError, match="root_shift"):
        shifted_support(talos, q, feet, rotations, 0, False, dataclasses.replace(config, root_shift=0.0))


def test_a_landing_too_wide_for_any_shift_says_how_close_the_best_came():
    talos, config = load_talos(), MotionConfig()
    q, feet, rotations = wide_landing(talos, 0.25)
    strict = dataclasses.replace(config, single_support_margin=0.2)  # wider than the 0.13 m sole
    key = support_margins(
        sole_corners(feet[0], np.array([False, True])), posture_frames(talos, q)[1][None, :2]
    )
    with pytest.raises(
        MotionError, match=r"keeps the CoM ([\d.]+) cm inside .* the best, a 0\.\d\d m shift"
    ) as error:
        shifted_support(talos, q, feet, rotations, 0, False, strict)
    # as far inside as the key posture itself, where that is less than asked
    assert abs(float(error.value.args[0].split("keeps the CoM ")[1].split(" cm")[0]) - 100 * key[0]) < 0.01


def test_shift_candidates_go_shortest_first_towards_the_swing_sole_first():
    candidates = shift_candidates(0.1, 0.02, np.array([0.0, 1.0]))
    lengths = np.linalg.norm(candidates, axis=1)
    assert len(candidates) == 41 and np.all(np.diff(lengths) > -1e-12)
    np.testing.assert_allclose(lengths[[0, 1, -1]], [0.0, 0.02, 0.1])
    np.testing.assert_allclose(candidates[1], [0.0, 0.02], atol=1e-12)
    np.testing.assert_allclose(candidates[8], [0.0, -0.02], atol=1e-12)


def test_a_long_phase_profile_is_solved_at_fewer_samples_and_stays_inside_its_bounds():
    """A landing whose swing leg needs the root 8-10 cm higher in mid-swing and at most 1 cm
    higher at its contact, lengthened to 6 s (600 samples, over PROFILE_KNOTS): inside every
    bound, the key posture's samples at 0, at rest at the contact end, and gentler than the
    same landing over 0.8 s solved at every sample (what lengthening a phase relies on)."""

    def profile(samples: int) -> np.ndarray:
        weight = contact_weight(samples, lifting=False)
        t = np.linspace(0.0, 1.0, samples)
        low = np.where(t < 0.8, -0.3, -0.01)
        high = 0.03 - 0.13 * np.exp(-0.5 * ((t - 0.5) / 0.12) ** 2)
        dips = dip_profile(low, high, weight)
        assert np.all(dips >= low - 1e-12) and np.all(dips <= high + 1e-12)
        assert np.all(np.abs(dips[weight < 1e-3]) < 1e-9)
        assert np.ptp(dips[-3:]) < 1e-6 and dips.min() < -0.09
        return dips

    assert 600 > motion.PROFILE_KNOTS >= 81
    peaks = [np.abs(np.diff(profile(samples), 2)).max() / 0.01**2 for samples in (81, 600)]  # m/s^2
    assert peaks[1] < 0.5 * peaks[0], peaks


def test_a_balanced_single_support_keeps_its_com_inside_where_the_held_root_leans_out():
    """A landing 0.15 m lower and 0.1 m ahead with the held root leaning 9 cm along the stance
    sole (`MotionConfig.lean`): its CoM comes within 3 cm of the sole's toe; made balanced,
    the CoM stays `single_support_margin` inside at every sample."""
    talos = load_talos()
    config = dataclasses.replace(MotionConfig(), lean=0.09)
    q = straight_plan(0.3).q[1]
    feet, _, rotation = posture_frames(talos, q)
    start = feet[0][:3, 3]
    path = np.repeat(feet[None], 81, axis=0)
    t = np.linspace(0.0, 1.0, 81)
    path[:, 0, :3, 3] = swing_path(start, start + np.r_[0.1, 0.0, -0.15], start[2] + 0.05, t, LAND_WINDOWS)
    rotations = np.repeat(rotation[None], 81, axis=0)
    spec = motion._PhaseSpec(
        "land", (1, 2), 0, 80, feet, path[-1], None, None, rotation, rotation, q, q, start[2] + 0.05
    )
    stance = sole_corners(feet, np.array([False, True]))
    held = held_root_support(talos, q, path, rotations, 0, False, config)[0]
    assert support_margins(stance, held[:, :2]).min() < config.single_support_margin
    _, coms, _, profiled = motion._single_support_coms(talos, spec, 1, config, balanced=True)
    assert profiled and support_margins(stance, coms[:, :2]).min() >= config.single_support_margin


def test_a_single_support_failing_its_equilibrium_check_is_made_again_balanced(monkeypatch):
    """make_motion makes a single support whose samples fail the equilibrium check once more
    with `balanced` (only that segment), and keeps the second motion; with root_shift 0 it
    makes it slower instead, and with neither it does not, and the failure is reported."""
    plan = straight_plan(0.3)
    segments, checks = [], []
    real_segment, real_check = motion._segment_phases, motion.check_motion

    def segment(plan, k, frames, terrain, config, talos, balanced=False, clearance=None):
        segments.append((k, balanced))
        return real_segment(plan, k, frames, terrain, config, talos, balanced, clearance)

    def check(made, config, clearance=None, collided=None):
        failures = real_check(made, config, clearance, collided)
        if not checks:  # the first motion: its first single support said to tip over
            index = next(i for i, phase in enumerate(made.phases) if phase.single_support)
            failures.append((made.phases[index].start + 1, index, "equilibrium", "robustness -1 < 0.0"))
        checks.append(made)
        return failures

    monkeypatch.setattr(motion, "_segment_phases", segment)
    monkeypatch.setattr(motion, "check_motion", check)
    made = motion.make_motion(plan, check=False)
    first = next(phase for phase in checks[0].phases if phase.single_support).postures[0]
    assert len(checks) == 2 and made is checks[1] and made.failures == []
    assert [k for k, balanced in segments if balanced] == [first]
    assert len(segments) == len(plan)  # every segment once, the remade one twice
    segments.clear(), checks.clear()
    unmoved = dataclasses.replace(MotionConfig(), root_shift=0.0, slowed_duration=0.0)
    made = motion.make_motion(plan, unmoved, check=False)
    assert len(checks) == 1 and [f[2] for f in made.failures] == ["equilibrium"]
    # without root shifts, the segment is made again slower, not balanced
    segments.clear(), checks.clear()
    made = motion.make_motion(plan, dataclasses.replace(MotionConfig(), root_shift=0.0), check=False)
    assert len(checks) == 2 and made.failures == [] and not any(balanced for _, balanced in segments)
    slow = [p for p in made.phases if p.single_support and p.postures[0] == first]
    fast = [p for p in checks[0].phases if p.single_support and p.postures[0] == first]
    assert sum(p.stop - p.start for p in slow) >= 1.9 * sum(p.stop - p.start for p in fast)


def test_a_long_profile_whose_fewer_samples_leave_no_room_is_solved_at_every_sample():
    """Bounds 1 mm apart that move faster than a knot's span: the bounds of a knot's span
    leave it no room, so the profile is solved at every sample, inside every bound."""
    samples = 400
    weight = contact_weight(samples, lifting=False)
    high = 0.05 * np.sin(np.linspace(0.0, 40.0, samples)) * weight + 0.0005
    low = high - 0.001
    dips = dip_profile(low, high, weight)
    assert np.all(dips >= low - 1e-12) and np.all(dips <= high + 1e-12)
