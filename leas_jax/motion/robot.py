"""Talos in MuJoCo, built with `mujoco.MjSpec` from example-robot-data's URDF.

Host-only (MuJoCo, Pinocchio), not jittable. The same URDF the contact generator loads
(`leas_jax.contacts.robot.model.TalosModel.urdf_path`, `talos_reduced.urdf`) is parsed by
MuJoCo's URDF reader with its mesh files handed over in memory (no download, no
`package://` resolution), then edited in code:

- a free joint `root_joint` on `base_link` (the URDF fixes nothing to the world, MuJoCo
  would weld its root link);
- the 32 revolute joints with the URDF's position limits (`range`) and effort limits
  (`actuatorfrcrange`, read by MuJoCo from `<limit effort>`), one torque motor each with
  `ctrlrange` = the effort limit;
- joint armature equal to Pinocchio's (`model.armature`, 0.1 kg m^2 on most joints as
  example-robot-data loads Talos), so that MuJoCo's mass matrix and Pinocchio's
  `crba`/`rnea` agree; masses and inertias come from the URDF's `<inertial>` as
  Pinocchio's do (tests/test_motion_robot.py compares them);
- one sole box per foot under each sole frame (`leg_*_sole_fix_joint`), the
  0.20 x 0.13 m sole rectangle of docs/design.md §6 check 1, its bottom face on the sole
  plane, and a site `*_sole` at the sole frame;
- the URDF's collision meshes collide with the terrain only (not with each other), so
  that a knee, hand or shin touching the terrain is seen; the two foot meshes
  (`leg_*_6_link`) do not collide: they reach 0.4 mm below the sole plane
  (`contacts.robot.model.FOOT_CLEARANCE`), the sole box stands for the foot.

Configurations: MuJoCo's qpos is root xyz + quaternion **wxyz** + 32 joints in MuJoCo's
body order; `TalosMujoco.qpos_from_pin` and `pin_from_qpos` convert from and to
Pinocchio's [39] (quaternion xyzw, Pinocchio's joint order).
"""

from __future__ import annotations

import functools
import math
import os
import re
import warnings
from dataclasses import dataclass

import numpy as np

from leas_jax.contacts.robot.model import FRICTION, LEG_PREFIXES, SOLE_FRAMES, SOLE_LENGTH, SOLE_WIDTH

# Sole box thickness, m: thin enough to sit inside the foot mesh's 1.07 cm below the
# ankle-roll link's sole plate; its bottom face is the sole plane.
SOLE_THICKNESS = 0.01
# Contact-type bits: the terrain's geoms keep MuJoCo's default (contype 1, conaffinity 1);
# the robot's colliding geoms have contype 0 and conaffinity 1, so they collide with the
# terrain and never with each other (0 & 1 == 0 both ways).
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 0, 1
SOLE_SITES = ("left_sole", "right_sole")
SOLE_GEOMS = ("left_sole_box", "right_sole_box")
ROOT_JOINT = "root_joint"
_PACKAGE = "package://"


