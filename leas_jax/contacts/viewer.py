"""Views of a contact plan: a self-contained 3D HTML page and a top-down PNG (host-only).

`write_html(plan, path)` writes one HTML file that needs no network: the data
(terrain mesh, guide, footprints, decimated Talos meshes, its kinematic tree and
the configurations of the shown key postures) is inlined as base64 typed
arrays, and a small WebGL2 renderer, the package's `viewer.js`, inlined too,
draws it (drag: orbit, right-drag or shift-drag: pan, wheel: zoom, slider,
play and speed: postures). `write_motion_html` writes the same page for
motions: time series of configurations played together (e.g. a planned motion
as a translucent ghost and its simulated rollout).

`write_footsteps_png(plan, path)` draws the terrain heightmap from above with
the guide, the footprints coloured by foot and the failed guide tail in red.

Both read a plan through the attributes of docs/design.md §6: `q [K, 39]`,
`feet [K, 2, 7]` (xyz + quaternion xyzw of the sole frames, NaN rows for a
foot in the air), `guide_index [K]`, `last_valid_index`, `coverage`,
`terrain` (file text, or a `Terrain`) and `guide [T, 4]`.
"""

from __future__ import annotations

import base64
import functools
import html
import io
import json
import re
from importlib import resources
from types import SimpleNamespace

import numpy as np

from leas_jax.contacts.robot.model import matrix_from_quat_xyzw

# Sole rectangle of Talos, centred on the sole frame (docs/design.md §6 check 1).
SOLE_LENGTH = 0.20  # m, along the sole frame x
SOLE_WIDTH = 0.13  # m, along the sole frame y
# Left foot blue, right foot orange in both views (matplotlib tab10).
FOOT_COLORS = ((0.12, 0.47, 0.71), (1.0, 0.50, 0.05))
FOOT_NAMES = ("left", "right")
# Vertex-clustering cell for the Talos meshes: 1.2 cm keeps the silhouette and
# brings the ~100k triangles of example-robot-data's meshes to ~50k, 0.56 MB
# inline (each file once; mirrored right limbs reuse the left meshes).
DEFAULT_MESH_CELL = 0.012  # m
# Postures whose configurations are stored in a plan's page: the slider and the
# "all" overlay use these; beyond ~60 the overlay is unreadable anyway.
DEFAULT_MAX_POSTURES = 60
# Playing a plan's page shows one stored posture every PLAN_FRAME_PERIOD seconds (at 1x).
PLAN_FRAME_PERIOD = 0.4  # s
# Frames per second stored in a motion's page (`write_motion_html`): smooth playback,
# a configuration (39 float32, 208 bytes in base64) per frame and track.
DEFAULT_FRAME_RATE = 25.0  # Hz


def _terrain_of(plan):
    """The plan's terrain as a `Terrain` (plans store the file text)."""
    from leas_jax.terrain import loads_terrain

    terrain = plan.terrain
    if isinstance(terrain, str):
        return loads_terrain(terrain, source="<plan terrain>")
    return terrain


quaternion_xyzw_to_matrix = matrix_from_quat_xyzw  # one conversion, in contacts.model


def footprints(plan) -> list[tuple[int, int, np.ndarray]]:
    """Distinct foot placements of the plan, in order of first appearance.

    A foot keeps its placement over many postures; each placement is listed
    once (placements equal within 1 mm / 1e-6 in the quaternion are merged).

    Returns:
        list of (foot, first posture index, corners [4, 3] world frame): the
        sole rectangle (SOLE_LENGTH x SOLE_WIDTH) in the sole frame's xy plane,
        foot 0 = left, 1 = right.
    """
    feet = np.asarray(plan.feet, dtype=np.float64)
    half = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]]) * [SOLE_LENGTH / 2, SOLE_WIDTH / 2]
    local = np.concatenate([half, np.zeros((4, 1))], axis=1)  # [4, 3] sole frame
    out, last = [], [None, None]
    for k in range(feet.shape[0]):
        for foot in (0, 1):
            row = feet[k, foot]
            if not np.isfinite(row).all():
                last[foot] = None
                continue
            if (
                last[foot] is not None
                and np.allclose(row[:3], last[foot][:3], atol=1e-3)
                and np.allclose(row[3:], last[foot][3:], atol=1e-6)
            ):
                continue
            last[foot] = row
            rotation = quaternion_xyzw_to_matrix(row[3:])
            out.append((foot, k, row[:3] + local @ rotation.T))
    return out


