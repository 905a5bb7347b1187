"""Single supports whose swing leg unbends fast are lengthened for their joints' speed: the
configurations their CoM references come from keep every joint within SPEED_MARGIN of its
velocity limit, and the whole-body IK that tracks them within the limit."""

import dataclasses

import numpy as np
from motion_helpers import straight_plan

from leas_jax.contacts.robot.model import load_talos
from leas_jax.motion.config import MotionConfig
from leas_jax.motion.motion import (
    SPEED_MARGIN,
    _PhaseSpec,
    _single_support,
    _single_support_coms,
    phase_references,
    posture_frames,
    speed_samples,
)
from leas_jax.motion.wbik import WholeBodyIK


def test_speed_samples_scale_with_the_peak_speed():
    dt, samples = 0.01, 80
    path = np.zeros((samples + 1, 39))
    path[:, 10] = (
        1.4 * (1.0 - np.cos(np.pi * np.linspace(0.0, 1.0, samples + 1))) / 2
    )  # peak 0.7 pi / 0.8 s = 2.75 rad/s
    limits = np.full(32, 7.0)
    assert speed_samples(path, samples, limits, dt) == samples
    assert speed_samples(path, samples, limits / 2, dt) == samples  # 2.75 < 3.5
    assert 124 <= speed_samples(path, samples, limits / 4, dt) <= 127  # 2.75 / 1.75 = 1.57 x


def _peak_speed_ratio(talos, ik, spec, q0, dt) -> float:
    """Peak |joint velocity| / limit along the whole-body IK of a phase from q0 (central differences)."""
    import pinocchio as pin

    q, out = q0, [q0]
    for ref in phase_references(spec, dt):
        q = ik.solve(q, ref)
        out.append(q)
    steps = np.array([pin.difference(talos.model, a, b) for a, b in zip(out[:-1], out[1:])]) / dt
    velocity = 0.5 * (steps[:-1] + steps[1:])
    return float((np.abs(velocity[:, 6:]) / talos.model.velocityLimit[6:]).max())


def test_a_high_landing_is_lengthened_for_its_knee_speed():
    """A landing over a 0.3 m apex on flat ground: over the 0.8 s landing the swing knee unbends
    faster than its 7 rad/s limit in the descent (circuit_0's landings 198 -> 199 and
    202 -> 203: -7.2 rad/s), while its CoM barely moves (no lengthening for the acceleration);
    lengthened, the IK's joints keep within their limits."""
    talos, config = load_talos(), MotionConfig()
    plan = straight_plan(0.3)
    k = 1  # one foot (the left) in the air, then both down
    assert np.isnan(plan.feet[k, 0, 0]) and not np.isnan(plan.feet[k + 1]).any()
    feet_a, com_a, rot_a = posture_frames(talos, plan.q[k])
    feet_b, _, rot_b = posture_frames(talos, plan.q[k + 1])
    landed = feet_a.copy()
    landed[0] = feet_b[0]
    samples = round(config.land_duration / config.dt)
    spec = _PhaseSpec(
        "land", (k, k + 1), 0, samples, feet_a, landed, com_a, com_a, rot_a, rot_b, plan.q[k], plan.q[k],
        feet_b[0][2, 3] + 0.3,
    )  # fmt: skip
    ik = WholeBodyIK(talos, config.ik_iterations, config.ik_damping, config.ik_tolerance)
    _, coms, _, _ = _single_support_coms(talos, spec, k, config)
    assert _peak_speed_ratio(talos, ik, dataclasses.replace(spec, coms=coms[1:]), plan.q[k], config.dt) > 1.0
    lengthened, coms = _single_support(talos, spec, k, config)
    assert lengthened.samples > samples
    _, _, configurations, _ = _single_support_coms(talos, lengthened, k, config)
    limits = talos.model.velocityLimit[6:]
    assert (np.abs(np.diff(configurations[:, 7:], axis=0)) / config.dt / limits).max() <= SPEED_MARGIN + 1e-9
    assert (
        _peak_speed_ratio(talos, ik, dataclasses.replace(lengthened, coms=coms[1:]), plan.q[k], config.dt)
        < 1.0
    )
