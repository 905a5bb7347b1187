"""Root kinematics of the guide path, paper eqs (1)-(3). Pure and jittable."""

import jax
import jax.numpy as jnp

from leas_jax.env.config import EnvConfig


def rotate_z(vec_xy: jax.Array, yaw: jax.Array) -> jax.Array:
    """Rotate horizontal vectors by `yaw` about z. vec_xy: [..., 2] -> [..., 2]."""
    c, s = jnp.cos(yaw), jnp.sin(yaw)
    x, y = vec_xy[..., 0], vec_xy[..., 1]
    return jnp.stack([c * x - s * y, s * x + c * y], axis=-1)


def world_xy(pose: jax.Array, offsets: jax.Array) -> tuple[jax.Array, jax.Array]:
    """World x and y of points given in the root frame, as two arrays.

    Args:
        pose: [4] (x, y, z, yaw), world.
        offsets: [N, 2] root-frame (x, y) offsets (m).

    Returns:
        (x [N], y [N]), world (m).

    The same points as `pose[:2] + rotate_z(offsets, pose[3])`, kept apart: vmapped over a
    batch of poses, XLA:CPU keeps a stacked [B, N, 2] array with the pair innermost, and the
    samplers' arithmetic on it ran about 10 times slower than on two [B, N] arrays (the
    learned condition's 238-point patch: 4.0 -> 0.4 us per pose on 2 cores;
    docs/results/2026-12-02-column-sampling).
    """
    c, s = jnp.cos(pose[3]), jnp.sin(pose[3])
    ox, oy = offsets[:, 0], offsets[:, 1]
    return pose[0] + (c * ox - s * oy), pose[1] + (s * ox + c * oy)


def wrap_angle(angle: jax.Array) -> jax.Array:
    """Wrap angles to [-pi, pi)."""
    return (angle + jnp.pi) % (2.0 * jnp.pi) - jnp.pi


def scale_action(action: jax.Array, yaw: jax.Array, config: EnvConfig):
    """Physical acceleration (world frame) and yaw rate of a normalised action.

    Args:
        action: [4] (a_x, a_y, a_z, omega), each clipped to [-1, 1].
        yaw: [] root yaw (rad); used when actions are in the root frame.
        config: a_max (x, y), vertical_a_max (z; None: a_max), omega_max, action frame.

    Returns:
        accel: [3] m/s^2, world frame.
        omega: [] rad/s.
    """
    action = jnp.clip(action, -1.0, 1.0)
    vertical = config.a_max if config.vertical_a_max is None else config.vertical_a_max
    accel = action[:3] * jnp.array([config.a_max, config.a_max, vertical])
    if config.actions_in_root_frame:
        accel = jnp.concatenate([rotate_z(accel[:2], yaw), accel[2:]])
    return accel, action[3] * config.omega_max


def integrate(
    pos: jax.Array, vel: jax.Array, yaw: jax.Array, accel: jax.Array, omega: jax.Array, config: EnvConfig
):
    """One step of the paper's update, eqs (1)-(3).

    pos_i = pos_{i-1} + vel_{i-1} dt                   (1)
    vel_i = vel_{i-1} + a dt, with |vel_i| <= v_max    (2)
    yaw_i = yaw_{i-1} + omega dt                        (3)

    Args:
        pos: [3] world position of base_link (m).
        vel: [3] world velocity (m/s).
        yaw: [] heading (rad).
        accel: [3] world acceleration (m/s^2).
        omega: [] yaw rate (rad/s).
        config: timestep and v_max.

    Returns:
        (pos, vel, yaw) after one timestep; yaw wrapped to [-pi, pi).
    """
    dt = config.timestep
    new_pos = pos + vel * dt
    new_vel = vel + accel * dt
    speed = jnp.linalg.norm(new_vel)
    new_vel = new_vel * jnp.minimum(1.0, config.v_max / jnp.maximum(speed, 1e-12))
    return new_pos, new_vel, wrap_angle(yaw + omega * dt)