def count_footsteps(plan) -> int:
    """Number of steps: placements of a foot after the initial stance (liftoff then landing)."""
    feet = np.asarray(plan.feet)
    if feet.shape[0] == 0:
        return 0
    initial = sum(1 for foot in (0, 1) if np.isfinite(feet[0, foot]).all())
    return max(0, len(footprints(plan)) - initial)


# ----------------------------------------------------------------------------- PNG


def write_footsteps_png(plan, path, dpi: int = 120) -> None:
    """Top-down plot: terrain heightmap, guide, footprints by foot, failed guide tail in red.

    Host-only (matplotlib, Agg canvas; does not touch pyplot's global state).

    Args:
        plan: a ContactPlan (docs/design.md §6 attributes).
        path: output .png file.
        dpi: resolution of the figure.
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Polygon

    from leas_jax.plotting import agg_figure, draw_heightmap

    terrain = _terrain_of(plan)
    (xmin, ymin), (xmax, ymax) = terrain.bounds
    width = 8.0
    height = max(3.0, min(12.0, width * (ymax - ymin) / (xmax - xmin)))
    fig = agg_figure(width + 1.5, height, dpi=dpi)
    ax = fig.add_subplot(1, 1, 1)
    image = draw_heightmap(ax, terrain, "footsteps")
    fig.colorbar(image, ax=ax, label="terrain height (m); dark blue: hole", fraction=0.04)
    for foot, _, corners in footprints(plan):
        color = FOOT_COLORS[foot]
        ax.add_patch(Polygon(corners[:, :2], closed=True, facecolor=(*color, 0.55), edgecolor=color, lw=0.8))
    guide = np.asarray(plan.guide, dtype=np.float64)
    last = int(plan.last_valid_index)
    ok_end = max(0, min(last, guide.shape[0] - 1))
    if last >= 0:
        ax.plot(guide[: ok_end + 1, 0], guide[: ok_end + 1, 1], color="limegreen", lw=1.5)
    if last < guide.shape[0] - 1:
        tail = guide[ok_end:] if last >= 0 else guide
        ax.plot(tail[:, 0], tail[:, 1], color="red", lw=1.5)
    ax.plot(guide[0, 0], guide[0, 1], "o", color="limegreen", ms=5)
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(
        f"{terrain.name}: coverage {float(plan.coverage):.3f}, last valid index {last}, "
        f"{count_footsteps(plan)} footsteps",
        fontsize=10,
    )
    ax.legend(
        handles=[
            Line2D([], [], color="limegreen", label="guide (covered)"),
            Line2D([], [], color="red", label="guide (failed tail)"),
            Line2D([], [], color=FOOT_COLORS[0], lw=6, label="left foot"),
            Line2D([], [], color=FOOT_COLORS[1], lw=6, label="right foot"),
        ],
        loc="upper right",
        fontsize=8,
        framealpha=0.8,
    )
    from leas_jax.files import atomic_write_bytes

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi, bbox_inches="tight")
    atomic_write_bytes(path, buffer.getvalue())


# ----------------------------------------------------------------------------- HTML


def decimate(vertices: np.ndarray, faces: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Simplify a triangle mesh by vertex clustering on a grid of `cell` metres.

    Vertices in one grid cell merge into their mean; triangles that collapse
    (two corners in one cell) or repeat are dropped. Crude but robust, fast
    and dependency-free; good enough for a viewer.

    Args:
        vertices: [V, 3]; faces: [F, 3] vertex indices; cell: m.

    Returns:
        (vertices [V', 3] float32, faces [F', 3] int64).
    """
    keys = np.floor(np.asarray(vertices) / cell).astype(np.int64)
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    merged = np.zeros((counts.size, 3))
    np.add.at(merged, inverse, vertices)
    merged /= counts[:, None]
    tri = inverse[np.asarray(faces)]
    keep = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    tri = tri[keep]
    _, first = np.unique(np.sort(tri, axis=1), axis=0, return_index=True)
    tri = tri[np.sort(first)]
    used = np.unique(tri)
    remap = np.full(counts.size, -1, dtype=np.int64)
    remap[used] = np.arange(used.size)
    return merged[used].astype(np.float32), remap[tri]


