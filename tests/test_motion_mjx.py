"""MJX batched replay (leas_jax.motion.mjx_replay): the controller's pieces, and agreement with CPU MuJoCo."""

import dataclasses

import numpy as np
import pytest
from motion_helpers import straight_plan

from leas_jax.motion.config import SimulationConfig
from leas_jax.motion.motion import make_motion

# Root position agreement between MJX (float32) and CPU MuJoCo (float64), m: measured 0.24 mm
# after 2 s of the flat-ground motion below (the root moves 8.6 cm in its first second).
ROOT_TOLERANCE = 0.002


def _prefix(motion, samples: int):
    """The motion's first `samples` samples (its per-sample arrays cut), phases left as they are."""
    cut = {
        k: getattr(motion, k)[:samples]
        for k in ("time", "q", "v", "a", "tau", "wrenches", "contact", "feet", "com")
    }
    return dataclasses.replace(motion, **cut)


def test_interpolate_and_control_match_the_cpu_controller():
    import jax.numpy as jnp

    from leas_jax.motion.mjx_replay import control, interpolate
    from leas_jax.motion.simulate import _interpolate

    samples = np.random.default_rng(0).normal(size=(5, 3))
    for position in (0.0, 1.25, 3.9, 4.0, 7.0):
        expected = _interpolate(samples, min(position, 4.0))
        np.testing.assert_allclose(interpolate(jnp.asarray(samples), position), expected, atol=1e-6)
    effort = jnp.array([10.0, 10.0, 10.0])
    tau = control(
        jnp.zeros(3), jnp.zeros(3), jnp.array([1.0, -1.0, 0.0]), jnp.array([0.0, 0.0, 2.0]), jnp.array([1.0, 0.0, 0.0]),
        jnp.array([100.0, 4.0, 0.0]), jnp.array([0.0, 0.0, 3.0]), effort,
    )  # fmt: skip
    np.testing.assert_allclose(tau, [10.0, -4.0, 6.0])  # clipped, PD, damping


def test_replay_inputs_pad_with_the_last_sample():
    from leas_jax.motion.mjx_replay import replay_inputs
    from leas_jax.motion.robot import scene_model
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.export import terrain_to_mjcf

    motion = make_motion(straight_plan(0.2))
    short = _prefix(motion, 50)
    mj = scene_model(terrain_to_mjcf(loads_terrain(motion.terrain)), 0.001)
    inputs = replay_inputs([motion, short], mj)
    assert inputs.q_ref.shape == (2, len(motion.q), 32) and list(inputs.samples) == [len(motion.q), 50]
    np.testing.assert_array_equal(
        inputs.q_ref[1, 49:], np.repeat(short.q[-1:, 7:], len(motion.q) - 49, axis=0)
    )
    np.testing.assert_array_equal(inputs.tau[0], motion.tau)
    with pytest.raises(ValueError, match="different periods"):
        replay_inputs([motion, dataclasses.replace(short, dt=0.02)], mj)


@pytest.mark.slow
def test_mjx_and_cpu_mujoco_agree_and_motions_are_batched():
    from leas_jax.motion.mjx_replay import replay
    from leas_jax.motion.simulate import simulate

    motion = make_motion(straight_plan(0.3))
    moved = motion.q.copy()
    moved[:, :2] += [0.5, -0.3]  # the same steps 0.58 m away on the same flat floor, cut at 1.5 s
    other = _prefix(dataclasses.replace(motion, q=moved), 150)
    mjx = replay([motion, other], seconds=2.0)
    cpu = simulate(motion, config=SimulationConfig(noslip_iterations=0))  # as the replay runs
    assert mjx.root.shape == (2, 200, 3) and np.isclose(mjx.time[-1], 1.99)
    for sample in (100, 199):  # 1 s (the CoM shifted over the stance foot), 1.99 s (in single support)
        np.testing.assert_allclose(mjx.root[0, sample], cpu.q[sample, :3], atol=ROOT_TOLERANCE)
    assert np.linalg.norm(cpu.q[100, :2] - cpu.q[0, :2]) > 0.05
    np.testing.assert_allclose(mjx.root[1, 100] - mjx.root[0, 100], [0.5, -0.3, 0.0], atol=1e-4)
    # past its end the cut motion holds its last sample while the whole one lifts a foot
    assert np.abs(mjx.qpos[0, 7:] - mjx.qpos[1, 7:]).max() > 0.1
