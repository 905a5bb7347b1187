"""Views of a contact plan: a self-contained 3D HTML page and a top-down PNG (host-only).

`write_html(plan, path)` writes one HTML file that needs no network: the data
(terrain boxes, guide, footprints, decimated Talos meshes and their placements
at the shown key postures) is inlined as base64 typed arrays, and a small
WebGL2 renderer written here draws it (drag: orbit, right-drag or shift-drag:
pan, wheel: zoom, slider: posture).

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

import numpy as np

from leas_jax.contacts.robot.model import matrix_from_quat_xyzw

# Sole rectangle of Talos, centred on the sole frame (docs/design.md §6 check 1).
SOLE_LENGTH = 0.20  # m, along the sole frame x
SOLE_WIDTH = 0.13  # m, along the sole frame y
# Left foot blue, right foot orange in both views (matplotlib tab10).
FOOT_COLORS = ((0.12, 0.47, 0.71), (1.0, 0.50, 0.05))
FOOT_NAMES = ("left", "right")
# Vertex-clustering cell for the Talos meshes: 1.2 cm keeps the silhouette and
# brings the ~100k triangles of example-robot-data's meshes to ~50k, about
# 1 MB inline (each file once; mirrored right limbs reuse the left meshes).
DEFAULT_MESH_CELL = 0.012  # m
# Postures whose robot placements are stored in the HTML: the slider and the
# "all" overlay use these; beyond ~60 the overlay is unreadable anyway.
DEFAULT_MAX_POSTURES = 60


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

    Host-only (Pinocchio forward kinematics + `updateGeometryPlacements`).

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
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode("ascii")


def html_payload(
    plan,
    *,
    max_postures: int = DEFAULT_MAX_POSTURES,
    mesh_cell: float = DEFAULT_MESH_CELL,
    robot: bool = True,
) -> dict:
    """The data inlined in the HTML page, as a JSON-ready dict (typed arrays in base64, little-endian).

    Keys: name, coverage, last_valid_index, bounds, terrain {positions f32
    [V*3], indices u32}, guide f32 [T*3], footprints {left, right: f32 [n*4*3]
    corners}, meshes [{positions f32, indices u16|u32, index_type}],
    robot {geoms [{mesh, color}], postures [P] (plan indices), guide_index
    [P], matrices f32 [P*G*12] row-major 3x4}.
    """
    from leas_jax.terrain.export import terrain_to_mesh

    terrain = _terrain_of(plan)
    mesh = terrain_to_mesh(terrain)
    guide = np.asarray(plan.guide, dtype=np.float64)
    feet_by_foot = {0: [], 1: []}
    for foot, _, corners in footprints(plan):
        feet_by_foot[foot].append(corners)
    payload = {
        "name": terrain.name,
        "coverage": float(plan.coverage),
        "last_valid_index": int(plan.last_valid_index),
        "n_postures": int(np.asarray(plan.q).shape[0]),
        "bounds": np.asarray(terrain.bounds, dtype=float).tolist(),
        "terrain": {"positions": _b64(mesh.vertices, "<f4"), "indices": _b64(mesh.faces, "<u4")},
        "guide": _b64(guide[:, :3], "<f4"),
        "footprints": {
            FOOT_NAMES[f]: _b64(np.reshape(c, (-1, 3)) if c else np.zeros((0, 3)), "<f4")
            for f, c in feet_by_foot.items()
        },
        "foot_colors": [list(c) for c in FOOT_COLORS],
        "meshes": [],
        "robot": None,
    }
    q = np.asarray(plan.q, dtype=np.float64)
    if robot and q.shape[0] > 0:
        _, _, meshes, geom_mesh, _, geom_color = _talos_visuals(mesh_cell)
        chosen = _select_postures(q.shape[0], max_postures)
        matrices, drawn = robot_placements(q[chosen], mesh_cell)
        for vertices, faces in meshes:
            small = vertices.shape[0] < 65536  # 16-bit indices halve the largest arrays
            payload["meshes"].append(
                {
                    "positions": _b64(vertices, "<f4"),
                    "indices": _b64(faces, "<u2" if small else "<u4"),
                    "index_type": "u16" if small else "u32",
                }
            )
        payload["robot"] = {
            "geoms": [{"mesh": int(geom_mesh[g]), "color": [float(c) for c in geom_color[g]]} for g in drawn],
            "postures": chosen.tolist(),
            "guide_index": np.asarray(plan.guide_index)[chosen].astype(int).tolist(),
            "matrices": _b64(matrices, "<f4"),
        }
    return payload


def write_html(
    plan,
    path,
    *,
    max_postures: int = DEFAULT_MAX_POSTURES,
    mesh_cell: float = DEFAULT_MESH_CELL,
    robot: bool = True,
) -> None:
    """Write a self-contained 3D view of the plan (no network, no CDN).

    Shows the terrain boxes, the guide (green up to `last_valid_index`, red
    after), the footprints (sole rectangles, blue left / orange right) and the
    Talos meshes at up to `max_postures` key postures (slider, or all at once).
    A few MB at most: the meshes are decimated and stored once, each posture
    adds only 3x4 matrices. Host-only (Pinocchio, trimesh).

    Args:
        plan: a ContactPlan (docs/design.md §6 attributes).
        path: output .html file.
        max_postures: key postures whose robot is stored (evenly spread).
        mesh_cell: vertex-clustering cell of the mesh decimation, m.
        robot: False to omit the robot (faster, much smaller).
    """
    from leas_jax.files import atomic_write_text

    payload = html_payload(plan, max_postures=max_postures, mesh_cell=mesh_cell, robot=robot)
    title = html.escape(f"LeaS contact plan: {payload['name']}")
    page = _PAGE.replace("__TITLE__", title).replace("__DATA__", script_json(payload))
    atomic_write_text(path, page)


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


_PAGE = r"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>__TITLE__</title>
<style>
  html, body { margin: 0; height: 100%; overflow: hidden; background: #20242a; font: 13px sans-serif; color: #ddd; }
  #view { width: 100%; height: 100%; display: block; }
  #panel { position: absolute; top: 8px; left: 8px; background: rgba(20, 22, 26, 0.85); padding: 8px 10px;
           border-radius: 4px; max-width: 420px; }
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
    posture <input id="posture" type="range" min="0" max="0" value="0"> <span id="posture-label"></span><br>
    <label><input id="show-all" type="checkbox"> all stored postures</label>
    <label><input id="show-robot" type="checkbox" checked> robot</label>
    <button id="play">play</button>
  </div>
  <div>feet: <span class="left">&#9632; left</span> <span class="right">&#9632; right</span>;
    guide: <span class="ok">covered</span> / <span class="bad">failed</span></div>
  <div style="color:#999">drag: orbit &middot; right/shift-drag: pan &middot; wheel: zoom</div>
  <div id="error" class="bad"></div>
</div>
<script id="plan-data" type="application/json">__DATA__</script>
<script>
"use strict";
const DATA = JSON.parse(document.getElementById("plan-data").textContent);

function decode(b64, Type) {
  const bin = atob(b64), bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return new Type(bytes.buffer);
}

// ---- 4x4 column-major matrices (WebGL layout)
function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
  return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0]);
}
function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
function normalize(a) { const n = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / n, a[1] / n, a[2] / n]; }
function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
function lookAt(eye, target, up) {
  const z = normalize(sub(eye, target)), x = normalize(cross(up, z)), y = cross(z, x);
  return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
                           -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
}
// Row-major 3x4 [R | p] from Python to column-major 4x4.
function fromRows34(m, o) {
  return new Float32Array([m[o], m[o + 4], m[o + 8], 0, m[o + 1], m[o + 5], m[o + 9], 0,
                           m[o + 2], m[o + 6], m[o + 10], 0, m[o + 3], m[o + 7], m[o + 11], 1]);
}
const IDENTITY = new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);

const canvas = document.getElementById("view");
const gl = canvas.getContext("webgl2", {antialias: true});
if (!gl) {
  document.getElementById("error").textContent = "WebGL2 is not available in this browser.";
  throw new Error("no WebGL2");
}

// Normals come from screen-space derivatives of the world position: meshes
// need no normal arrays (smaller file) and are shaded flat per triangle.
const VS = `#version 300 es
in vec3 aPos;
uniform mat4 uProj, uView, uModel;
out vec3 vWorld;
void main() {
  vec4 w = uModel * vec4(aPos, 1.0);
  vWorld = w.xyz;
  gl_Position = uProj * uView * w;
}`;
const FS = `#version 300 es
precision highp float;
in vec3 vWorld;
uniform vec4 uColor;
uniform int uMode;  // 0: shaded, 1: flat colour (lines), 2: shaded terrain with a 0.5 m grid
out vec4 outColor;
void main() {
  if (uMode == 1) { outColor = uColor; return; }
  vec3 n = normalize(cross(dFdx(vWorld), dFdy(vWorld)));
  float light = 0.35 + 0.5 * abs(dot(n, normalize(vec3(0.4, 0.3, 1.0)))) + 0.15 * abs(n.x);
  vec3 c = uColor.rgb * light;
  if (uMode == 2) {
    vec2 g = abs(fract(vWorld.xy * 2.0 + 0.5) - 0.5) / fwidth(vWorld.xy * 2.0);
    float line = 1.0 - min(min(g.x, g.y), 1.0);
    c = mix(c, c * 0.6, line * abs(n.z));
  }
  outColor = vec4(c, uColor.a);
}`;
function compile(type, src) {
  const s = gl.createShader(type);
  gl.shaderSource(s, src);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}
const prog = gl.createProgram();
gl.attachShader(prog, compile(gl.VERTEX_SHADER, VS));
gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, FS));
gl.linkProgram(prog);
if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
gl.useProgram(prog);
const loc = {};
for (const name of ["uProj", "uView", "uModel", "uColor", "uMode"]) loc[name] = gl.getUniformLocation(prog, name);
const aPos = gl.getAttribLocation(prog, "aPos");

function makeDrawable(positions, indices, indexType) {
  const vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  const vbo = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, vbo);
  gl.bufferData(gl.ARRAY_BUFFER, positions, gl.STATIC_DRAW);
  gl.enableVertexAttribArray(aPos);
  gl.vertexAttribPointer(aPos, 3, gl.FLOAT, false, 0, 0);
  let count = positions.length / 3, type = null;
  if (indices) {
    const ibo = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibo);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
    count = indices.length;
    type = indexType === "u16" ? gl.UNSIGNED_SHORT : gl.UNSIGNED_INT;
  }
  gl.bindVertexArray(null);
  return {vao, count, type};
}
function draw(d, mode, primitive, color, model) {
  if (d.count === 0) return;
  gl.uniformMatrix4fv(loc.uModel, false, model || IDENTITY);
  gl.uniform4fv(loc.uColor, color);
  gl.uniform1i(loc.uMode, mode);
  gl.bindVertexArray(d.vao);
  if (d.type !== null) gl.drawElements(primitive, d.count, d.type, 0);
  else gl.drawArrays(primitive, 0, d.count);
}

// ---- scene
const terrain = makeDrawable(decode(DATA.terrain.positions, Float32Array), decode(DATA.terrain.indices, Uint32Array), "u32");
const guideAll = decode(DATA.guide, Float32Array);
const nGuide = guideAll.length / 3, lastValid = DATA.last_valid_index;
const okEnd = Math.max(0, Math.min(lastValid, nGuide - 1));
const guideOk = makeDrawable(lastValid >= 0 ? guideAll.slice(0, 3 * (okEnd + 1)) : new Float32Array(0));
const guideBad = makeDrawable(lastValid < nGuide - 1 ? guideAll.slice(lastValid >= 0 ? 3 * okEnd : 0) : new Float32Array(0));
// Footprints: each rectangle (4 corners) as 2 triangles and a closed outline,
// lifted 3 mm to stay above the support surface.
function footDrawables(b64) {
  const c = decode(b64, Float32Array), n = c.length / 12;
  const tri = new Float32Array(n * 18), lines = new Float32Array(n * 24);
  for (let r = 0; r < n; r++) {
    const v = i => [c[12 * r + 3 * i], c[12 * r + 3 * i + 1], c[12 * r + 3 * i + 2] + 0.003];
    [0, 1, 2, 0, 2, 3].forEach((i, k) => tri.set(v(i), 18 * r + 3 * k));
    [0, 1, 1, 2, 2, 3, 3, 0].forEach((i, k) => lines.set(v(i), 24 * r + 3 * k));
  }
  return {fill: makeDrawable(tri), outline: makeDrawable(lines)};
}
const feet = [footDrawables(DATA.footprints.left), footDrawables(DATA.footprints.right)];
const meshes = DATA.meshes.map(m => makeDrawable(decode(m.positions, Float32Array),
    decode(m.indices, m.index_type === "u16" ? Uint16Array : Uint32Array), m.index_type));
const robot = DATA.robot;
let robotMatrices = [];
if (robot) {
  const flat = decode(robot.matrices, Float32Array), G = robot.geoms.length;
  for (let p = 0; p < robot.postures.length; p++) {
    const perPosture = [];
    for (let g = 0; g < G; g++) perPosture.push(fromRows34(flat, 12 * (p * G + g)));
    robotMatrices.push(perPosture);
  }
}

// ---- UI
const slider = document.getElementById("posture"), label = document.getElementById("posture-label");
const showAll = document.getElementById("show-all"), showRobot = document.getElementById("show-robot");
// data goes into the page as text nodes only (textContent), never parsed as HTML
const info = document.getElementById("info"), nameNode = document.createElement("b");
nameNode.textContent = String(DATA.name);
info.appendChild(nameNode);
info.appendChild(document.createTextNode(
  `: coverage ${Number(DATA.coverage).toFixed(3)}, last valid index ${Number(DATA.last_valid_index)}, ` +
  `${Number(DATA.n_postures)} postures` + (robot ? ` (${robot.postures.length} stored)` : "")));
if (robot) slider.max = robot.postures.length - 1;
else document.getElementById("robot-controls").style.display = "none";
function updateLabel() {
  if (!robot) return;
  const p = +slider.value;
  label.textContent = `#${robot.postures[p]} (guide index ${robot.guide_index[p]})`;
}
let playing = null;
document.getElementById("play").onclick = () => {
  if (playing) { clearInterval(playing); playing = null; return; }
  playing = setInterval(() => { slider.value = (+slider.value + 1) % (+slider.max + 1); updateLabel(); render(); }, 300);
};
slider.oninput = () => { updateLabel(); render(); };
showAll.onchange = showRobot.onchange = render;
updateLabel();

// ---- orbit camera (z up) around the centre of the terrain bounds
const b = DATA.bounds;
const cam = {
  target: [(b[0][0] + b[1][0]) / 2, (b[0][1] + b[1][1]) / 2, 0],
  dist: 1.2 * Math.hypot(b[1][0] - b[0][0], b[1][1] - b[0][1]),
  az: -Math.PI / 2 - 0.5, el: 0.6,
};
function eye() {
  return [cam.target[0] + cam.dist * Math.cos(cam.el) * Math.cos(cam.az),
          cam.target[1] + cam.dist * Math.cos(cam.el) * Math.sin(cam.az),
          cam.target[2] + cam.dist * Math.sin(cam.el)];
}
let drag = null;
canvas.addEventListener("contextmenu", e => e.preventDefault());
canvas.addEventListener("mousedown", e => { drag = {x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey}; });
window.addEventListener("mouseup", () => { drag = null; });
window.addEventListener("mousemove", e => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX; drag.y = e.clientY;
  if (drag.pan) {
    const s = cam.dist * 0.0015, ca = Math.cos(cam.az), sa = Math.sin(cam.az);
    // Grab-the-ground panning: screen right is (-sin az, cos az), the view
    // direction on the ground is -(cos az, sin az).
    cam.target[0] += s * (dx * sa - dy * ca);
    cam.target[1] += s * (-dx * ca - dy * sa);
  } else {
    cam.az -= dx * 0.005;
    cam.el = Math.max(-1.5, Math.min(1.5, cam.el + dy * 0.005));
  }
  render();
});
canvas.addEventListener("wheel", e => {
  e.preventDefault();
  cam.dist = Math.max(0.2, cam.dist * Math.exp(e.deltaY * 0.001));
  render();
}, {passive: false});

function render() {
  const w = canvas.clientWidth, h = canvas.clientHeight, dpr = window.devicePixelRatio || 1;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr); canvas.height = Math.round(h * dpr);
  }
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.clearColor(0.13, 0.14, 0.16, 1);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.enable(gl.DEPTH_TEST);
  gl.uniformMatrix4fv(loc.uProj, false, perspective(0.8, canvas.width / Math.max(1, canvas.height), 0.02, 500));
  gl.uniformMatrix4fv(loc.uView, false, lookAt(eye(), cam.target, [0, 0, 1]));
  draw(terrain, 2, gl.TRIANGLES, [0.62, 0.58, 0.50, 1]);
  draw(guideOk, 1, gl.LINE_STRIP, [0.3, 0.85, 0.3, 1]);
  draw(guideBad, 1, gl.LINE_STRIP, [0.95, 0.2, 0.2, 1]);
  feet.forEach((f, i) => {
    const c = DATA.foot_colors[i];
    draw(f.fill, 0, gl.TRIANGLES, [c[0], c[1], c[2], 1]);
    draw(f.outline, 1, gl.LINES, [0.05, 0.05, 0.05, 1]);
  });
  if (robot && showRobot.checked) {
    const shown = showAll.checked ? robotMatrices.map((_, p) => p) : [+slider.value];
    for (const p of shown) {
      robot.geoms.forEach((g, i) => draw(meshes[g.mesh], 0, gl.TRIANGLES, [g.color[0], g.color[1], g.color[2], 1], robotMatrices[p][i]));
    }
  }
  document.body.dataset.rendered = String((+document.body.dataset.rendered || 0) + 1);
}
window.addEventListener("resize", render);
render();
</script>
</body>
</html>
"""
