"""Execute a motion in MuJoCo physics and measure what happened, phase by phase.

Host-only (MuJoCo, NumPy), not jittable. `simulate(motion, terrain)` puts Talos
(`motion.robot.terrain_scene`) at the motion's first configuration and runs a joint-space
tracking controller at every physics step (1 kHz):

    tau = tau_ff(t) + kp (q_ref(t) - q) + kd (v_ref(t) - v),  clipped to the effort limits,

with q_ref, v_ref and tau_ff (the motion's inverse dynamics with its planned sole
wrenches) interpolated linearly between the motion's 100 Hz samples. The gains come
from the mass matrix (`SimulationConfig`). The root is not actuated: balance comes from
the feed-forward and the stiffness of the legs.

Measured (`Rollout`, `PhaseResult`): the root's height over the supporting soles and its
tilt (a fall ends the run); where each sole lands at the end of its landing phase
(position and angle errors against the plan's placement); how far each sole slips while
in support; every contact between the terrain and a robot geom other than the sole
boxes; the largest commanded torque over its limit (before clipping).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from leas_jax.motion.config import SimulationConfig
from leas_jax.motion.motion import Motion


@dataclass
class PhaseResult:
    """What happened during one phase of the motion.

    Attributes:
        kind, postures, swing: the motion's phase (`motion.Phase`).
        landing_position: m, sole position error at the end of a landing phase (NaN otherwise).
        landing_angle: rad, sole orientation error there (NaN otherwise).
        slip: m, largest horizontal displacement of a supporting sole from where it stood
            at the start of the phase.
        torque_ratio: largest |commanded torque| / effort limit, before clipping.
        other_contacts: names of robot geoms other than the soles that touched the terrain.
        fallen: the root fell (too low or tilted) during the phase.
        reached: the simulation got to the phase's end.
    """

    kind: str
    postures: tuple
    swing: int
    landing_position: float = math.nan
    landing_angle: float = math.nan
    slip: float = 0.0
    torque_ratio: float = 0.0
    other_contacts: list = field(default_factory=list)
    fallen: bool = False
    reached: bool = False

    def problems(self, config: SimulationConfig) -> list[str]:
        """Why this phase fails the success criteria (empty: it passes)."""
        out = []
        if self.fallen:
            out.append("the robot fell")
        elif not self.reached:
            out.append("not reached")
        if self.landing_position > config.landing_position:
            out.append(f"sole lands {self.landing_position * 100:.1f} cm from its placement")
        if self.landing_angle > config.landing_angle:
            out.append(f"sole lands {math.degrees(self.landing_angle):.1f} deg off its placement")
        if self.slip > config.max_slip:
            out.append(f"a supporting sole slips {self.slip * 100:.1f} cm")
        if self.torque_ratio > 1.0:
            out.append(f"torque {self.torque_ratio:.2f} x its limit (clipped)")
        if self.other_contacts:
            out.append("terrain touched by " + ", ".join(sorted(set(self.other_contacts))))
        return out


@dataclass
class Rollout:
    """Result of `simulate`.

    Attributes:
        success: every phase reached and passes, and the robot stands at the end.
        fallen: the root fell (height or tilt bounds).
        fall_time: s of the fall, NaN when none.
        phases: [P] PhaseResult, one per motion phase.
        time: [M] s, recorded samples (every motion sample, 100 Hz).
        q: [M, 39] simulated Pinocchio configurations at those times.
        root_height: [M] base_link height over the highest supporting sole, m.
        tilt: [M] angle between base_link's z axis and world z, rad.
        joint_torque_ratio: [32] largest |commanded torque| / effort limit of each joint over
            the run, before clipping (Pinocchio joint order, `JOINT_GROUPS`).
        seconds: wall-clock time of the simulation, s.
        cpu_seconds: CPU time of this process during the simulation, s.
        message: one line: success, or the first failing phase and why.
    """

    success: bool
    fallen: bool
    fall_time: float
    phases: list
    time: np.ndarray
    q: np.ndarray
    root_height: np.ndarray
    tilt: np.ndarray
    seconds: float
    message: str
    joint_torque_ratio: np.ndarray = field(default_factory=lambda: np.zeros(32))
    cpu_seconds: float = math.nan

    def group_torque_ratios(self) -> dict:
        """Largest |commanded torque| / effort limit per joint group of `JOINT_GROUPS`."""
        return {
            name: float(self.joint_torque_ratio[list(index)].max()) for name, index in JOINT_GROUPS.items()
        }

    def summary(self) -> dict:
        """Figures of the rollout: phases reached, worst landing, slip and torque ratio."""
        reached = [p for p in self.phases if p.reached]
        landings = [p for p in reached if p.kind == "land"]
        return {
            "success": self.success,
            "fallen": self.fallen,
            "phases": len(self.phases),
            "phases_reached": len(reached),
            "landings": len(landings),
            "max_landing_position_m": max((p.landing_position for p in landings), default=math.nan),
            "max_landing_angle_deg": math.degrees(max((p.landing_angle for p in landings), default=math.nan)),
            "max_slip_m": max((p.slip for p in reached), default=math.nan),
            "max_torque_ratio": max((p.torque_ratio for p in self.phases), default=math.nan),
            "seconds": self.seconds,
        }


# Talos's actuated joints by group, as indices into the 32 joints in Pinocchio's order
# (leg_left_1..6, leg_right_1..6, torso_1..2, arm_left_1..7, gripper_left, arm_right_1..7,
# gripper_right, head_1..2).
JOINT_GROUPS = {
    "legs": tuple(range(0, 12)),
    "torso": (12, 13),
    "arms": tuple(range(14, 21)) + tuple(range(22, 29)),
    "grippers": (21, 29),
    "head": (30, 31),
}


def pd_gains(mj, talos, config: SimulationConfig) -> tuple[np.ndarray, np.ndarray]:
    """Joint gains [32] kp (N m/rad) and kd (N m s/rad), Pinocchio joint order.

    kp = M_ii omega^2 (at least `leg_stiffness` on the legs), kd = 2 zeta sqrt(kp M_ii),
    with M_ii the joint's diagonal of the mass matrix at half-sitting (armature included).
    """
    import pinocchio as pin

    inertia = np.diag(pin.crba(talos.model, talos.model.createData(), talos.q_ref))[6:]
    kp = inertia * config.omega**2
    legs = np.concatenate([leg.v_index for leg in talos.legs]) - 6
    kp[legs] = np.maximum(kp[legs], config.leg_stiffness)
    return kp, 2.0 * config.zeta * np.sqrt(kp * inertia)


def _interpolate(samples: np.ndarray, position: float) -> np.ndarray:
    """Linear interpolation of samples [N, ...] at a fractional index."""
    low = min(int(position), len(samples) - 1)
    high = min(low + 1, len(samples) - 1)
    frac = position - low
    return (1.0 - frac) * samples[low] + frac * samples[high]


def _tilt(xmat: np.ndarray) -> float:
    """Angle between a body's z axis (rotation matrix [9], row-major) and world z, rad."""
    return float(math.acos(max(-1.0, min(1.0, xmat[8]))))


