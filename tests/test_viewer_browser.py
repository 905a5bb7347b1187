"""The HTML viewer drawn by a real browser: headless Chromium (software WebGL2, SwiftShader)
renders pages at fixed cameras and the test reads the screenshot's pixels.

Skipped when no Chromium binary is found (install: `apt-get install chromium`)."""

from __future__ import annotations

import shutil
import subprocess
from types import SimpleNamespace

import numpy as np
import pytest

from leas_jax.contacts import viewer

CHROMIUM = next(
    (path for name in ("chromium", "chromium-browser", "google-chrome") if (path := shutil.which(name))), None
)
pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="no chromium binary on PATH (apt-get install chromium)"
)

WIDTH, HEIGHT = 640, 480
FOVY = 0.8  # rad, the page's vertical field of view

# Two boxes with coplanar faces: the ground x in [-1, 1] and a step x in [0, 1] rising to 0.4 m,
# both y in [-1, 1] and down to z = -0.6: their y = -1 sides overlap on x in [0, 1], z in [-0.6, 0].
COPLANAR = """
name = "coplanar"
bounds = [[-1.0, -1.0], [1.0, 1.0]]
void_height = -2.0
resolution = 0.02

[[box]]
center = [0.0, 0.0, -0.3]
size = [2.0, 2.0, 0.6]

[[box]]
center = [0.5, 0.0, -0.1]
size = [1.0, 2.0, 1.0]
"""


