"""Root kinematics of the guide path, paper eqs (1)-(3). Pure and jittable."""

import jax
import jax.numpy as jnp

from leas_jax.env.config import EnvConfig


def rotate_z(vec_xy: jax.Array, yaw: jax.Array) -> jax.Array:
    """Rotate horizontal vectors by `yaw` about z. vec_xy: [..., 2] -> [..., 2]."""
    c, s = jnp.cos(yaw), jnp.sin(yaw)
    x, y = vec_xy[..., 0], vec_xy[..., 1]
    return jnp.stack([c * x - s * y, s * x + c * y], axis=-1)


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
