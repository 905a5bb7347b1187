"""Batched replay of motions in MJX: `simulate`'s controller written in JAX, vmapped over motions.

`replay(motions, seconds)` runs B motions of one terrain at once: each starts at its
first configuration and, at every physics step (1 kHz), applies

    ctrl = clip(tau_ff(t) + kp (q_ref(t) - q) + kd (v_ref(t) - v), -effort, effort),

with q_ref, v_ref, tau_ff interpolated linearly between the motion's 100 Hz samples and the
gains of `simulate.pd_gains`, as `simulate.simulate` does on CPU MuJoCo (the default and the
judge: falls, landings, slip, torque and other terrain contacts are measured there). The
model is `simulate`'s (`robot.scene_model` of `robot.physics_terrain_mjcf`, the same friction
solver) with one difference: only the sole boxes collide with the
terrain, as MJX has no collisions for the links' cylinders and meshes; a motion that
`simulate` passes touches the terrain with its soles alone, so the physics is the same but
for the noslip solver, which `simulate` runs by default (`SimulationConfig.noslip_iterations`)
and the replay does not (MuJoCo's default, 0). JAX's default float32 runs the steps (CPU
MuJoCo: float64).

Host code builds the model and the padded input arrays; the rollout (`rollout_one`, vmapped
by `replay`) is jitted JAX. Motions of different lengths are padded with their last sample,
which is what `simulate` replays after a motion's end (its `settle`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from leas_jax.motion.config import SimulationConfig


@dataclass(frozen=True)
class ReplayInputs:
    """Padded per-motion arrays of a batch (host, NumPy).

    Attributes:
        qpos0: [B, nq] MuJoCo initial positions (each motion's first configuration).
        q_ref: [B, N, 32] joint position references, rad, Pinocchio joint order.
        v_ref: [B, N, 32] joint velocity references, rad/s.
        tau: [B, N, 32] feed-forward torques, N m.
        samples: [B] each motion's own number of samples (N is the largest).
        dt: s between samples.
    """

    qpos0: np.ndarray
    q_ref: np.ndarray
    v_ref: np.ndarray
    tau: np.ndarray
    samples: np.ndarray
    dt: float


@dataclass(frozen=True)
class MjxReplay:
    """Result of `replay`.

    Attributes:
        time: [S] s, the recorded instants (every motion sample, 100 Hz, from 0).
        root: [B, S, 3] base_link position, world, m, at those instants (before the step).
        qpos: [B, nq] MuJoCo positions after the last step.
        seconds: wall-clock time of the rollout (compilation included), s.
    """

    time: np.ndarray
    root: np.ndarray
    qpos: np.ndarray
    seconds: float


def mjx_scene(terrain, config: SimulationConfig = SimulationConfig()):
    """(MujocoTalos, mjx.Model) of Talos in `terrain`, only its sole boxes colliding."""
    from mujoco import mjx

    from leas_jax.motion.robot import physics_terrain_mjcf, scene_model, set_friction_solver

    mj = scene_model(physics_terrain_mjcf(terrain, config.mesh_contact), config.timestep)
    set_friction_solver(mj.model, config.cone, config.impratio)
    soles = set(mj.sole_geoms)
    for geom in mj.robot_geoms:
        if geom not in soles:
            mj.model.geom_contype[geom] = 0
            mj.model.geom_conaffinity[geom] = 0
    return mj, mjx.put_model(mj.model)


def replay_inputs(motions, mj) -> ReplayInputs:
    """Stack motions [B] into padded arrays (`ReplayInputs`) for a scene `mj` (`mjx_scene`).

    Raises:
        ValueError: the motions have different sampling periods.
    """
    dts = {float(m.dt) for m in motions}
    if len(dts) != 1:
        raise ValueError(f"motions sampled at different periods: {sorted(dts)}")
    length = max(len(m.q) for m in motions)

    def pad(samples: np.ndarray) -> np.ndarray:
        return np.concatenate([samples, np.repeat(samples[-1:], length - len(samples), axis=0)])

    return ReplayInputs(
        qpos0=np.stack([mj.qpos_from_pin(m.q[0]) for m in motions]),
        q_ref=np.stack([pad(m.q[:, 7:]) for m in motions]),
        v_ref=np.stack([pad(m.v[:, 6:]) for m in motions]),
        tau=np.stack([pad(m.tau) for m in motions]),
        samples=np.array([len(m.q) for m in motions]),
        dt=dts.pop(),
    )


def interpolate(samples, position):
    """Linear interpolation of samples [N, D] at a fractional index position (clipped to [0, N - 1]) -> [D]."""
    import jax.numpy as jnp

    position = jnp.clip(position, 0.0, samples.shape[0] - 1)
    low = jnp.floor(position).astype(jnp.int32)
    high = jnp.minimum(low + 1, samples.shape[0] - 1)
    frac = position - low
    return (1.0 - frac) * samples[low] + frac * samples[high]


def control(q, v, q_ref, v_ref, tau_ff, kp, kd, effort):
    """Joint torques [32] (Pinocchio joint order) of the tracking controller, clipped to the effort limits.

    Args:
        q, v: [32] joint positions (rad) and velocities (rad/s); q_ref, v_ref, tau_ff: [32]
            references and feed-forward (N m); kp, kd, effort: [32] gains and limits.
    """
    import jax.numpy as jnp

    return jnp.clip(tau_ff + kp * (q_ref - q) + kd * (v_ref - v), -effort, effort)


def rollout_one(mx, indices, gains, qpos0, q_ref, v_ref, tau, samples: int, stride: int):
    """One motion's rollout in MJX (jittable, vmappable over qpos0, q_ref, v_ref, tau).

    Args:
        mx: mjx.Model; indices: (qpos [32], dof [32], actuator [32]) index arrays of the
            joints in Pinocchio order; gains: (kp, kd, effort) [32] each.
        qpos0: [nq]; q_ref, v_ref, tau: [N, 32] (`ReplayInputs` rows).
        samples: instants to record (S); stride: physics steps per motion sample.

    Returns:
        (root [S, 3] base_link position before each recorded instant's steps, final qpos [nq]).
    """
    import jax
    import jax.numpy as jnp
    from mujoco import mjx

    qpos_index, dof_index, actuator_index = indices
    kp, kd, effort = gains
    data = mjx.make_data(mx).replace(qpos=qpos0)
    data = mjx.forward(mx, data)

    def physics_step(data, position):
        command = control(
            data.qpos[qpos_index],
            data.qvel[dof_index],
            interpolate(q_ref, position),
            interpolate(v_ref, position),
            interpolate(tau, position),
            kp,
            kd,
            effort,
        )
        data = data.replace(ctrl=jnp.zeros(mx.nu, command.dtype).at[actuator_index].set(command))
        return mjx.step(mx, data), None

    def motion_sample(data, index):
        positions = index + jnp.arange(stride) / stride
        after, _ = jax.lax.scan(physics_step, data, positions)
        return after, data.qpos[:3]

    data, root = jax.lax.scan(motion_sample, data, jnp.arange(samples))
    return root, data.qpos


def replay(motions, seconds: float, terrain=None, config: SimulationConfig = SimulationConfig()) -> MjxReplay:
    """Replay motions [B] of one terrain for `seconds` in MJX, vmapped over the motions.

    Args:
        motions: `Motion`s on one terrain (their `terrain` text), same sampling period.
        seconds: simulated time, s (past a motion's end it holds its last sample).
        terrain: a `Terrain`, or None for the motions' own.
        config: physics step and gains (`SimulationConfig`).

    Returns:
        MjxReplay.

    Raises:
        ValueError: no motions, or motions of different terrains or periods.
    """
    import time as clock

    import jax
    import jax.numpy as jnp

    from leas_jax.contacts.robot.model import load_talos
    from leas_jax.motion.simulate import pd_gains
    from leas_jax.terrain import loads_terrain

    if not motions:
        raise ValueError("no motions to replay")
    if len({m.terrain for m in motions}) != 1:
        raise ValueError("the motions of one replay share a terrain")
    started = clock.perf_counter()
    terrain = terrain or loads_terrain(motions[0].terrain, source="<motion terrain>")
    mj, mx = mjx_scene(terrain, config)
    inputs = replay_inputs(motions, mj)
    kp, kd = pd_gains(mj, load_talos(), config)
    indices = tuple(jnp.asarray(a) for a in (mj.qpos_index, mj.dof_index, mj.actuator_index))
    gains = tuple(jnp.asarray(a, jnp.float32) for a in (kp, kd, mj.effort))
    samples = round(seconds / inputs.dt)
    stride = round(inputs.dt / config.timestep)

    @jax.jit
    def batch(mx, indices, gains, qpos0, q_ref, v_ref, tau):
        def one(*rows):
            return rollout_one(mx, indices, gains, *rows, samples=samples, stride=stride)

        return jax.vmap(one)(qpos0, q_ref, v_ref, tau)

    arrays = (inputs.qpos0, inputs.q_ref, inputs.v_ref, inputs.tau)
    root, qpos = batch(mx, indices, gains, *(jnp.asarray(a, jnp.float32) for a in arrays))
    root, qpos = np.asarray(root), np.asarray(qpos)
    return MjxReplay(
        time=np.arange(samples) * inputs.dt, root=root, qpos=qpos, seconds=clock.perf_counter() - started
    )