def screenshot(page, tmp_path, cam, name="shot", frame=None):
    """RGB [HEIGHT, WIDTH, 3] uint8 of `page` drawn with the panel hidden at camera
    cam = (azimuth, elevation, distance, target x, y, z) and, if given, the robot's `frame`."""
    from PIL import Image

    out = tmp_path / f"{name}.png"
    fragment = (
        "panel=0&cam=" + ",".join(f"{v:.6g}" for v in cam) + ("" if frame is None else f"&frame={frame}")
    )
    done = subprocess.run(
        [
            CHROMIUM,
            "--headless=new",
            "--no-sandbox",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--force-device-scale-factor=1",
            "--hide-scrollbars",
            f"--window-size={WIDTH},{HEIGHT}",
            "--virtual-time-budget=5000",
            f"--screenshot={out}",
            f"file://{page}#{fragment}",
        ],
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert out.exists(), f"chromium wrote no screenshot (exit {done.returncode}): {done.stderr[-2000:]}"
    return np.asarray(Image.open(out).convert("RGB"))


def project(points, cam):
    """Pixel (column, row) of world points seen by the page's camera (its lookAt and perspective)."""
    az, el, dist, *target = cam
    target = np.asarray(target, dtype=float)
    eye = target + dist * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    z = (eye - target) / np.linalg.norm(eye - target)
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    rel = np.asarray(points, dtype=float) - eye
    cx, cy, cz = rel @ x, rel @ y, rel @ z  # camera frame, looking along -z
    f = 1.0 / np.tan(FOVY / 2)
    ndc_x, ndc_y = f * cx / (WIDTH / HEIGHT) / -cz, f * cy / -cz
    return np.stack([(ndc_x + 1) / 2 * WIDTH, (1 - ndc_y) / 2 * HEIGHT], axis=-1)


def patch(image, pixel, half=3):
    """Pixels of the (2 half + 1)^2 square round `pixel`, [n, 3] float."""
    col, row = np.round(pixel).astype(int)
    assert half <= col < WIDTH - half and half <= row < HEIGHT - half, f"{pixel} off the image"
    return image[row - half : row + half + 1, col - half : col + half + 1].reshape(-1, 3).astype(float)


def box_plan(terrain_text):
    """A plan without postures: the page shows the terrain only."""
    return SimpleNamespace(
        q=np.zeros((0, 39)),
        feet=np.zeros((0, 2, 7)),
        guide_index=np.zeros(0, int),
        last_valid_index=-1,
        coverage=0.0,
        terrain=terrain_text,
        guide=np.zeros((1, 4)),
    )


def test_walls_of_overlapping_boxes_are_flat_colour(tmp_path):
    """Looking at the y = -1 side, where the two boxes' faces coincide: one even colour, no speckle."""
    page = tmp_path / "coplanar.html"
    viewer.write_html(box_plan(COPLANAR), page)
    cam = (-np.pi / 2 + 0.3, 0.25, 4.0, 0.0, 0.0, -0.1)
    image = screenshot(page, tmp_path, cam)
    # Grid of points inside the overlap x in [0.1, 0.9], z in [-0.5, -0.1], on y = -1.
    xs, zs = np.meshgrid(np.linspace(0.15, 0.85, 6), np.linspace(-0.45, -0.15, 4))
    points = np.stack([xs.ravel(), np.full(xs.size, -1.0), zs.ravel()], axis=1)
    pixels = np.concatenate([patch(image, p, half=4) for p in project(points, cam)])
    background = np.array([33, 36, 41])  # clear colour (0.13, 0.14, 0.16)
    assert np.abs(pixels.mean(axis=0) - background).max() > 30, "the wall is not drawn"
    assert pixels.std(axis=0).max() < 2.0, "uneven wall: speckle"
    assert np.abs(pixels - np.median(pixels, axis=0)).max() < 8, "stray pixels on the wall"
    # The same wall where only the ground box has it (x < 0) has the same colour: same height, same light.
    other = np.concatenate([patch(image, p) for p in project([[-0.5, -1.0, -0.3]], cam)])
    assert np.abs(other.mean(axis=0) - pixels.mean(axis=0)).max() < 3


def _interior_points(terrain, height, step=0.1, margin=0.3):
    """Grid points whose terrain height, and that of every point within `margin`, is `height` (+-5 mm)."""
    (xmin, ymin), (xmax, ymax) = terrain.bounds
    xs, ys = np.meshgrid(np.arange(xmin, xmax, step), np.arange(ymin, ymax, step))
    grid = np.stack([xs.ravel(), ys.ravel()], axis=1)
    on = np.ones(len(grid), bool)
    for dx in (-margin, 0.0, margin):
        for dy in (-margin, 0.0, margin):
            on &= np.abs(terrain.height_at(grid + [dx, dy]) - height) < 0.005
    return np.c_[grid[on], np.full(on.sum(), height)]


def test_a_mesh_scene_shows_its_platform_apart_from_the_floor(tmp_path):
    """The HPP stairs mesh from above: its 0.6 m platform and the floor are drawn, in other colours."""
    from pathlib import Path

    from leas_jax.terrain import load_terrain

    path = Path(__file__).resolve().parents[1] / "terrains" / "hpp" / "demos" / "talos_stairs10.toml"
    terrain = load_terrain(path)
    page = tmp_path / "stairs.html"
    viewer.write_html(box_plan(path.read_text()), page)
    (xmin, ymin), (xmax, ymax) = terrain.bounds
    cam = (-np.pi / 2, 1.45, 8.0, (xmin + xmax) / 2, (ymin + ymax) / 2, 0.0)
    image = screenshot(page, tmp_path, cam)
    platform, floor = _interior_points(terrain, 0.6), _interior_points(terrain, 0.0)
    assert len(platform) >= 3 and len(floor) >= 3
    # every third point: a few spread over each surface
    top = np.array([patch(image, p).mean(axis=0) for p in project(platform[::3], cam)])
    ground = np.array([patch(image, p).mean(axis=0) for p in project(floor[::3], cam)])
    background = np.array([33, 36, 41])
    colours = []
    for surface in (top, ground):
        assert (np.abs(surface - background).max(axis=1) > 30).all(), "a surface is not drawn"
        colour = np.median(surface, axis=0)
        # one level surface, one colour: but for grid lines and railing posts in front of a few points
        assert (np.abs(surface - colour).max(axis=1) < 12).mean() > 0.8
        colours.append(colour)
    assert np.abs(colours[0] - colours[1]).max() > 40, "platform and floor look alike"


GROUND = """
name = "ground"
bounds = [[-1.5, -1.5], [1.5, 1.5]]
void_height = -2.0
resolution = 0.02

[[box]]
center = [0.0, 0.0, -0.1]
size = [3.0, 3.0, 0.2]
"""


def test_a_motion_page_draws_the_ghost_and_the_simulated_robot_where_they_stand(tmp_path):
    """Planned Talos (ghost) at y = -0.4, simulated at y = +0.4, seen from -x: translucent blue where
    the ghost's torso is, the robot's own grey where the simulated one's is, at the frame the URL asks."""
    import example_robot_data

    talos = example_robot_data.load("talos")
    base = talos.model.referenceConfigurations["half_sitting"].copy()  # not a view into the model
    planned, simulated = np.tile(base, (3, 1)), np.tile(base, (3, 1))
    planned[:, 1], simulated[:, 1] = -0.4, 0.4
    planned[2, 1], simulated[2, 1] = -1.3, 1.3  # both step 0.9 m aside at the last frame
    page = tmp_path / "motion.html"
    tracks = [("planned", planned, (0.35, 0.6, 1.0, 0.35)), ("simulated", simulated, None)]
    viewer.write_motion_html(page, GROUND, np.full((1, 2, 7), np.nan), tracks, 0.04)
    reference = tmp_path / "ground.html"
    viewer.write_html(box_plan(GROUND), reference)
    cam = (np.pi, 0.15, 3.5, 0.0, 0.0, 0.9)
    empty = screenshot(reference, tmp_path, cam, "empty")
    torso = np.array([[0.0, -0.4, base[2] + 0.15], [0.0, 0.4, base[2] + 0.15]])
    for frame, present in ((0, True), (2, False)):
        image = screenshot(page, tmp_path, cam, f"frame{frame}", frame=frame)
        ghost, solid = (patch(image, p, half=2).mean(axis=0) for p in project(torso, cam))
        ghost_empty, solid_empty = (patch(empty, p, half=2).mean(axis=0) for p in project(torso, cam))
        if not present:  # both robots stepped aside: the scene behind shows again
            assert np.abs(ghost - ghost_empty).max() < 10 and np.abs(solid - solid_empty).max() < 10
            continue
        assert np.abs(solid - solid_empty).max() > 40, "the simulated robot is not drawn"
        assert abs(solid[2] - solid[0]) < 20, "the simulated robot is tinted"
        assert np.abs(ghost - ghost_empty).max() > 20, "the ghost is not drawn"
        assert ghost[2] - ghost[0] > 25, "the ghost is not translucent blue"