@functools.lru_cache(maxsize=4)
def _talos_visuals(cell: float):
    """Talos model, visual model and decimated meshes (cached per process).

    Returns:
        (model, visual_model, meshes, geom_mesh, geom_scale, geom_color):
        meshes is a list of (vertices [V, 3] float32, faces [F, 3]) in the
        mesh file frame, unscaled; geom_mesh[g] the mesh index of visual
        geometry g (or -1 if it has no drawable shape), geom_scale[g] [3] its
        meshScale (applied in the placement matrix, so the mirrored right
        limbs reuse the left meshes), geom_color[g] [3] RGB.
    """
    import coal
    import example_robot_data
    import trimesh

    robot = example_robot_data.load("talos")
    meshes, index_of, geom_mesh, geom_scale, geom_color = [], {}, [], [], []
    for geom in robot.visual_model.geometryObjects:
        shape = geom.geometry
        key, mesh = None, None
        if geom.meshPath.lower().endswith((".stl", ".dae", ".obj", ".ply")):
            key = geom.meshPath
            if key not in index_of:
                mesh = trimesh.load(geom.meshPath, force="mesh")
        elif isinstance(shape, coal.Cylinder):
            key = ("cylinder", shape.radius, shape.halfLength)
            if key not in index_of:
                mesh = trimesh.creation.cylinder(
                    radius=shape.radius, height=2 * shape.halfLength, sections=16
                )
        elif isinstance(shape, coal.Box):
            key = ("box", *np.asarray(shape.halfSide).tolist())
            if key not in index_of:
                mesh = trimesh.creation.box(extents=2 * np.asarray(shape.halfSide))
        if key is None:
            geom_mesh.append(-1)
        else:
            if mesh is not None:
                vertices, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
                if len(faces) > 200:  # primitives and tiny meshes stay exact
                    vertices, faces = decimate(vertices, faces, cell)
                index_of[key] = len(meshes)
                meshes.append((np.asarray(vertices, dtype=np.float32), np.asarray(faces)))
            geom_mesh.append(index_of[key])
        geom_scale.append(np.asarray(geom.meshScale, dtype=np.float64))
        color = np.asarray(geom.meshColor, dtype=np.float64)[:3]
        # URDF meshes without material come out black or white: use a light grey.
        geom_color.append(color if 0.05 < color.mean() < 0.95 else np.array([0.72, 0.72, 0.75]))
    return robot.model, robot.visual_model, meshes, geom_mesh, geom_scale, geom_color


def _select_postures(count: int, maximum: int) -> np.ndarray:
    """Up to `maximum` posture indices spread evenly over [0, count), first and last included."""
    if count <= maximum:
        return np.arange(count)
    return np.unique(np.round(np.linspace(0, count - 1, maximum)).astype(int))


def robot_placements(q: np.ndarray, cell: float = DEFAULT_MESH_CELL):
    """World placements of the Talos visual geometries for each configuration.

    Host-only (Pinocchio forward kinematics + `updateGeometryPlacements`). The
    pages compute the same placements themselves (viewer.js, from
    `robot_model_payload`); this is their reference.

    Args:
        q: [N, 39] Pinocchio configurations (free-flyer xyz + quaternion xyzw, joints).

    Returns:
        (matrices [N, G, 3, 4] float32: oMg with the mesh scale folded in,
        drawn geometry indices [G] into the visual model).
    """
    import pinocchio as pin

    model, visual_model, _, geom_mesh, geom_scale, _ = _talos_visuals(cell)
    data, visual_data = model.createData(), pin.GeometryData(visual_model)
    drawn = [g for g, m in enumerate(geom_mesh) if m >= 0]
    out = np.zeros((len(q), len(drawn), 3, 4), dtype=np.float32)
    for n, config in enumerate(np.asarray(q, dtype=np.float64)):
        pin.forwardKinematics(model, data, config)
        pin.updateGeometryPlacements(model, data, visual_model, visual_data)
        for slot, g in enumerate(drawn):
            placement = visual_data.oMg[g]
            out[n, slot, :, :3] = placement.rotation * geom_scale[g][None, :]
            out[n, slot, :, 3] = placement.translation
    return out, np.array(drawn)


