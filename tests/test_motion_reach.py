"""Single support where no single depth on the contact weight lets the legs reach every sample:
the root's height is chosen sample by sample inside what reaches (`reach_interval`), the
smoothest such profile at rest at both ends (`dip_profile`)."""

import dataclasses

import numpy as np
import pytest
from motion_helpers import straight_plan

from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.config import MotionConfig
from leas_jax.motion.motion import (
    MotionError,
    contact_weight,
    dip_profile,
    held_root_configuration,
    held_root_support,
    posture_frames,
    profiled_support,
    reach_interval,
    root_dip,
    stretched_samples,
)


def test_dip_profile_stays_inside_its_bounds_and_is_at_rest_at_both_ends():
    """A landing whose swing leg needs the root 8-10 cm higher in mid-swing and at most 1 cm
    higher at its contact: inside every bound, the key posture's samples at 0, the contact end
    level, and smooth (no single depth x weight fits: 0.1 / 0.5 > 0.01 / 1)."""
    weight = contact_weight(81, lifting=False)
    t = np.linspace(0.0, 1.0, 81)
    bump = np.exp(-0.5 * ((t - 0.5) / 0.12) ** 2)
    low = np.where(t < 0.8, -0.3, -0.01)
    high = 0.03 - 0.13 * bump  # [-0.3, -0.1] mid-swing, [-0.01, 0.03] at the contact
    dips = dip_profile(low, high, weight)
    assert np.all(dips >= low - 1e-9) and np.all(dips <= high + 1e-9)
    assert np.all(np.abs(dips[weight < 1e-3]) < 1e-9)
    assert abs(dips[-1] - dips[-2]) < 1e-6 and abs(dips[-2] - dips[-3]) < 1e-6
    assert dips.min() < -0.09
    # smooth: its acceleration (second differences) grows from 0 at the key posture and
    # changes little from sample to sample (a kink at a bound would be a jump)
    second = np.diff(dips, 2)
    assert np.abs(second[:2]).max() < 1e-9 and np.abs(second).max() < 1e-3
    assert np.abs(np.diff(second)).max() < 1e-4
    assert high[40] / weight[40] * weight[-1] < low[-1]  # one depth on the weight: too high at contact


def test_reach_interval_brackets_the_root_heights_that_reach():
    talos = load_talos()
    q = straight_plan(0.3).q[1]
    feet, _, rotation = posture_frames(talos, q)
    lower = feet.copy()
    lower[0, 2, 3] -= 0.2  # the left sole 0.2 m lower: the root comes down 7-30 cm
    knees, shift = np.zeros(2), np.zeros(2)
    low, high = reach_interval(talos, q, lower, rotation, shift, knees)
    assert abs(low - root_dip(talos, q, lower, rotation, shift, knees)) < 1e-4
    for dip, reaches in ((low + 1e-4, True), (high - 1e-4, True), (low - 1e-3, False)):
        configuration = held_root_configuration(talos, q, lower, rotation, np.r_[shift, -dip], knees)
        assert (configuration is not None) == reaches
    raised = feet.copy()
    raised[0, 2, 3] += 0.2  # 0.2 m higher: the root may rise 7 cm or come down 11
    low, high = reach_interval(talos, q, raised, rotation, shift, knees)
    assert -0.1 < low < -0.05 and 0.05 < high < 0.15
    raised[0, 2, 3] += 0.3
    assert np.isnan(reach_interval(talos, q, raised, rotation, shift, knees)).all()


def test_a_swing_needing_the_root_low_midway_and_high_at_contact_is_made():
    """The left sole dips 0.2 m below its start mid-swing (the root must come down 7 cm there,
    0.15 m on the contact weight) and lands 0.2 m above it (the root may come down at most
    11 cm there): the held-root depth cannot do both, the profile can."""
    talos, config = load_talos(), MotionConfig()
    q = straight_plan(0.3).q[1]
    feet, com, rotation = posture_frames(talos, q)
    t = np.linspace(0.0, 1.0, 81)
    path = np.repeat(feet[None], 81, axis=0)
    path[:, 0, 2, 3] += 0.2 * t - 0.3 * np.sin(np.pi * t)
    rotations = np.repeat(rotation[None], 81, axis=0)
    with pytest.raises(MotionError):
        held_root_support(talos, q, path, rotations, 0, False, config)
    with pytest.raises(MotionError, match="profiled_reach"):
        profiled_support(
            talos, q, path, rotations, 0, False, dataclasses.replace(config, profiled_reach=False)
        )
    coms = profiled_support(talos, q, path, rotations, 0, False, config)[0]
    np.testing.assert_allclose(coms[0], com, atol=1e-6)  # the key posture's root, held
    assert coms[40, 2] < com[2] - 0.03  # come down midway
    assert np.abs(np.diff(coms[:, 2], 2)).max() < 1e-3


def test_a_profiled_phase_is_stretched_for_its_vertical_acceleration_too():
    """A CoM path that only rises and comes down (a root height profile): no horizontal
    acceleration, so only the vertical count lengthens it, by sqrt(peak / limit)."""
    dt, samples = 0.01, 80
    t = np.linspace(0.0, 1.0, samples + 1)
    path = np.zeros((samples + 1, 3))
    path[:, 2] = 0.1 * np.sin(np.pi * t) ** 2  # peak vertical acceleration 2 pi^2 0.1 / 0.8^2 = 3.1 m/s^2
    assert stretched_samples(path, samples, 0.5, dt) == samples
    longer = stretched_samples(path, samples, 0.5, dt, vertical=True)
    assert 190 < longer < 210


def test_reach_intervals_stop_at_the_first_sample_found_out_of_reach(monkeypatch):
    """Every tenth sample is searched first and the search stops where the soles are out of
    reach: a phase that cannot be made costs a tenth of the searches; one that can, all of them
    in any order, each sample its own interval."""
    import leas_jax.motion.motion as motion

    searched = []

    def interval(talos, q, feet, rotation, shift, knees, margin):
        searched.append(int(feet))
        return (np.nan, np.nan) if feet == 30 else (-0.01 * feet, 0.01 * feet)

    monkeypatch.setattr(motion, "reach_interval", interval)
    samples = np.arange(100)
    low, high, out = motion.reach_intervals(None, None, samples, samples, samples, samples, 0.0)
    assert out == 30 and searched == [0, 10, 20, 30]
    searched.clear()
    samples = np.arange(25)
    low, high, out = motion.reach_intervals(None, None, samples, samples, samples, samples, 0.0)
    assert out is None and sorted(searched) == list(range(25))
    np.testing.assert_allclose(high, 0.01 * samples)
    np.testing.assert_allclose(low, -0.01 * samples)


def test_a_bound_through_the_key_posture_leaves_it_without_a_step():
    """A landing whose key posture has its legs at their reach: the highest lowering that reaches
    falls through 0 just after the key posture's samples. The profile leaves them smoothly, and
    a longer phase has it gentler (what lengthening a phase for its acceleration relies on); a
    full 5 mm inset there forced a step at any duration."""
    peaks = []
    for samples in (81, 321):
        weight = contact_weight(samples, lifting=False)
        t = np.linspace(0.0, 1.0, samples)
        high = 0.004 - 0.05 * t  # the root must rise after t = 0.08
        dips = dip_profile(np.full(samples, -0.3), high, weight)
        assert np.all(dips <= high + 1e-9) and np.all(np.abs(dips[weight < 1e-3]) < 1e-9)
        peaks.append(np.abs(np.diff(dips, 2)).max())
    assert peaks[0] < 1e-3 and peaks[1] < 0.5 * peaks[0], peaks