def _angle_between(rot0: np.ndarray, rot1: np.ndarray) -> float:
    """Geodesic angle between two rotation matrices [3, 3], rad."""
    cos = (np.trace(rot0.T @ rot1) - 1.0) / 2.0
    return float(math.acos(max(-1.0, min(1.0, cos))))


def simulate(
    motion: Motion,
    terrain=None,
    config: SimulationConfig = SimulationConfig(),
    feedforward: bool = True,
    torque_scale: float = 1.0,
) -> Rollout:
    """Run a motion in MuJoCo with the tracking controller and judge it.

    Args:
        motion: the motion (`make_motion` or `Motion.load`).
        terrain: a `Terrain`, or None for the motion's own terrain text.
        config: physics step, gains, success bounds.
        feedforward: add the motion's inverse-dynamics torques (False: PD alone).
        torque_scale: factor on every applied torque (0 leaves the robot limp).

    Returns:
        Rollout with one PhaseResult per phase of the motion.
    """
    import time as clock

    import mujoco

    from leas_jax.contacts.robot.model import load_talos
    from leas_jax.motion.robot import set_friction_solver, terrain_scene
    from leas_jax.terrain import loads_terrain

    started, cpu_started = clock.perf_counter(), clock.process_time()
    if terrain is None:
        terrain = loads_terrain(motion.terrain, source="<motion terrain>")
    mj = terrain_scene(terrain, config.timestep, config.mesh_contact)
    mj.model.opt.noslip_iterations = config.noslip_iterations
    set_friction_solver(mj.model, config.cone, config.impratio)
    talos = load_talos()
    model = mj.model
    data = mujoco.MjData(model)
    kp, kd = pd_gains(mj, talos, config)
    effort = mj.effort
    data.qpos[:] = mj.qpos_from_pin(motion.q[0])
    mujoco.mj_forward(model, data)
    sole_geoms = set(mj.sole_geoms)
    robot_geoms = set(mj.robot_geoms.tolist()) - sole_geoms
    results = [PhaseResult(p.kind, p.postures, p.swing) for p in motion.phases]
    stride = round(motion.dt / config.timestep)
    steps = (len(motion.q) - 1) * stride + round(config.settle / config.timestep)
    record_q, record_height, record_tilt = [], [], []
    anchors = [None, None]  # xy of each supporting sole at the start of its support phase
    phase_index, fall_time = 0, math.nan
    q_joint, dq_joint = mj.qpos_index, mj.dof_index
    actuators = mj.actuator_index
    joint_ratio = np.zeros(len(effort))
    landing = LandingCorrection(talos, motion) if config.landing_correction else None
    for step in range(steps + 1):
        position = min(step / stride, len(motion.q) - 1)
        sample = int(position)
        while phase_index < len(motion.phases) - 1 and sample >= motion.phases[phase_index].stop:
            _close_phase(results[phase_index], motion, phase_index, data, mj)
            phase_index += 1
            anchors = [None, None]
            if landing is not None:
                landing.begin(phase_index, data.site_xpos[list(mj.sole_sites), :2])
        result = results[phase_index]
        q_ref = _interpolate(motion.q[:, 7:], position)
        if landing is not None:
            q_ref = q_ref + landing.offset(phase_index, position)
        v_ref = _interpolate(motion.v[:, 6:], position)
        command = kp * (q_ref - data.qpos[q_joint]) + kd * (v_ref - data.qvel[dq_joint])
        if feedforward:
            command += _interpolate(motion.tau, position)
        command *= torque_scale
        ratio = np.abs(command) / effort
        np.maximum(joint_ratio, ratio, out=joint_ratio)
        result.torque_ratio = max(result.torque_ratio, float(ratio.max()))
        data.ctrl[actuators] = np.clip(command, -effort, effort)
        contact = motion.contact[min(sample + 1, len(motion.q) - 1)] & motion.contact[sample]
        for side in (0, 1):
            if contact[side]:
                xy = data.site_xpos[mj.sole_sites[side], :2].copy()
                if anchors[side] is None:
                    anchors[side] = xy
                result.slip = max(result.slip, float(np.linalg.norm(xy - anchors[side])))
            else:
                anchors[side] = None
        for c in range(data.ncon):
            pair = {int(data.contact[c].geom1), int(data.contact[c].geom2)}
            touching = pair & robot_geoms  # robot geoms collide with the terrain only
            if touching:
                result.other_contacts.extend(
                    model.geom(g).name or model.body(model.geom_bodyid[g]).name for g in touching
                )
        if step % stride == 0:
            supporting = [data.site_xpos[mj.sole_sites[s], 2] for s in (0, 1) if motion.contact[sample, s]]
            height = float(data.qpos[2] - max(supporting or [0.0]))
            tilt = _tilt(data.xmat[mj.root_body])
            record_q.append(mj.pin_from_qpos(data.qpos.copy()))
            record_height.append(height)
            record_tilt.append(tilt)
            if height < config.min_root_height or tilt > config.max_tilt:
                result.fallen = True
                fall_time = step * config.timestep
                break
        mujoco.mj_step(model, data)
    else:
        _close_phase(results[phase_index], motion, phase_index, data, mj)
    fallen = not math.isnan(fall_time)
    problems = [(i, p.problems(config)) for i, p in enumerate(results)]
    failing = [(i, reasons) for i, reasons in problems if reasons]
    if failing:
        index, reasons = failing[0]
        phase = motion.phases[index]
        message = f"{phase.describe(motion.dt)}: {'; '.join(reasons)}"
    else:
        message = f"{len(results)} phases executed, the robot stands at the end"
    return Rollout(
        success=not failing and not fallen,
        fallen=fallen,
        fall_time=fall_time,
        phases=results,
        time=np.arange(len(record_q)) * motion.dt,
        q=np.array(record_q),
        root_height=np.array(record_height),
        tilt=np.array(record_tilt),
        seconds=clock.perf_counter() - started,
        message=message,
        joint_torque_ratio=joint_ratio,
        cpu_seconds=clock.process_time() - cpu_started,
    )


