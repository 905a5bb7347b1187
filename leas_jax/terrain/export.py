"""Terrain exports: MuJoCo MJCF scene and triangle meshes (trimesh).

Host code; not jittable.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING
from xml.sax.saxutils import quoteattr

import numpy as np

from leas_jax.errors import TerrainError

if TYPE_CHECKING:  # annotations only: the model's methods call this module
    from leas_jax.terrain.model import Terrain

MESH_EXTENSIONS = (".glb", ".obj", ".stl")
EXPORT_EXTENSIONS = (".xml",) + MESH_EXTENSIONS


def _fmt(values) -> str:
    """Space-separated numbers with enough digits to round-trip float64."""
    return " ".join(repr(float(v)) for v in values)


def terrain_to_mjcf(terrain: Terrain) -> str:
    """MuJoCo scene of a terrain: one `<geom type="box">` per box in the world body.

    Geoms are named box0, box1, ... in box order; `size` holds the half extents and
    `quat` the orientation in MuJoCo's (w, x, y, z) order.

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
        "  </asset>",
        "  <default>",
        '    <geom type="box" material="terrain"/>',
        "  </default>",
        "  <worldbody>",
        f'    <light pos="{_fmt([(xmin + xmax) / 2, (ymin + ymax) / 2, 10.0])}" dir="0 0 -1" directional="true"/>',
    ]
    for index, box in enumerate(terrain.boxes):
        lines.append(
            f'    <geom name="box{index}" type="box" pos="{_fmt(box.center)}" '
            f'size="{_fmt(box.half)}" quat="{_fmt(box.quaternion_wxyz)}"/>'
        )
    lines += ["  </worldbody>", "</mujoco>", ""]
    return "\n".join(lines)


def terrain_to_mesh(terrain: Terrain):
    """Triangle mesh of all boxes (12 triangles per box, outward normals), world frame.

    Returns:
        trimesh.Trimesh with 8 vertices and 12 faces per box, boxes in order.
    """
    import trimesh

    unit = trimesh.creation.box(extents=[1.0, 1.0, 1.0])
    vertices, faces = [], []
    for index, box in enumerate(terrain.boxes):
        # unit-cube corners scaled to the box then rotated and moved into the world
        vertices.append(box.center + (unit.vertices * box.size) @ box.rotation.T)
        faces.append(unit.faces + 8 * index)
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
    try:
        if suffix == ".xml":
            path.write_text(terrain_to_mjcf(terrain), encoding="utf-8")
        else:
            terrain_to_mesh(terrain).export(str(path), file_type=suffix[1:])
    except OSError as err:
        raise TerrainError(f"{path}: cannot write export: {err.strerror or err}") from None
