"""Terrain exports: MuJoCo MJCF scene and triangle meshes (trimesh).

Host code; not jittable. Files are written atomically (a temporary file in the target's
folder, then renamed): a failed export leaves no partial file.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from leas_jax.errors import TerrainError
from leas_jax.terrain.model import Terrain

MESH_EXTENSIONS = (".glb", ".obj", ".stl")
EXPORT_EXTENSIONS = (".xml",) + MESH_EXTENSIONS


def _fmt(values) -> str:
    """Space-separated numbers with enough digits to round-trip float64."""
    return " ".join(repr(float(v)) for v in values)


def terrain_to_mjcf(terrain: Terrain) -> str:
    """MuJoCo scene of a terrain: one `<geom type="box">` per box, one mesh geom per mesh.

    Geoms are named box0, box1, ... in box order; `size` holds the half extents and
    `quat` the orientation in MuJoCo's (w, x, y, z) order. Meshes (`Terrain.meshes`) are
    assets mesh0, mesh1, ... with their world-frame vertices and faces inline, so the
    scene needs no other file; MuJoCo ray casts them triangle by triangle (its
    collisions use their convex hulls). `inertia="shell"` lets open meshes compile.

    Args:
        terrain: the terrain.

    Returns:
        MJCF XML text, loadable with `mujoco.MjModel.from_xml_string`.
    """
    (xmin, ymin), (xmax, ymax) = terrain.bounds
    extent = float(max(xmax - xmin, ymax - ymin))
    lines = [
        f"<mujoco model={quoteattr(terrain.name)}>",
        # Large terrains: keep the free camera's clipping planes around the whole scene.
        f'  <statistic center="{_fmt([(xmin + xmax) / 2, (ymin + ymax) / 2, 0.0])}" extent="{extent!r}"/>',
        "  <visual>",
        '    <map znear="0.001" zfar="1000"/>',
        "  </visual>",
        # mjx.ray (mujoco-mjx 3.17) indexes mat_rgba by geom_matid and fails on a model
        # without materials: every geom gets one.
        "  <asset>",
        '    <material name="terrain" rgba="0.62 0.60 0.55 1"/>',
        *_mesh_assets(terrain),
        "  </asset>",
        "  <default>",
        '    <geom type="box" material="terrain"/>',
        "  </default>",
        "  <worldbody>",
        f'    <light pos="{_fmt([(xmin + xmax) / 2, (ymin + ymax) / 2, 10.0])}" dir="0 0 -1" directional="true"/>',
    ]
    lines += box_geoms(terrain)
    for index in range(len(terrain.meshes)):
        lines.append(f'    <geom name="mesh{index}" type="mesh" mesh="mesh{index}"/>')
    lines += ["  </worldbody>", "</mujoco>", ""]
    return "\n".join(lines)


def box_geoms(terrain: Terrain) -> list[str]:
    """`<geom type="box">` lines of the terrain's boxes, named box0, box1, ... in box order."""
    return [
        f'    <geom name="box{index}" type="box" pos="{_fmt(box.center)}" '
        f'size="{_fmt(box.half)}" quat="{_fmt(box.quaternion_wxyz)}"/>'
        for index, box in enumerate(terrain.boxes)
    ]


def _mesh_assets(terrain: Terrain) -> list[str]:
    """`<mesh>` asset lines of the terrain's meshes (vertices with float64 round-trip digits)."""
    return [
        f'    <mesh name="mesh{index}" inertia="shell" vertex="{_fmt(mesh.vertices.reshape(-1))}" '
        f'face="{" ".join(str(int(f)) for f in mesh.faces.reshape(-1))}"/>'
        for index, mesh in enumerate(terrain.meshes)
    ]


def terrain_to_mesh(terrain: Terrain):
    """Triangle mesh of all boxes (12 triangles per box, outward normals), then of the meshes, world frame.

    Returns:
        trimesh.Trimesh with 8 vertices and 12 faces per box, boxes in order, then each
        of `terrain.meshes` as it is (its orientation kept).
    """
    import trimesh

    unit = trimesh.creation.box(extents=[1.0, 1.0, 1.0])
    vertices, faces = [np.zeros((0, 3))], [np.zeros((0, 3), dtype=np.int64)]
    count = 0
    for box in terrain.boxes:
        # unit-cube corners scaled to the box then rotated and moved into the world
        vertices.append(box.center + (unit.vertices * box.size) @ box.rotation.T)
        faces.append(unit.faces + count)
        count += 8
    for mesh in terrain.meshes:
        vertices.append(mesh.vertices)
        faces.append(mesh.faces + count)
        count += len(mesh.vertices)
    return trimesh.Trimesh(vertices=np.concatenate(vertices), faces=np.concatenate(faces), process=False)


def export_terrain(terrain: Terrain, path) -> None:
    """Write a terrain by file extension: .xml (MJCF) or .glb, .obj, .stl (mesh).

    Raises:
        TerrainError: unknown extension or unwritable path.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in EXPORT_EXTENSIONS:
        raise TerrainError(
            f"{path}: unknown export format {suffix or '(none)'!r}: use one of {', '.join(EXPORT_EXTENSIONS)}"
        )
    if suffix == ".xml":
        data = terrain_to_mjcf(terrain).encode("utf-8")
    else:
        data = terrain_to_mesh(terrain).export(file_type=suffix[1:])
        data = data.encode("utf-8") if isinstance(data, str) else data
    try:
        _write_atomic(path, data)
    except OSError as err:
        raise TerrainError(f"{path}: cannot write export: {err.strerror or err}") from None


def _write_atomic(path: Path, data: bytes) -> None:
    """Write bytes to path through a temporary file in its folder, renamed over it."""
    handle, temp = tempfile.mkstemp(dir=path.parent if str(path.parent) else ".", prefix=f".{path.name}.")
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(data)
        os.replace(temp, path)
    except BaseException:
        Path(temp).unlink(missing_ok=True)
        raise