class LandingCorrection:
    """Joint-reference offsets [32] that land each swing sole on its planned world placement.

    The tracked robot creeps: its supporting soles slide by tenths of a millimetre per phase
    (well under `max_slip`), the whole robot with them, and a swing leg that tracks its
    joint references lands its sole where the plan puts it relative to the stance sole, not
    in the world: on flat ground and on eval_stairs the landing error passes 3 cm after
    130-240 s of motion. At the start of every phase the supporting soles' horizontal
    offsets e (world, simulated minus the motion's reference) are read and each leg is
    given a sole offset t relative to the root for the phase's end:

    - double support: t = e - mean(e) (the legs agree with where the soles are: no
      internal force; the root rides at their mean offset);
    - single support: the stance leg t = 0 (the root rides with its sole), the swing leg
      t = -e_stance: its sole travels to, and lands on, its world placement.

    A leg's joints get dq = J^-1 [t, 0] (damped least squares), J [6, 6] the sole's
    Jacobian (position and orientation, world-aligned) over its six joints at the phase's
    last reference sample; the offsets move from the previous phase's on the minimum-jerk
    scaling. Orientation and height are not corrected.
    """

    # Damping of the least squares, m^2 (a landing knee near full stretch, on steps, makes
    # J nearly singular; the offsets are millimetres).
    DAMPING = 1e-3

    def __init__(self, talos, motion: Motion):
        self.talos = talos
        self.motion = motion
        self.data = talos.model.createData()
        self.legs_q = [np.asarray(leg.q_index) - 7 for leg in talos.legs]  # [6] joint indices
        self.legs_v = [np.asarray(leg.v_index) for leg in talos.legs]  # [6] velocity indices
        self.start = np.zeros((2, 6))  # per side: joint offset at the phase's start, rad
        self.target = np.zeros((2, 6))  # per side: joint offset at the phase's end, rad

    def begin(self, index: int, soles_xy: np.ndarray) -> None:
        """Phase `index` starts with the soles at soles_xy [2, 2] (world, simulated)."""
        import pinocchio as pin

        phase = self.motion.phases[index]
        offsets = np.asarray(soles_xy) - self.motion.feet[phase.start, :, :2]  # [2, 2]
        if phase.swing < 0:
            moves = offsets - offsets.mean(axis=0)
        else:
            moves = np.zeros((2, 2))
            moves[phase.swing] = -offsets[1 - phase.swing]
        model, data = self.talos.model, self.data
        pin.computeJointJacobians(model, data, self.motion.q[phase.stop])
        pin.updateFramePlacements(model, data)
        self.start = self.target.copy()
        for side in (0, 1):
            frame = self.talos.sole_frame_ids[side]
            jacobian = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)[:, self.legs_v[side]]
            move = np.r_[moves[side], 0.0, 0.0, 0.0, 0.0]
            self.target[side] = jacobian.T @ np.linalg.solve(
                jacobian @ jacobian.T + self.DAMPING * np.eye(6), move
            )

    def offset(self, index: int, position: float) -> np.ndarray:
        """The offset [32] (rad) added to the joint references at fractional sample `position`."""
        from leas_jax.motion.paths import min_jerk

        phase = self.motion.phases[index]
        fraction = min(max((position - phase.start) / max(phase.stop - phase.start, 1), 0.0), 1.0)
        s = float(min_jerk(np.array([fraction]))[0])
        out = np.zeros(32)
        for side in (0, 1):
            out[self.legs_q[side]] = self.start[side] + s * (self.target[side] - self.start[side])
        return out


def _close_phase(result: PhaseResult, motion: Motion, index: int, data, mj) -> None:
    """Mark a phase reached; after a landing, measure the sole against its planned placement."""
    from leas_jax.contacts.robot.model import matrix_from_quat_xyzw

    result.reached = True
    phase = motion.phases[index]
    if phase.kind != "land":
        return
    side = phase.swing
    planned = motion.plan_feet[phase.postures[1], side]
    site = mj.sole_sites[side]
    result.landing_position = float(np.linalg.norm(data.site_xpos[site] - planned[:3]))
    result.landing_angle = _angle_between(
        data.site_xmat[site].reshape(3, 3), matrix_from_quat_xyzw(planned[3:])
    )