@dataclass(frozen=True)
class MujocoTalos:
    """Talos's MuJoCo model and the maps between its arrays and Pinocchio's.

    Attributes:
        model: mujoco.MjModel (robot alone, or robot + terrain from `scene_model`).
        joint_names: (32,) actuated joint names, Pinocchio's order.
        qpos_index: [32] qpos index of each joint in `joint_names` (Pinocchio order).
        dof_index: [32] qvel index of each joint in `joint_names`.
        actuator_index: [32] actuator id of each joint in `joint_names`.
        effort: [32] effort limits, N m, Pinocchio order (the URDF's `<limit effort>`).
        sole_sites: (left, right) site ids of the sole frames.
        sole_geoms: (left, right) geom ids of the sole boxes.
        robot_geoms: [G] ids of every robot geom that collides (sole boxes included).
        root_body: body id of base_link.
    """

    model: object
    joint_names: tuple
    qpos_index: np.ndarray
    dof_index: np.ndarray
    actuator_index: np.ndarray
    effort: np.ndarray
    sole_sites: tuple
    sole_geoms: tuple
    robot_geoms: np.ndarray
    root_body: int

    def qpos_from_pin(self, q: np.ndarray) -> np.ndarray:
        """MuJoCo qpos [..., 39] of Pinocchio configurations q [..., 39]."""
        q = np.asarray(q, dtype=np.float64)
        out = np.empty_like(q)
        out[..., :3] = q[..., :3]
        out[..., 3] = q[..., 6]
        out[..., 4:7] = q[..., 3:6]
        out[..., self.qpos_index] = q[..., 7:]
        return out

    def pin_from_qpos(self, qpos: np.ndarray) -> np.ndarray:
        """Pinocchio configurations [..., 39] of MuJoCo qpos [..., 39]."""
        qpos = np.asarray(qpos, dtype=np.float64)
        out = np.empty_like(qpos)
        out[..., :3] = qpos[..., :3]
        out[..., 6] = qpos[..., 3]
        out[..., 3:6] = qpos[..., 4:7]
        out[..., 7:] = qpos[..., self.qpos_index]
        return out

    def qvel_from_pin_at(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """MuJoCo qvel [38] of a Pinocchio velocity v [38] at configuration q [39].

        Pinocchio's free-flyer velocity is the root's linear and angular velocity in the
        base_link frame; MuJoCo's free joint takes the linear velocity in the world frame and
        the angular one in the body frame.
        """
        from leas_jax.contacts.robot.model import matrix_from_quat_xyzw

        out = np.empty(38)
        out[:3] = matrix_from_quat_xyzw(q[3:7]) @ v[:3]
        out[3:6] = v[3:6]
        out[self.dof_index] = v[6:]
        return out

    def pin_v_from_qvel(self, qpos: np.ndarray, qvel: np.ndarray) -> np.ndarray:
        """Pinocchio velocity [38] (root velocity in the base_link frame) of MuJoCo (qpos, qvel)."""
        from leas_jax.contacts.robot.model import matrix_from_quat_xyzw

        rot = matrix_from_quat_xyzw(np.r_[qpos[4:7], qpos[3]])
        out = np.empty(38)
        out[:3] = rot.T @ qvel[:3]
        out[3:6] = qvel[3:6]
        out[6:] = qvel[self.dof_index]
        return out


def _urdf_with_assets(urdf_path: str) -> tuple[str, dict]:
    """The URDF text with each `package://` mesh renamed to an in-memory asset, and the assets.

    example-robot-data's meshes live under `<share>/example-robot-data/...`; the URDF
    names them `package://example-robot-data/...`. MuJoCo's URDF reader resolves no
    packages, so each file is read here and handed over by a flat unique name.

    Returns:
        (URDF text with a floating `root_joint` from a `world` link to `base_link` and a
        `<mujoco><compiler>` element, {asset name: file bytes}).
    """
    with open(urdf_path) as handle:
        text = handle.read()
    share = os.path.normpath(os.path.join(os.path.dirname(urdf_path), "..", "..", "..", ".."))
    assets = {}

    def rename(match):
        relative = match.group(1)[len(_PACKAGE) :]
        key = relative.replace("/", "__")
        if key not in assets:
            with open(os.path.join(share, relative), "rb") as handle:
                assets[key] = handle.read()
        return f'filename="{key}"'

    text = re.sub(r'filename="(package://[^"]*)"', rename, text)
    head = re.search(r"<robot[^>]*>", text)
    if head is None:
        raise RuntimeError(f"{urdf_path}: no <robot> element")
    # discardvisual: the collision meshes are enough; fusestatic: fixed links merge into
    # their parent body as Pinocchio merges them into their parent joint.
    compiler = (
        '<mujoco><compiler discardvisual="true" fusestatic="true" balanceinertia="false" '
        'strippath="false" angle="radian"/></mujoco>'
    )
    floating = (
        f'<link name="world"/><joint name="{ROOT_JOINT}" type="floating">'
        '<parent link="world"/><child link="base_link"/></joint>'
    )
    text = text[: head.end()] + compiler + text[head.end() :]
    text = text.replace("</robot>", floating + "</robot>")
    return text, assets


def talos_spec():
    """MjSpec of Talos (free joint, motors, sole boxes and sites), no terrain.

    Returns:
        (mujoco.MjSpec, pinocchio Model of the same URDF as the contact generator loads).
    """
    import mujoco

    from leas_jax.contacts.robot.model import load_talos

    talos = load_talos()
    pin_model = talos.model
    text, assets = _urdf_with_assets(talos.urdf_path)
    spec = mujoco.MjSpec.from_string(text, assets=assets)
    spec.modelname = "talos"
    for joint_id in range(2, pin_model.njoints):
        name = pin_model.names[joint_id]
        joint = spec.joint(name)
        dof = pin_model.joints[joint_id].idx_v
        joint.armature = float(pin_model.armature[dof])
        index = pin_model.joints[joint_id].idx_q
        joint.range = [float(pin_model.lowerPositionLimit[index]), float(pin_model.upperPositionLimit[index])]
        joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        effort = float(pin_model.effortLimit[dof])
        joint.actfrcrange = [-effort, effort]
        joint.actfrclimited = mujoco.mjtLimited.mjLIMITED_TRUE
        motor = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        motor.set_to_motor()
        motor.ctrlrange = [-effort, effort]
        motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    for geom in spec.geoms:
        geom.contype, geom.conaffinity = ROBOT_CONTYPE, ROBOT_CONAFFINITY
        geom.friction = [FRICTION, 0.005, 0.0001]
        if geom.parent.name in {f"{prefix}_6_link" for prefix in LEG_PREFIXES}:
            geom.contype, geom.conaffinity = 0, 0  # the sole box stands for the foot
    for prefix, frame_name, site_name, geom_name in zip(LEG_PREFIXES, SOLE_FRAMES, SOLE_SITES, SOLE_GEOMS):
        frame = pin_model.frames[pin_model.getFrameId(frame_name)]
        body = spec.body(f"{prefix}_6_link")
        placement = frame.placement  # sole frame in the ankle-roll joint frame (= this body's frame)
        rot = np.asarray(placement.rotation)
        quat = _wxyz(rot)
        body.add_site(
            name=site_name, pos=np.asarray(placement.translation), quat=quat, size=[0.01, 0.01, 0.01]
        )
        body.add_geom(
            name=geom_name,
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[SOLE_LENGTH / 2, SOLE_WIDTH / 2, SOLE_THICKNESS / 2],
            pos=np.asarray(placement.translation) + rot @ np.array([0.0, 0.0, SOLE_THICKNESS / 2]),
            quat=quat,
            contype=ROBOT_CONTYPE,
            conaffinity=ROBOT_CONAFFINITY,
            friction=[FRICTION, 0.005, 0.0001],
            mass=0.0,
            rgba=[0.2, 0.3, 0.8, 1.0],
        )
    return spec, pin_model


def _wxyz(rot: np.ndarray) -> np.ndarray:
    """[4] quaternion (w, x, y, z) of a rotation matrix [3, 3]."""
    from leas_jax.contacts.robot.model import quat_xyzw_from_matrix

    x, y, z, w = quat_xyzw_from_matrix(rot)
    return np.array([w, x, y, z])


def _wrap(model, pin_model) -> MujocoTalos:
    """`MujocoTalos` maps of a compiled model holding Talos's joints, sites and geoms."""
    import mujoco

    names = tuple(pin_model.names[j] for j in range(2, pin_model.njoints))
    joints = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in names]
    if min(joints) < 0:
        raise RuntimeError("MuJoCo Talos lacks a joint of the Pinocchio model")
    root_body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base_link")
    robot_bodies = _subtree(model, root_body)
    robot_geoms = np.array(
        [g for g in range(model.ngeom) if model.geom_bodyid[g] in robot_bodies and model.geom_conaffinity[g]]
    )
    dof_effort = np.array(
        [pin_model.effortLimit[pin_model.joints[j].idx_v] for j in range(2, pin_model.njoints)]
    )
    return MujocoTalos(
        model=model,
        joint_names=names,
        qpos_index=np.array([model.jnt_qposadr[j] for j in joints]),
        dof_index=np.array([model.jnt_dofadr[j] for j in joints]),
        actuator_index=np.array([mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, n) for n in names]),
        effort=dof_effort,
        sole_sites=tuple(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, n) for n in SOLE_SITES),
        sole_geoms=tuple(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in SOLE_GEOMS),
        robot_geoms=robot_geoms,
        root_body=root_body,
    )