def _b64(array: np.ndarray, dtype) -> str:
    """Base64 text of the array's bytes in `dtype` (C order)."""
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode("ascii")


def robot_model_payload(cell: float = DEFAULT_MESH_CELL) -> dict:
    """Talos's kinematic tree and drawn geometries for the page's forward kinematics.

    The page places the meshes itself from configurations q (39 floats a frame
    instead of 12 per geometry): joint j's world placement is
    parent's placement * joint placement * joint motion (the free flyer's
    translation and quaternion xyzw, or a rotation about x, y or z by q[q_index]),
    and geometry g's is its joint's placement * its own (mesh scale folded in).

    Returns:
        dict: parent [J] (joint 0 is the universe), kind [J] ("universe",
        "free", "rx", "ry", "rz"), q_index [J], nq, joint_placements f32
        [J*12] (row-major 3x4, base64), geom_joint [G], geom_placements f32
        [G*12]; G counts the drawn geometries (those of `robot_placements`).
    """
    model, visual_model, _, geom_mesh, geom_scale, _ = _talos_visuals(cell)
    kinds = []
    for j, joint in enumerate(model.joints):
        name = joint.shortname()
        if j == 0:
            kinds.append("universe")
        elif name == "JointModelFreeFlyer":
            kinds.append("free")
        elif name in ("JointModelRX", "JointModelRY", "JointModelRZ"):
            kinds.append("r" + name[-1].lower())
        else:  # the page knows only these; Talos has no other kind
            raise ValueError(f"joint {model.names[j]}: {name} is not drawn by the viewer")
    joints = np.zeros((model.njoints, 3, 4))
    for j in range(model.njoints):
        placement = model.jointPlacements[j]
        joints[j] = np.c_[placement.rotation, placement.translation]
    drawn = [g for g, m in enumerate(geom_mesh) if m >= 0]
    geoms = np.zeros((len(drawn), 3, 4))
    for slot, g in enumerate(drawn):
        placement = visual_model.geometryObjects[g].placement
        geoms[slot] = np.c_[placement.rotation * geom_scale[g][None, :], placement.translation]
    return {
        "parent": [int(p) for p in model.parents],
        "kind": kinds,
        "q_index": [int(i) for i in model.idx_qs],
        "nq": int(model.nq),
        "joint_placements": _b64(joints, "<f4"),
        "geom_joint": [int(visual_model.geometryObjects[g].parentJoint) for g in drawn],
        "geom_placements": _b64(geoms, "<f4"),
    }


def _robot_payload(tracks, times, mesh_cell: float) -> tuple[list, dict]:
    """Meshes and the robot entry of a page: model, geometries and the tracks' configurations.

    Args:
        tracks: list of (name, q [F_k, 39], color): color None draws the robot in
            its own colours, an RGBA tuple draws it translucent in that colour.
        times: [F] s, the frames' times (F the longest track; shorter tracks
            hold their last configuration).
    """
    _, _, meshes, geom_mesh, _, geom_color = _talos_visuals(mesh_cell)
    drawn = [g for g, m in enumerate(geom_mesh) if m >= 0]
    mesh_entries = []
    for vertices, faces in meshes:
        small = vertices.shape[0] < 65536  # 16-bit indices halve the largest arrays
        mesh_entries.append(
            {
                "positions": _b64(vertices, "<f4"),
                "indices": _b64(faces, "<u2" if small else "<u4"),
                "index_type": "u16" if small else "u32",
            }
        )
    entry = {
        "model": robot_model_payload(mesh_cell),
        "geoms": [{"mesh": int(geom_mesh[g]), "color": [float(c) for c in geom_color[g]]} for g in drawn],
        "tracks": [
            {
                "name": name,
                "style": "solid" if color is None else "ghost",
                "color": None if color is None else [float(c) for c in color],
                "q": _b64(np.asarray(q, dtype=np.float64), "<f4"),
            }
            for name, q, color in tracks
        ],
        "times": _b64(np.asarray(times, dtype=np.float64), "<f4"),
        "overlay": False,
    }
    return mesh_entries, entry


