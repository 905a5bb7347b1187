"""Terrain format v2 sources: `[[mesh]]` files, the `[elevation]` map, and their content hashes.

Host code, not jittable. `leas_jax.terrain.loader` calls `load_sources` on the parsed
TOML; v1 files (boxes only) pass through unchanged. A v2 file (docs/design.md §4):

    [[mesh]]                      # any number; STL, OBJ, PLY, GLB (trimesh)
    file = "scene.stl"            # relative to the terrain file, absolute, or
                                  # "hpp-environments:multicontact/bridge.stl"
    translate = [0.0, 0.0, 0.0]   # m, world = translate + R(rpy) (scale * v)
    rpy = [0.0, 0.0, 0.0]         # rad, z-y-x as boxes
    scale = 1.0                   # a number or [sx, sy, sz], non-zero (0.001: millimetres)

    [elevation]                   # at most one
    file = "heights.npy"          # [nx, ny] array (float, uint16, int16), or a 16-bit PNG
    origin = [x0, y0, z0]         # m, sample [i, j] at (x0 + i res, y0 + j res)
    resolution = 0.05             # m
    height_scale = 1.0            # m per stored unit (> 0): z = z0 + height_scale * value

A PNG reads as a map, north up: image row 0 is the largest y. The elevation map becomes
a mesh of two triangles per grid cell, so every consumer treats it as a mesh.

The terrain text is what guide and plan files embed, so it must find the same files
again from anywhere: on a load from a file the loader appends a `[resolved]` table with
the absolute directory relative files were read from and the SHA-256 of every file's
bytes. A later parse of that text (a plan's terrain, a worker's copy) reads the files
from there and rejects any whose bytes changed.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import io
import json
import os
from pathlib import Path, PurePosixPath

import numpy as np

from leas_jax.terrain.mesh import TerrainMesh
from leas_jax.terrain.model import rotation_from_rpy

TOP_KEYS = {"mesh", "elevation", "resolved"}
MESH_KEYS = {"file", "translate", "rpy", "scale"}
ELEVATION_KEYS = {"file", "origin", "resolution", "height_scale"}
RESOLVED_KEYS = {"base_dir", "sha256"}
MESH_SUFFIXES = (".stl", ".obj", ".ply", ".glb")
ELEVATION_SUFFIXES = (".npy", ".png")
ELEVATION_DTYPES = ("float32", "float64", "uint16", "int16")
MAX_FILE_BYTES = 256 << 20  # a larger source file is rejected before it is read
MAX_TRIANGLES = 2_000_000  # per mesh (the 20 x 20 m HPP scene has 7 326)
MAX_ELEVATION_SAMPLES = 1_000_000  # 1000 x 1000 samples, 2 million triangles
# Packages whose data a terrain file may name as "<package>:<path>", and the folder of
# the installed distribution the path is relative to (hpp-environments ships its
# scenes in a cmeel prefix).
PACKAGE_FOLDERS = {"hpp-environments": "cmeel.prefix/share/hpp_environments/meshes"}


def has_geometry(data: dict) -> bool:
    """Whether parsed terrain TOML has `[[mesh]]` entries or an `[elevation]` table."""
    return bool(data.get("mesh")) or "elevation" in data


def load_sources(check, data: dict, text: str, path: str | None) -> tuple[tuple[TerrainMesh, ...], str]:
    """Meshes of a terrain's `[[mesh]]` and `[elevation]` entries, and the text to keep.

    Args:
        check: the loader's `_Checker` (its errors name the terrain file, key and value).
        data: the parsed TOML.
        text: the TOML text.
        path: the terrain file, or None (text from elsewhere: relative files are then
            relative to `[resolved].base_dir`, else to the working directory).

    Returns:
        (meshes in file order, the elevation last; the text, with a `[resolved]` table
        appended when it has sources and none yet).

    Raises:
        TerrainError: see the module docstring and `_read` for what is rejected.
    """
    raw_meshes = data.get("mesh", [])
    if not isinstance(raw_meshes, list) or not all(isinstance(m, dict) for m in raw_meshes):
        check.fail("mesh", raw_meshes, "must be an array of tables ([[mesh]])")
    raw_elevation = data.get("elevation")
    if raw_elevation is not None and not isinstance(raw_elevation, dict):
        check.fail("elevation", raw_elevation, "must be a table ([elevation])")
    entries = [(f"mesh[{k}]", raw) for k, raw in enumerate(raw_meshes)]
    if raw_elevation is not None:
        entries.append(("elevation", raw_elevation))
    resolved = data.get("resolved")
    if not entries:
        if resolved is not None:
            check.fail("resolved", resolved, "only terrains with [[mesh]] or [elevation] entries have one")
        return (), text
    base, hashes = _resolved(check, resolved, path, [key for key, _ in entries])
    meshes = []
    for key, raw in entries:
        if key == "elevation":
            meshes.append(_elevation(check, raw, base, hashes.get(key)))
        else:
            meshes.append(_mesh(check, key, raw, base, hashes.get(key)))
    if resolved is None:
        text = text + ("" if text.endswith("\n") else "\n") + _resolved_table(base, meshes)
    return tuple(meshes), text


def mesh_hash_mismatches(text: str, terrain) -> list[str]:
    """Messages for the meshes of `terrain` whose SHA-256 differs from, or is missing in, the
    `[resolved]` table of a terrain text (a plan's); [] when they all match."""
    import tomllib

    recorded = tomllib.loads(text).get("resolved", {}).get("sha256", {})
    messages = []
    for mesh in terrain.meshes:
        expected = recorded.get(mesh.key)
        if expected != mesh.sha256:
            messages.append(
                f"terrain {mesh.key} ({mesh.source}): SHA-256 {mesh.sha256}, the plan's terrain records {expected}"
            )
    return messages


def _resolved(check, raw, path, keys) -> tuple[Path, dict]:
    """(directory of relative files, {key: expected sha256}) from `[resolved]` or the file path."""
    if raw is None:
        base = Path(path).resolve().parent if path is not None else Path.cwd()
        return base, {}
    if not isinstance(raw, dict):
        check.fail("resolved", raw, "must be a table ([resolved])")
    check.keys(raw, "resolved", RESOLVED_KEYS, ("base_dir", "sha256"))
    base_dir = raw["base_dir"]
    if not isinstance(base_dir, str) or not os.path.isabs(base_dir):
        check.fail("resolved.base_dir", base_dir, "must be an absolute directory path")
    hashes = raw["sha256"]
    if not isinstance(hashes, dict) or set(hashes) != set(keys):
        check.fail("resolved.sha256", hashes, f"must be a table with exactly the keys {', '.join(keys)}")
    for key, value in hashes.items():
        if not isinstance(value, str) or len(value) != 64 or any(c not in "0123456789abcdef" for c in value):
            check.fail(
                f"resolved.sha256.{key}", value, "must be a SHA-256 hex digest (64 lowercase hex digits)"
            )
    return Path(base_dir), dict(hashes)


def _resolved_table(base: Path, meshes) -> str:
    """The `[resolved]` TOML table of a terrain's sources (json.dumps quotes are TOML basic strings)."""
    digests = ", ".join(f"{json.dumps(m.key)} = {json.dumps(m.sha256)}" for m in meshes)
    return (
        "\n# Appended on load (terrain format v2): where relative files were read, and the\n"
        "# SHA-256 of each source file's bytes, checked whenever this text is parsed again.\n"
        "[resolved]\n"
        f"base_dir = {json.dumps(str(base))}\n"
        f"sha256 = {{ {digests} }}\n"
    )


def locate(check, key: str, name, base: Path, suffixes: tuple[str, ...]) -> Path:
    """The file a `file` key names: "<package>:<path>" in an installed package's data,
    an absolute path, or a path relative to `base`."""
    if not isinstance(name, str) or not name:
        check.fail(key, name, "must be a non-empty string (a file path)")
    suffix = PurePosixPath(name).suffix.lower()
    if suffix not in suffixes:
        check.fail(key, name, f"unknown file type {suffix or '(none)'!r}: use one of {', '.join(suffixes)}")
    package, sep, inner = name.partition(":")
    if sep and package in PACKAGE_FOLDERS:
        parts = PurePosixPath(inner).parts
        if not parts or PurePosixPath(inner).is_absolute() or ".." in parts:
            check.fail(key, name, f"the path inside {package} must be relative, without '..'")
        try:
            dist = importlib.metadata.distribution(package)
        except importlib.metadata.PackageNotFoundError:
            check.fail(key, name, f"package {package} is not installed (pip install {package})")
        return Path(dist.locate_file(PACKAGE_FOLDERS[package])) / inner
    file = Path(name)
    return file if file.is_absolute() else base / file


def _read(check, key: str, name, file: Path, expected: str | None) -> tuple[bytes, str]:
    """(bytes, sha256 hex) of a source file; too large, unreadable or changed files are rejected."""
    try:
        size = file.stat().st_size
        if size > MAX_FILE_BYTES:
            check.fail(key, name, f"{file}: {size} bytes exceeds the {MAX_FILE_BYTES}-byte bound")
        data = file.read_bytes()
    except OSError as err:
        check.fail(key, name, f"cannot read {file}: {err.strerror or err}")
    digest = hashlib.sha256(data).hexdigest()
    if expected is not None and digest != expected:
        check.fail(
            key,
            name,
            f"{file} has SHA-256 {digest}, not the {expected} recorded in [resolved]: the file changed",
        )
    return data, digest


def _vector3(check, key: str, raw: dict, name: str, default) -> np.ndarray:
    return (
        check.array(f"{key}.{name}", raw[name], (3,))
        if name in raw
        else np.asarray(default, dtype=np.float64)
    )


def _mesh(check, key: str, raw: dict, base: Path, expected: str | None) -> TerrainMesh:
    """One `[[mesh]]` entry, read and moved into the world frame."""
    check.keys(raw, key, MESH_KEYS, ("file",))
    translate = _vector3(check, key, raw, "translate", np.zeros(3))
    rpy = _vector3(check, key, raw, "rpy", np.zeros(3))
    if "scale" in raw and isinstance(raw["scale"], list):
        scale = check.array(f"{key}.scale", raw["scale"], (3,))
    else:
        scale = np.full(3, check.number(f"{key}.scale", raw["scale"]) if "scale" in raw else 1.0)
    if np.any(scale == 0.0):
        check.fail(f"{key}.scale", raw["scale"], "must be non-zero (a mesh of no extent)")
    name = raw["file"]
    file = locate(check, f"{key}.file", name, base, MESH_SUFFIXES)
    data, digest = _read(check, f"{key}.file", name, file, expected)
    vertices, faces = _parse_mesh(check, f"{key}.file", name, file, data)
    world = translate + (vertices * scale) @ rotation_from_rpy(rpy).T
    _check_extent(check, f"{key}.file", name, world)
    return TerrainMesh(key=key, vertices=world, faces=faces, sha256=digest, source=name)


def _check_extent(check, key: str, name: str, world: np.ndarray) -> None:
    """World vertices within the loader's coordinate bound (`check.number`'s default range,
    as for boxes and heights); the message names the file's key, the file and the reach."""
    check.number(f"{key} ({json.dumps(name)}) largest world |coordinate|", float(np.abs(world).max()))


def _parse_mesh(check, key: str, name: str, file: Path, data: bytes) -> tuple[np.ndarray, np.ndarray]:
    """(vertices [V, 3], faces [F, 3]) of mesh file bytes, validated."""
    import trimesh

    try:
        loaded = trimesh.load(
            io.BytesIO(data), file_type=file.suffix.lower()[1:], force="mesh", process=False
        )
        vertices = np.asarray(loaded.vertices, dtype=np.float64).reshape(-1, 3)
        faces = np.asarray(loaded.faces, dtype=np.int64).reshape(-1, 3)
    except Exception as err:  # trimesh raises many types on malformed files
        check.fail(
            key, name, f"{file} is not a readable {file.suffix.lower()} mesh: {type(err).__name__}: {err}"
        )
    if len(faces) == 0:
        check.fail(key, name, f"{file} holds no triangle (empty mesh)")
    if len(faces) > MAX_TRIANGLES:
        check.fail(key, name, f"{file} holds {len(faces)} triangles, over the bound of {MAX_TRIANGLES}")
    if not np.all(np.isfinite(vertices)):
        bad = int(np.count_nonzero(~np.all(np.isfinite(vertices), axis=1)))
        check.fail(key, name, f"{file} has {bad} vertices with nan or inf coordinates")
    if faces.min() < 0 or faces.max() >= len(vertices):
        check.fail(key, name, f"{file} has faces indexing vertices outside [0, {len(vertices) - 1}]")
    return vertices, faces


def _elevation(check, raw: dict, base: Path, expected: str | None) -> TerrainMesh:
    """The `[elevation]` table, as a mesh of two triangles per grid cell."""
    key = "elevation"
    check.keys(raw, key, ELEVATION_KEYS, ("file", "origin", "resolution"))
    origin = check.array(f"{key}.origin", raw["origin"], (3,))
    resolution = check.number(f"{key}.resolution", raw["resolution"])
    if resolution <= 0.0:
        check.fail(f"{key}.resolution", raw["resolution"], "must be > 0")
    scale = check.number(f"{key}.height_scale", raw["height_scale"]) if "height_scale" in raw else 1.0
    if scale <= 0.0:
        check.fail(f"{key}.height_scale", raw["height_scale"], "must be > 0")
    name = raw["file"]
    file = locate(check, f"{key}.file", name, base, ELEVATION_SUFFIXES)
    data, digest = _read(check, f"{key}.file", name, file, expected)
    grid = _parse_grid(check, f"{key}.file", name, file, data)
    heights = origin[2] + scale * grid
    vertices = grid_vertices(heights, origin[:2], resolution)
    _check_extent(check, f"{key}.file", name, vertices)
    return TerrainMesh(
        key=key,
        vertices=vertices,
        faces=grid_faces(*heights.shape),
        sha256=digest,
        source=name,
    )


def _parse_grid(check, key: str, name: str, file: Path, data: bytes) -> np.ndarray:
    """[nx, ny] float64 stored values of an elevation file (index [i, j] = x i, y j)."""
    if file.suffix.lower() == ".npy":
        try:
            array = np.load(io.BytesIO(data), allow_pickle=False)
        except (ValueError, OSError, EOFError) as err:
            check.fail(key, name, f"{file} is not a .npy array: {err}")
        if array.dtype.name not in ELEVATION_DTYPES:
            check.fail(
                key, name, f"{file} has dtype {array.dtype.name}: use one of {', '.join(ELEVATION_DTYPES)}"
            )
    else:
        from PIL import Image

        try:
            image = Image.open(io.BytesIO(data))
            image.load()
        except Exception as err:  # Pillow raises several types on malformed files
            check.fail(key, name, f"{file} is not a readable PNG: {type(err).__name__}: {err}")
        if image.format != "PNG" or image.mode not in ("I;16", "I;16B", "I;16L"):
            check.fail(
                key,
                name,
                f"{file} is a {image.format} image of mode {image.mode}: use a 16-bit grayscale PNG",
            )
        # North up: image row 0 is the largest y, so [i, j] = image[ny - 1 - j, i].
        array = np.asarray(image, dtype=np.uint16)[::-1].T
    if array.ndim != 2 or min(array.shape) < 2:
        check.fail(key, name, f"{file} has shape {list(array.shape)}: need a 2-D grid of at least 2 x 2")
    if array.size > MAX_ELEVATION_SAMPLES:
        check.fail(key, name, f"{file} has {array.size} samples, over the bound of {MAX_ELEVATION_SAMPLES}")
    values = np.asarray(array, dtype=np.float64)
    if not np.all(np.isfinite(values)):
        check.fail(key, name, f"{file} has {int(np.count_nonzero(~np.isfinite(values)))} nan or inf samples")
    return values


def grid_vertices(heights: np.ndarray, origin, resolution: float) -> np.ndarray:
    """[nx*ny, 3] vertices of a height grid [nx, ny]: vertex i*ny + j at (x0 + i res, y0 + j res, h[i, j])."""
    nx, ny = heights.shape
    x = origin[0] + np.arange(nx) * resolution
    y = origin[1] + np.arange(ny) * resolution
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return np.stack([gx, gy, heights], axis=-1).reshape(-1, 3)


def grid_faces(nx: int, ny: int) -> np.ndarray:
    """[2 (nx-1) (ny-1), 3] triangles of a grid: each cell split along its (i, j)-(i+1, j+1) diagonal,
    counter-clockwise seen from above."""
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), indexing="ij")
    a = (i * ny + j).reshape(-1)
    b, c, d = a + ny, a + ny + 1, a + 1  # (i+1, j), (i+1, j+1), (i, j+1)
    return np.concatenate([np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)])