def _subtree(model, root: int) -> set:
    """Ids of the bodies in the subtree of body `root` (itself included)."""
    out = {root}
    for body in range(root + 1, model.nbody):
        if model.body_parentid[body] in out:
            out.add(body)
    return out


@functools.lru_cache(maxsize=1)
def talos_mujoco() -> MujocoTalos:
    """Talos alone in MuJoCo (no terrain, no floor), cached per process."""
    spec, pin_model = talos_spec()
    return _wrap(spec.compile(), pin_model)


def scene_model(terrain_mjcf: str, timestep: float) -> MujocoTalos:
    """Talos standing in a terrain scene.

    Args:
        terrain_mjcf: the terrain's MJCF (`Terrain.to_mjcf()`: boxes, meshes, elevation
            maps as meshes), world frame.
        timestep: physics step, s.

    Returns:
        MujocoTalos whose model holds the terrain geoms (friction set to
        `contacts.robot.model.FRICTION`, the plan's mu) and Talos attached at the world origin.
    """
    import mujoco

    terrain = mujoco.MjSpec.from_string(terrain_mjcf)
    for geom in terrain.geoms:
        geom.friction = [FRICTION, 0.005, 0.0001]
    scene, pin_model = talos_spec()
    scene.visual.map.znear, scene.visual.map.zfar = terrain.visual.map.znear, terrain.visual.map.zfar
    scene.stat.center, scene.stat.extent = terrain.stat.center, terrain.stat.extent
    with warnings.catch_warnings():
        # MuJoCo warns that a child without an asset dict (the terrain's inline meshes) may
        # lose its assets when attached again; this scene is compiled once, never attached.
        warnings.filterwarnings("ignore", message="Attaching a child without asset dict")
        scene.attach(terrain, prefix="terrain/", frame=scene.worldbody.add_frame())
    scene.option.timestep = timestep
    scene.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    return _wrap(scene.compile(), pin_model)