def _scene_payload(terrain, name: str, subtitle: str, guide, last_valid_index: int, feet) -> dict:
    """The page's data without a robot: terrain mesh, guide, footprints.

    `terrain.heights` is the range of the heights of the terrain's upward faces
    (normal z > 0.5; either way up for a mesh wound inwards): the page colours
    the terrain by height over it.
    """
    from leas_jax.terrain.export import terrain_to_mesh

    mesh = terrain_to_mesh(terrain)
    vertices, faces = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces)
    heights = [0.0, 1.0]
    if len(faces):
        triangles = vertices[faces]
        normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
        length = np.linalg.norm(normals, axis=1)
        cosine = np.divide(normals[:, 2], length, out=np.zeros(len(faces)), where=length > 0)
        up = cosine > 0.5
        if not up.any():  # a mesh wound inwards: its tops face down
            up = np.abs(cosine) > 0.5
        z = triangles[up][..., 2] if up.any() else triangles[..., 2]
        heights = [float(z.min()), float(max(z.max(), z.min() + 0.05))]
    feet_by_foot = {0: [], 1: []}
    for foot, _, corners in footprints(SimpleNamespace(feet=feet)):
        feet_by_foot[foot].append(corners)
    guide = np.asarray(guide, dtype=np.float64)
    return {
        "name": name,
        "subtitle": subtitle,
        "last_valid_index": int(last_valid_index),
        "bounds": np.asarray(terrain.bounds, dtype=float).tolist(),
        "terrain": {
            "positions": _b64(vertices, "<f4"),
            "indices": _b64(faces, "<u4"),
            "heights": heights,
        },
        "guide": _b64(guide[:, :3], "<f4"),
        "footprints": {
            FOOT_NAMES[f]: _b64(np.reshape(c, (-1, 3)) if c else np.zeros((0, 3)), "<f4")
            for f, c in feet_by_foot.items()
        },
        "foot_colors": [list(c) for c in FOOT_COLORS],
        "meshes": [],
        "robot": None,
    }


def html_payload(
    plan,
    *,
    max_postures: int = DEFAULT_MAX_POSTURES,
    mesh_cell: float = DEFAULT_MESH_CELL,
    robot: bool = True,
) -> dict:
    """The data inlined in a plan's page, as a JSON-ready dict (typed arrays in base64, little-endian).

    Keys: name, subtitle (coverage, last valid index, postures), coverage,
    last_valid_index, n_postures, bounds, terrain {positions f32 [V*3],
    indices u32, heights [2]}, guide f32 [T*3], footprints {left, right: f32
    [n*4*3] corners}, foot_colors, meshes [{positions f32, indices u16|u32,
    index_type}], robot (None without one) {model (`robot_model_payload`),
    geoms [{mesh, color}], tracks [{name, style, color, q f32 [P*39]}],
    times f32 [P] (s: one stored posture every `PLAN_FRAME_PERIOD` when
    played), overlay (all postures can be drawn at once), postures [P] (plan
    indices), guide_index [P]}.
    """
    terrain = _terrain_of(plan)
    q = np.asarray(plan.q, dtype=np.float64)
    chosen = _select_postures(q.shape[0], max_postures)
    subtitle = (
        f"coverage {float(plan.coverage):.3f}, last valid index {int(plan.last_valid_index)}, "
        f"{q.shape[0]} postures" + (f" ({len(chosen)} stored)" if robot and q.shape[0] else "")
    )
    payload = _scene_payload(terrain, terrain.name, subtitle, plan.guide, plan.last_valid_index, plan.feet)
    payload.update(coverage=float(plan.coverage), n_postures=int(q.shape[0]))
    if robot and q.shape[0] > 0:
        meshes, entry = _robot_payload(
            [("robot", q[chosen], None)], np.arange(len(chosen)) * PLAN_FRAME_PERIOD, mesh_cell
        )
        entry.update(
            overlay=True,
            postures=chosen.tolist(),
            guide_index=np.asarray(plan.guide_index)[chosen].astype(int).tolist(),
        )
        payload.update(meshes=meshes, robot=entry)
    return payload


