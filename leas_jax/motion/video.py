"""Offscreen renderings of a simulated motion: an animated GIF (Pillow) of Talos in MuJoCo.

Host-only. MuJoCo renders offscreen through an OpenGL backend chosen by the MUJOCO_GL
environment variable (egl, osmesa or glfw); `render_frames` tries EGL, then OSMesa, when
MUJOCO_GL is unset, and raises `VideoError` (one line) when none works, e.g. on a machine
without `libegl1` or `libosmesa6`.
"""

from __future__ import annotations

import os

import numpy as np

from leas_jax.errors import LeasError

# Backends tried in this order when MUJOCO_GL is unset.
GL_BACKENDS = ("egl", "osmesa")


class VideoError(LeasError):
    """No frame can be rendered (no OpenGL backend) or the file type is not supported."""


# One frame of a one-sphere model: exit 0 when the backend in MUJOCO_GL renders.
_PROBE = (
    "import mujoco; m = mujoco.MjModel.from_xml_string("
    '\'<mujoco><worldbody><geom type="sphere" size=".1"/></worldbody></mujoco>\'); '
    "r = mujoco.Renderer(m, 8, 8); r.update_scene(mujoco.MjData(m)); r.render(); r.close()"
)


def ensure_gl() -> str:
    """The OpenGL backend MuJoCo renders with: MUJOCO_GL when set, else the first of
    GL_BACKENDS that renders a frame.

    Each backend is tried in a child process: MuJoCo picks its backend when first imported,
    and a backend that cannot open a context may abort the process (GLFW without a display).

    Raises:
        VideoError: no backend renders.
    """
    import subprocess
    import sys

    chosen = os.environ.get("MUJOCO_GL")
    for backend in (chosen,) if chosen else GL_BACKENDS:
        try:
            done = subprocess.run(
                [sys.executable, "-c", _PROBE],
                env=dict(os.environ, MUJOCO_GL=backend),
                capture_output=True,
                timeout=120,
            )
        except (OSError, subprocess.TimeoutExpired):
            continue
        if done.returncode == 0:
            return backend
    raise VideoError(
        "no OpenGL backend renders offscreen (MUJOCO_GL=egl needs libegl1, osmesa needs libosmesa6: "
        "apt-get install -y libegl1 libosmesa6)"
    )


def frame_indices(samples: int, dt: float, speed: float, fps: float, window=None) -> np.ndarray:
    """Indices [F] of the recorded samples shown in the video.

    Args:
        samples: recorded samples (`Rollout.q` rows), one every `dt` s.
        speed: motion seconds per video second.
        fps: video frames per second.
        window: (start, end) s of the motion shown, None: all of it.
    """
    start, end = (0.0, (samples - 1) * dt) if window is None else window
    end = min(end, (samples - 1) * dt)
    times = np.arange(start, end + 1e-9, speed / fps)
    return np.unique(np.clip(np.round(times / dt).astype(int), 0, samples - 1))


def render_frames(
    motion,
    q: np.ndarray,
    size: tuple[int, int] = (320, 240),
    distance: float = 3.5,
    azimuth: float = 60.0,
    elevation: float = -12.0,
) -> list[np.ndarray]:
    """RGB frames [H, W, 3] uint8 of Talos at configurations q [F, 39] (Pinocchio order, world)
    in the motion's terrain, the camera following the root (`distance` m away, `azimuth` and
    `elevation` in deg, MuJoCo's free camera).

    Rendered in a child process whose MUJOCO_GL is `ensure_gl`'s backend (this process may
    have imported MuJoCo with another one).

    Raises:
        VideoError: no OpenGL backend.
    """
    import concurrent.futures
    import multiprocessing

    backend = ensure_gl()
    previous = os.environ.get("MUJOCO_GL")
    os.environ["MUJOCO_GL"] = backend  # inherited by the spawned child
    try:
        context = multiprocessing.get_context("spawn")
        with concurrent.futures.ProcessPoolExecutor(1, context) as pool:
            return pool.submit(
                _render_here, motion.terrain, np.asarray(q), size, distance, azimuth, elevation
            ).result()
    finally:
        if previous is None:
            os.environ.pop("MUJOCO_GL", None)
        else:
            os.environ["MUJOCO_GL"] = previous


def _render_here(terrain_text: str, q: np.ndarray, size, distance: float, azimuth: float, elevation: float):
    """`render_frames` in this process (MuJoCo's backend already chosen)."""
    import mujoco

    from leas_jax.motion.robot import scene_model
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.export import terrain_to_mjcf

    terrain = loads_terrain(terrain_text, source="<motion terrain>")
    mj = scene_model(terrain_to_mjcf(terrain), 0.001)
    model = mj.model
    width, height = size
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
    model.vis.global_.offheight = max(model.vis.global_.offheight, height)
    data = mujoco.MjData(model)
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.distance, camera.azimuth, camera.elevation = distance, azimuth, elevation
    renderer = mujoco.Renderer(model, height, width)
    frames = []
    lookat = np.asarray(q[0, :3], dtype=np.float64).copy()
    try:
        for configuration in q:
            data.qpos[:] = mj.qpos_from_pin(configuration)
            mujoco.mj_forward(model, data)
            # the camera glides after the root (a fifth of the way per frame): no jitter
            lookat += 0.2 * (configuration[:3] - lookat) if frames else 0.0
            camera.lookat[:] = lookat - np.array([0.0, 0.0, 0.25])
            renderer.update_scene(data, camera)
            frames.append(renderer.render().copy())
    finally:
        renderer.close()
    return frames


def write_gif(frames: list[np.ndarray], path, fps: float, colors: int = 64) -> int:
    """Write frames [H, W, 3] uint8 as a looping GIF (one shared adaptive palette of `colors`);
    returns the file's size in bytes."""
    from PIL import Image

    images = [Image.fromarray(f) for f in frames]
    palette = images[len(images) // 2].quantize(colors=colors, method=Image.Quantize.MEDIANCUT)
    quantized = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in images]
    quantized[0].save(
        path,
        save_all=True,
        append_images=quantized[1:],
        duration=round(1000.0 / fps),
        loop=0,
        optimize=True,
    )
    return os.path.getsize(path)


def write_video(
    motion, rollout, path, speed: float = 10.0, fps: float = 10.0, size=(320, 240), window=None
) -> int:
    """Render a rollout's recorded postures and write them to `path` (.gif); returns its size, bytes.

    Args:
        motion: the simulated `Motion` (terrain, dt).
        rollout: `simulate`'s `Rollout` (q [M, 39], one row per motion sample).
        speed: motion seconds per video second; fps: frames per second; size: (width, height) px.
        window: (start, end) s of the motion shown, None: all.

    Raises:
        VideoError: not a .gif path, or no OpenGL backend.
    """
    suffix = os.path.splitext(str(path))[1].lower()
    if suffix != ".gif":
        raise VideoError(
            f"{path}: only .gif is written (Pillow); .mp4 would need ffmpeg, which this installation lacks"
        )
    chosen = frame_indices(len(rollout.q), motion.dt, speed, fps, window)
    frames = render_frames(motion, rollout.q[chosen], size)
    return write_gif(frames, path, fps)