# MuJoCo's friction cones by `SimulationConfig.cone`.
CONES = ("pyramidal", "elliptic")


def set_friction_solver(model, cone: str, impratio: float) -> None:
    """Set a MuJoCo model's friction cone (one of CONES) and impratio (> 0), in place."""
    import mujoco

    if cone not in CONES:
        raise ValueError(f"cone: expected one of {', '.join(CONES)}, got {cone!r}")
    if not impratio > 0.0:
        raise ValueError(f"impratio: expected a positive number, got {impratio!r}")
    model.opt.cone = mujoco.mjtCone.mjCONE_ELLIPTIC if cone == "elliptic" else mujoco.mjtCone.mjCONE_PYRAMIDAL
    model.opt.impratio = impratio


# Raster of a mesh terrain's physics scene: cell size, m (at most; the terrain's own
# resolution when finer), and the height step, m, under which neighbouring cells merge.
RASTER_SPACING = 0.02
HEIGHT_QUANTUM = 0.001
# Steepest mesh face with a column of its own in a physics scene (`surface_columns`), rad:
# a steeper one (a block's or a stair's riser) is a side of the columns beside it, and a
# near-vertical face would make a column too thin for its convex hull.
COLUMN_MAX_SLOPE = math.radians(85.0)
# Collision surfaces of a mesh terrain's physics scene (`terrain_scene`).
MESH_CONTACTS = ("columns", "raster")


def terrain_scene(terrain, timestep: float, mesh_contact: str) -> MujocoTalos:
    """Talos in a terrain's physics scene: `scene_model` of `physics_terrain_mjcf`.

    Args:
        terrain: a `Terrain` (world frame).
        timestep: physics step, s.
        mesh_contact: one of MESH_CONTACTS (`physics_terrain_mjcf`; `SimulationConfig.mesh_contact`).
    """
    return scene_model(physics_terrain_mjcf(terrain, mesh_contact), timestep)