def motion_payload(
    terrain,
    feet,
    tracks,
    dt: float,
    *,
    rate: float = DEFAULT_FRAME_RATE,
    line=None,
    subtitle: str = "",
    mesh_cell: float = DEFAULT_MESH_CELL,
) -> dict:
    """The data of a page that animates motions (time series of configurations) over a terrain.

    Args:
        terrain: file text or `Terrain`.
        feet: [K, 2, 7] sole placements whose footprints are drawn (`footprints`).
        tracks: list of (name, q [N_k, 39] sampled every `dt`, color): color None
            draws the robot in its own colours, an RGBA tuple translucent in
            that colour (a ghost). All start at time 0; the shorter ones hold
            their last configuration.
        dt: sampling period of the tracks, s.
        rate: frames stored per second (the tracks are subsampled to it; the
            last sample of each is kept).
        line: [T, >=3] points drawn as the green line (e.g. the root's path), or None.
        subtitle: text after the terrain name.

    Returns:
        the `html_payload` keys; robot.times are the frames' times (s), no
        postures or guide_index, overlay False.
    """
    terrain = _terrain_of(SimpleNamespace(terrain=terrain))
    stride = max(1, int(round(1.0 / (rate * dt))))
    longest = max(len(q) for _, q, _ in tracks)
    frames = np.arange(0, longest, stride)
    if frames[-1] != longest - 1:
        frames = np.append(frames, longest - 1)
    sampled = []
    for name, q, color in tracks:
        q = np.asarray(q, dtype=np.float64)
        own = frames[frames < len(q)]
        if own[-1] != len(q) - 1:  # a track that ends between frames shows its end next
            own = np.append(own, len(q) - 1)
        sampled.append((name, q[own], color))
    line = np.zeros((0, 3)) if line is None else np.asarray(line, dtype=np.float64)
    payload = _scene_payload(terrain, terrain.name, subtitle, line, len(line) - 1, feet)
    payload["meshes"], payload["robot"] = _robot_payload(sampled, frames * dt, mesh_cell)
    return payload


def _page(payload: dict, title: str) -> str:
    """The HTML page: template, escaped title, the payload's JSON and the inlined renderer."""
    parts = {"TITLE": html.escape(title), "DATA": script_json(payload), "SCRIPT": viewer_script()}
    # one pass: a placeholder's name inside the data or the script is left as it is
    return re.sub(r"__(TITLE|DATA|SCRIPT)__", lambda match: parts[match.group(1)], _PAGE)


@functools.lru_cache(maxsize=1)
def viewer_script() -> str:
    """The renderer's JavaScript (the package's viewer.js), checked to be safe to inline.

    Raises:
        ValueError: the file holds "</script" or "<!--", which would end or break
            the page's <script> element.
    """
    text = resources.files("leas_jax.contacts").joinpath("viewer.js").read_text(encoding="utf-8")
    if re.search(r"</script|<!--", text, re.IGNORECASE):
        raise ValueError("viewer.js holds </script or <!--: it cannot be inlined")
    return text