def physics_terrain_mjcf(terrain, mesh_contact: str) -> str:
    """MJCF of a terrain's collision surface (world frame).

    A terrain of boxes only is exported as it is (`terrain_to_mjcf`: one box geom per box).
    MuJoCo collides a mesh geom through its convex hull, so a terrain with meshes (the HPP
    scenes: a room's floor, a staircase) would be a solid block; its collision surface is
    then made of convex pieces:

    - "columns": its boxes as boxes, and under each convex piece of its meshes' upward
      faces a convex column down to the void (`surface_columns`): every face, tilted ones
      included, is the plane it is, and a sole on it meets one convex geom.
    - "raster": boxes over the cells of its heights raster (`raster_boxes`; `Terrain.height_at`,
      exact ray casts on the boxes and the meshes' triangles). A tilted face becomes a
      staircase of steps (5 mm on a 15 deg face at 2 cm cells) on which soles slip and roll
      (docs/results/2026-12-07-motion-mesh-contact).

    A MuJoCo height field of the same heights was measured first: on flat ground its box
    contacts make the flat-ground test motion fall (1 cm samples) or slip 1 cm (20 cm samples).

    Args:
        terrain: a `Terrain`.
        mesh_contact: one of MESH_CONTACTS.

    Raises:
        ValueError: an unknown `mesh_contact`.
    """
    from leas_jax.terrain.export import box_geoms, terrain_to_mjcf

    if mesh_contact not in MESH_CONTACTS:
        raise ValueError(f"mesh_contact: expected one of {', '.join(MESH_CONTACTS)}, got {mesh_contact!r}")
    if not terrain.meshes:
        return terrain_to_mjcf(terrain)
    assets, lines = [], []
    if mesh_contact == "raster":
        for i, (lo, hi) in enumerate(raster_boxes(terrain)):
            centre, half = (lo + hi) / 2.0, (hi - lo) / 2.0
            lines.append(
                f'    <geom name="raster{i}" type="box" pos="{centre[0]:.6f} {centre[1]:.6f} {centre[2]:.6f}" '
                f'size="{half[0]:.6f} {half[1]:.6f} {half[2]:.6f}"/>'
            )
    else:
        lines = box_geoms(terrain)
        for i, column in enumerate(surface_columns(terrain)):
            assets.append(
                f'    <mesh name="column{i}" vertex="{" ".join(f"{v:.9g}" for v in column.reshape(-1))}"/>'
            )
            lines.append(f'    <geom name="column{i}" type="mesh" mesh="column{i}"/>')
    mjcf = [
        "<mujoco>",
        "  <asset>",
        *assets,
        "  </asset>",
        "  <worldbody>",
        *lines,
        "  </worldbody>",
        "</mujoco>",
    ]
    return "\n".join(mjcf)


def surface_columns(terrain) -> list[np.ndarray]:
    """Convex columns whose union's top is the surface of the terrain's meshes.

    Each is the prism under one convex piece of coplanar upward faces (`support_polygons`
    over every face up to COLUMN_MAX_SLOPE, covered faces left out) down to `void_height`:
    what lies under a face is solid, as in the terrain's heights raster.

    Returns:
        list of [2N, 3] vertices (world, m): the piece's N corners, then the same corners
        at `void_height`.
    """
    from leas_jax.terrain.mesh import support_polygons

    pieces = support_polygons(terrain.meshes, math.tan(COLUMN_MAX_SLOPE), terrain.height_at)
    bottom = float(terrain.void_height)
    return [
        np.concatenate([p.vertices, np.c_[p.vertices[:, :2], np.full(len(p.vertices), bottom)]])
        for p in pieces
        if p.vertices[:, 2].min() > bottom
    ]


def raster_boxes(terrain, spacing: float | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Axis-aligned boxes (lower corner [3], upper corner [3]; world, m) whose union's top is
    the terrain's heights sampled every `spacing` m (default RASTER_SPACING or the terrain's
    resolution, the finer) over its bounds: each sample owns the cell of that size around it;
    cells of equal height (to HEIGHT_QUANTUM) merge into rectangles, greedily along x then y;
    each box reaches down to `void_height`; cells over the void hold none.
    """
    (x0, y0), (x1, y1) = np.asarray(terrain.bounds, dtype=np.float64)
    spacing = spacing or min(RASTER_SPACING, float(terrain.resolution))
    xs = np.arange(x0, x1 + 1e-9, spacing)
    ys = np.arange(y0, y1 + 1e-9, spacing)
    grid = np.stack(np.meshgrid(xs, ys, indexing="xy"), axis=-1)  # [rows (y), cols (x), 2]
    heights = terrain.height_at(grid)
    bottom = float(terrain.void_height)
    keys = np.round(heights / HEIGHT_QUANTUM).astype(np.int64)
    solid = heights > bottom + HEIGHT_QUANTUM
    free = solid.copy()
    boxes = []
    rows, cols = keys.shape
    for r in range(rows):
        c = 0
        while c < cols:
            if not free[r, c]:
                c += 1
                continue
            key = keys[r, c]
            end = c
            while end + 1 < cols and free[r, end + 1] and keys[r, end + 1] == key:
                end += 1
            last = r
            while (
                last + 1 < rows and (free[last + 1, c : end + 1] & (keys[last + 1, c : end + 1] == key)).all()
            ):
                last += 1
            free[r : last + 1, c : end + 1] = False
            top = float(heights[r, c])
            lo = np.array([xs[c] - spacing / 2, ys[r] - spacing / 2, bottom])
            hi = np.array([xs[end] + spacing / 2, ys[last] + spacing / 2, top])
            boxes.append((lo, hi))
            c = end + 1
    return boxes