def write_html(
    plan,
    path,
    *,
    max_postures: int = DEFAULT_MAX_POSTURES,
    mesh_cell: float = DEFAULT_MESH_CELL,
    robot: bool = True,
) -> None:
    """Write a self-contained 3D view of the plan (no network, no CDN).

    Shows the terrain (coloured by height), the guide (green up to
    `last_valid_index`, red after), the footprints (sole rectangles, blue left
    / orange right) and Talos at up to `max_postures` key postures (slider,
    play, or all at once). A few MB at most: the meshes are decimated and
    stored once, each posture adds only its configuration (39 floats).
    Host-only (Pinocchio, trimesh).

    Args:
        plan: a ContactPlan (docs/design.md §6 attributes).
        path: output .html file.
        max_postures: key postures whose robot is stored (evenly spread).
        mesh_cell: vertex-clustering cell of the mesh decimation, m.
        robot: False to omit the robot (faster, much smaller).
    """
    from leas_jax.files import atomic_write_text

    payload = html_payload(plan, max_postures=max_postures, mesh_cell=mesh_cell, robot=robot)
    atomic_write_text(path, _page(payload, f"LeaS contact plan: {payload['name']}"))


def write_motion_html(
    path, terrain, feet, tracks, dt: float, *, title: str = "LeaS motion", **options
) -> None:
    """Write a self-contained page that animates motions over a terrain (play, pause, time slider, speed).

    Arguments as `motion_payload` (`options`: rate, line, subtitle, mesh_cell);
    `title` is the page's title. 208 bytes per stored frame and track (25
    frames/s by default) over the 0.56 MB of meshes: 0.91 MB for the planned and
    simulated robots over 26 s.
    """
    from leas_jax.files import atomic_write_text

    payload = motion_payload(terrain, feet, tracks, dt, **options)
    atomic_write_text(path, _page(payload, f"{title}: {payload['name']}"))


# Characters of JSON text escaped inside the page's <script>: with no "<", ">" or "&" left, no
# string can close the element ("</script>") or open a comment ("<!--"); U+2028 and U+2029 end
# lines in older JavaScript parsers.
_SCRIPT_ESCAPES = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026", "\u2028": "\\u2028", "\u2029": "\\u2029"}


def script_json(payload) -> str:
    """JSON text of `payload` safe to embed in an HTML <script> element (JSON.parse gives `payload` back)."""
    text = json.dumps(payload, separators=(",", ":"))
    for char, escape in _SCRIPT_ESCAPES.items():
        text = text.replace(char, escape)
    return text


# The page: panel and canvas; the data (__DATA__) and the renderer (__SCRIPT__, viewer.js) are inlined.
_PAGE = r"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>__TITLE__</title>
<style>
  html, body { margin: 0; height: 100%; overflow: hidden; background: #20242a; font: 13px sans-serif; color: #ddd; }
  #view { width: 100%; height: 100%; display: block; }
  #panel { position: absolute; top: 8px; left: 8px; background: rgba(20, 22, 26, 0.85); padding: 8px 10px;
           border-radius: 4px; max-width: 440px; }
  #panel input[type=range] { width: 260px; vertical-align: middle; }
  .left { color: rgb(31, 120, 181); } .right { color: rgb(255, 127, 14); }
  .ok { color: #4c4; } .bad { color: #e44; }
</style>
</head>
<body>
<canvas id="view"></canvas>
<div id="panel">
  <div id="info"></div>
  <div id="robot-controls">
    <input id="posture" type="range" min="0" max="0" value="0"> <span id="posture-label"></span><br>
    <button id="play">play</button>
    speed <select id="speed"><option value="0.25">0.25x</option><option value="0.5">0.5x</option>
      <option value="1" selected>1x</option><option value="2">2x</option><option value="4">4x</option></select>
    <label><input id="show-robot" type="checkbox" checked> robot</label>
    <label id="show-all-label"><input id="show-all" type="checkbox"> all stored postures</label>
    <span id="tracks"></span>
  </div>
  <div>feet: <span class="left">&#9632; left</span> <span class="right">&#9632; right</span>;
    path: <span class="ok">covered</span> / <span class="bad">failed</span>; terrain coloured by height</div>
  <div style="color:#999">drag: orbit &middot; right/shift-drag: pan &middot; wheel: zoom</div>
  <div id="error" class="bad"></div>
</div>
<script id="plan-data" type="application/json">__DATA__</script>
<script>
__SCRIPT__</script>
</body>
</html>
"""
