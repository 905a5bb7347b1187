"""Whole-body motions along contact plans: phases, task references, IK, dynamics and checks.

Host-only (Pinocchio, hpp-centroidal-dynamics), not jittable. `make_motion(plan, config)`
turns a `ContactPlan` (docs/design.md §6) into a `Motion`: Talos configurations every
`config.dt` seconds that pass through every key posture of the plan, at rest, in order.

Between consecutive postures k and k+1 (the plan changes at most one foot at a time):

- both feet down in both: one double-support **shift**: the CoM goes from posture k's
  to posture k+1's along a straight line, the root turns and the upper body moves from
  one posture's to the other's, all on one minimum-jerk time scaling;
- k in double support, k+1 on one foot: a **shift** to posture k+1's CoM, root and upper
  body with both feet still down, then a single-support **lift**: the swing sole leaves
  its placement along +z and reaches its place in posture k+1 (the plan's lifted foot),
  the CoM held over the stance sole;
- k on one foot, k+1 in double support: a single-support **land**: the swing sole
  rises to an apex above the terrain, travels and comes down along -z onto its new
  placement, the CoM held; then a **shift** to posture k+1.

The static equilibria of a fixed set of contacts form a convex set of CoM positions, so
a CoM moving straight between two of them stays in it. Every sample is then checked
(`check_motion`): joint position and velocity limits, equilibrium robustness with the
CoM's acceleration (hpp-centroidal-dynamics), joint torques from Pinocchio's rnea within
the URDF's effort limits, collisions with the terrain and between the legs and the body
(coal, as the verifier checks key postures; `clearance.BodyClearance`). Single supports are
made clear of the terrain by a margin and of themselves (`MotionConfig.body_clearance`), the
swing path bulging away from the stance leg where that needs it; the arms change between
half-sitting and held in where their way is clear (`upper_body_window`, `tucked_arms`).
"""

from __future__ import annotations

import dataclasses
import io
import itertools
import math
import os
from dataclasses import dataclass, field

import numpy as np

from leas_jax.contacts.plan import ContactPlan
from leas_jax.errors import LeasError
from leas_jax.motion.config import MotionConfig

SIDES = ("left", "right")
# Key-posture match: the IK's configuration at a key instant must equal the plan's within
# this (rad and m, Pinocchio's `difference`) before the plan's own is stored there.
KEY_POSTURE_TOL = 1e-6
# Keys of a motion file.
MOTION_KEYS = (
    "time",
    "q",
    "v",
    "a",
    "tau",
    "wrenches",
    "contact",
    "feet",
    "com",
    "key_index",
    "phase_kind",
    "phase_bounds",
    "phase_postures",
    "phase_swing",
    "plan_q",
    "plan_feet",
    "terrain",
    "dt",
)
PHASE_KINDS = ("shift", "lift", "land")
# Single support: the root comes down at most this far, m, for the swing sole to reach its
# contact (`held_root_support`), found by steps of DIP_SCAN, m.
MAX_DIP = 0.30
DIP_SCAN = 0.01
# ... or rises at most this far, m, where no lowering lets a leg reach its sole: crouched
# plans (navigate's on eval_bridge, knees at 1.4-1.7 rad) lift a swing sole behind the root
# with its ankle past its -1.31 rad pitch limit; a higher root unbends that leg.
MAX_RISE = 0.15
# ... and where the height is chosen sample by sample (`reach_interval`), up to this far up,
# m: its smoothing must leave room above a needed rise (rubble_0's landing 75 -> 76 needs
# 0.139 m in mid-swing; capped at MAX_RISE, the profile kinked there at 12 m/s^2).
MAX_PROFILE_RISE = 0.3
# Single-support configurations keep their leg joints this far inside their limits where
# that works (else none), rad: the whole-body IK tracks their CoM, not their root, and ends
# a few mrad off them (measured on eval_bridge's crouched plans: an ankle 0.1 mrad past).
LIMIT_MARGIN = 0.03
# A root height chosen sample by sample (`dip_profile`) keeps up to this far, m, inside what
# reaches where there is room: its smoothing then stays off the corners of those bounds (a
# corner followed exactly gave rubble_0's landing 75 -> 76 a 12 m/s^2 vertical CoM
# acceleration). The inset is this times the contact weight, 0 at the key posture: where a bound
# passes through the key posture's root (legs stretched to their reach), a full inset forced a
# 5 mm step at the first sample off it, 50 m/s^2 at any duration, so that lengthening the phase
# for its acceleration never ended (rubble_1's lift 140 -> 141: 554 -> 5 080 samples).
DIP_INSET = 0.005
# A phase's root height profile is solved at most at this many samples and interpolated
# between them (`dip_profile`): 1.6 s of a phase at 100 Hz, twice the landing's nominal 0.8 s.
PROFILE_KNOTS = 161
# A single-support phase is lengthened at most this many times for its CoM's acceleration
# (`_single_support`; one is enough where its references scale with its duration, the next
# ones take up the samples' rounding).
STRETCHES = 4
# ... and for its joints' speed: the configurations its CoM references come from (the root held
# or profiled, `held_root_support`) keep each joint within this fraction of its velocity limit
# (times `MotionConfig.velocity_ratio`). The whole-body IK tracks their CoM, not their root,
# and ends close to them; a crouched swing leg unbends fast in the landing's descent (circuit_0:
# the right knee from 1.76 to 0.30 rad in 0.32 s, -7.2 rad/s where its limit is 7).
SPEED_MARGIN = 0.9
# Root shifts tried in single support where no height profile reaches (`shifted_support`):
# multiples of this, m, up to `MotionConfig.root_shift`.
ROOT_SHIFT_STEP = 0.02
# Index in a configuration [39] of the upper body's first joint (torso, arms, grippers, head):
# 7 for the free flyer, 12 for the legs.
UPPER_BODY = 19
# Bulges of a single support's swing path away from the stance sole, (m, held), tried in turn
# where its configurations collide (`_single_support_coms`): a bump over the travel window
# (a swing foot passing the stance shin on a stair: eval_stairs_0's landing 89 -> 90, cleared
# by the 4 cm one), then a bulge held out while the legs pass (`paths.HELD_BULGES`: on
# eval_bridge's beam a bump leaves the shins and knees in contact), its phase lengthened for
# `MotionConfig.bulge_acceleration`. Held out within the phase's own duration, the swing
# leg's sideways swing took the stance ankle or hip roll to 1.07-1.08 x its effort limit
# (docs/results/2026-12-06-motion-clearance; slowed: docs/results/2026-12-06-motion-held-bulge).
SWING_BULGES = ((0.04, False), (0.08, False), (0.04, True), (0.07, True), (0.10, True))
# The arms change between key postures over this fraction of a shift, at its start or end
# (`upper_body_window`), the shift lengthened where their joints' speed needs it.
UPPER_BODY_SPLIT = 0.5
# Where no span of a shift clears their way, the change moves at most this many postures
# earlier or later (`tucked_arms`).
ARM_CHANGE_REACH = 4
# Detours of an arm whose samples in a phase meet the terrain or the body (`detoured_phase`):
# offsets, rad, of the shoulder pitch (arm_X_1), the shoulder roll outwards (arm_X_2) and the
# elbow (arm_X_4, negative bends it), reached at mid-phase and gone at both ends
# (`detour_profile`), so every key posture stays the plan's. Tried in this order, the fewest
# joints and the smallest offsets first, the first whose phase collides nowhere kept. The key
# postures may hold a gripper millimetres from the terrain (slalom_debris_0's 35: 4.8 mm from a
# debris tile) and the root's travel in a shift sweeps it in: there the right shoulder pitches
# back (0.24 rad, at its limit); on talos_stairs15_0 both elbows bend 1 rad where the thighs
# meet the held-in grippers, and beside the stair's wall the right shoulder rolls out 0.6 rad
# with the elbow bent 0.5 (docs/results/2026-12-07-motion-arm-detours/diagnose.txt).
ARM_DETOURS = tuple(
    sorted(
        (
            d
            for d in itertools.product((0.0, -0.4, 0.4, -0.8, 0.8), (0.0, 0.3, 0.6), (0.0, -0.5, -1.0))
            if any(d)
        ),
        key=lambda d: (sum(1 for x in d if x), sum(abs(x) for x in d)),
    )
)


class MotionError(LeasError):
    """A motion cannot be made (or read): the message names the phase and why."""


@dataclass(frozen=True)
class Phase:
    """One phase of a motion.

    Attributes:
        kind: "shift" (double support, CoM moves), "lift" or "land" (single support).
        start: sample index where the phase starts (the previous phase's last sample).
        stop: sample index where it ends, > start.
        postures: (k, k + 1) plan postures the phase goes between.
        swing: side in the air (0 left, 1 right), -1 in double support.
    """

    kind: str
    start: int
    stop: int
    postures: tuple
    swing: int

    @property
    def single_support(self) -> bool:
        return self.swing >= 0

    def describe(self, dt: float) -> str:
        """One line: kind, postures and time span."""
        foot = f", {SIDES[self.swing]} foot in the air" if self.swing >= 0 else ""
        return (
            f"{self.kind} between postures {self.postures[0]} and {self.postures[1]}{foot} "
            f"(t = {self.start * dt:.2f}-{self.stop * dt:.2f} s)"
        )


@dataclass(frozen=True, eq=False)
class Motion:
    """A whole-body motion of Talos sampled every `dt` seconds, world frame.

    Attributes:
        time: [N] s, from 0.
        q: [N, 39] Pinocchio configurations (root xyz + quaternion xyzw, 32 joints).
        v: [N, 38] velocities (root linear and angular in the base_link frame, joints).
        a: [N, 38] accelerations, same frames.
        tau: [N, 32] joint torques from inverse dynamics, N m, Pinocchio joint order.
        wrenches: [N, 2, 6] planned (force, torque) at each sole frame, sole frame, N and N m.
        contact: [N, 2] bool, sole in support (left, right).
        feet: [N, 2, 7] reference sole placements (xyz + quaternion xyzw), world; the
            swing sole's moves along its path.
        com: [N, 3] CoM, world, m.
        key_index: [K] sample index of each plan posture (q[key_index] == plan.q, except at
            the moved_keys).
        phases: tuple of Phase, in time order.
        plan_q: [K, 39], plan_feet: [K, 2, 7]: the plan's postures and placements.
        terrain: the terrain file's text.
        dt: sampling period, s.
        moved_keys: [J] plan postures reached otherwise: with their CoM moved inside the support
            polygon (`MotionConfig.support_margin`, `centred_postures`: same soles, root
            orientation and upper body, another root position and leg joints), or with the
            arms of a neighbour where the arms' change moved (`tucked_arms`: same contacts,
            root and legs).
    """

    time: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    wrenches: np.ndarray
    contact: np.ndarray
    feet: np.ndarray
    com: np.ndarray
    key_index: np.ndarray
    phases: tuple
    plan_q: np.ndarray
    plan_feet: np.ndarray
    terrain: str
    dt: float
    moved_keys: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    failures: list = field(default_factory=list)

    @property
    def duration(self) -> float:
        """Length of the motion, s."""
        return float(self.time[-1])

    def phase_at(self, sample: int) -> int:
        """Index of the phase holding sample index `sample` (phases own (start, stop])."""
        for index, phase in enumerate(self.phases):
            if sample <= phase.stop:
                return index
        return len(self.phases) - 1

    def save(self, path) -> None:
        """Write the motion as an .npz with the keys of MOTION_KEYS, atomically."""
        from leas_jax.files import atomic_write_bytes

        buffer = io.BytesIO()
        np.savez(
            buffer,
            time=self.time,
            q=self.q,
            v=self.v,
            a=self.a,
            tau=self.tau,
            wrenches=self.wrenches,
            contact=self.contact,
            feet=self.feet,
            com=self.com,
            key_index=self.key_index,
            phase_kind=np.array([PHASE_KINDS.index(p.kind) for p in self.phases], dtype=np.int64),
            phase_bounds=np.array([(p.start, p.stop) for p in self.phases], dtype=np.int64).reshape(-1, 2),
            phase_postures=np.array([p.postures for p in self.phases], dtype=np.int64).reshape(-1, 2),
            phase_swing=np.array([p.swing for p in self.phases], dtype=np.int64),
            plan_q=self.plan_q,
            plan_feet=self.plan_feet,
            terrain=np.str_(self.terrain),
            dt=np.float64(self.dt),
            moved_keys=np.asarray(self.moved_keys, dtype=np.int64),
        )
        atomic_write_bytes(os.fspath(path), buffer.getvalue())

    @classmethod
    def load(cls, path) -> Motion:
        """Read a motion written by `save`.

        Raises:
            MotionError: not a motion file, a key missing or arrays of the wrong shape.
        """
        import zipfile

        try:
            data = np.load(path, allow_pickle=False)
        except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
            raise MotionError(f"{path}: not a readable motion file ({type(exc).__name__}: {exc})") from None
        with data:
            if not isinstance(data, np.lib.npyio.NpzFile):
                raise MotionError(f"{path}: a single .npy array, expected a motion .npz")
            missing = [key for key in MOTION_KEYS if key not in data.files]
            if missing:
                raise MotionError(f"{path}: missing key '{missing[0]}' (not a motion file?)")
            arrays = {key: data[key] for key in MOTION_KEYS}
            # files written before key postures were moved have no moved_keys: none moved
            moved = data["moved_keys"] if "moved_keys" in data.files else np.zeros(0, dtype=np.int64)
        n = len(arrays["time"])
        shapes = {
            "q": (n, 39),
            "v": (n, 38),
            "a": (n, 38),
            "tau": (n, 32),
            "wrenches": (n, 2, 6),
            "contact": (n, 2),
            "feet": (n, 2, 7),
            "com": (n, 3),
        }
        for key, shape in shapes.items():
            if arrays[key].shape != shape:
                raise MotionError(
                    f"{path}: key '{key}' has shape {list(arrays[key].shape)}, expected {list(shape)}"
                )
        if n < 2 or not np.isfinite(arrays["q"]).all():
            raise MotionError(f"{path}: key 'q' must hold at least 2 finite configurations")
        phases = tuple(
            Phase(
                PHASE_KINDS[int(kind)],
                int(bounds[0]),
                int(bounds[1]),
                tuple(int(p) for p in postures),
                int(swing),
            )
            for kind, bounds, postures, swing in zip(
                arrays["phase_kind"], arrays["phase_bounds"], arrays["phase_postures"], arrays["phase_swing"]
            )
        )
        return cls(
            time=arrays["time"],
            q=arrays["q"],
            v=arrays["v"],
            a=arrays["a"],
            tau=arrays["tau"],
            wrenches=arrays["wrenches"],
            contact=arrays["contact"].astype(bool),
            feet=arrays["feet"],
            com=arrays["com"],
            key_index=arrays["key_index"],
            phases=phases,
            plan_q=arrays["plan_q"],
            plan_feet=arrays["plan_feet"],
            terrain=str(arrays["terrain"]),
            dt=float(arrays["dt"]),
            moved_keys=np.asarray(moved, dtype=np.int64).reshape(-1),
        )


@dataclass(frozen=True)
class _PhaseSpec:
    """A phase's task references at its two ends (world frame) before sampling.

    Attributes:
        kind, postures, swing: as in Phase.
        samples: number of samples (duration / dt).
        feet0, feet1: [2, 4, 4] sole placements at the start and end.
        com0, com1: [3] CoM at the start and end.
        rot0, rot1: [3, 3] root orientation at the start and end.
        upper0, upper1: [39] configurations whose upper-body joints are used.
        apex: m, height of the swing sole's path (`paths.swing_path`; NaN in a shift).
        coms: [samples, 3] CoM references of samples 1..n (single support), or None: straight
            from com0 to com1.
        upper_window: (t0, t1), the span of normalised time over which the upper body goes
            from upper0's to upper1's (`upper_body_window`).
        swing_offset: m, the swing sole's path bulges this far away from the stance sole
            (`swing_feet`); swing_held: the bulge held out while the legs pass, not a bump.
        upper_detour: [39] offsets of the upper-body joints reached at mid-phase
            (`detour_profile`; zero elsewhere), or None: none (`detoured_phase`).
    """

    kind: str
    postures: tuple
    swing: int
    samples: int
    feet0: np.ndarray
    feet1: np.ndarray
    com0: np.ndarray
    com1: np.ndarray
    rot0: np.ndarray
    rot1: np.ndarray
    upper0: np.ndarray
    upper1: np.ndarray
    apex: float
    coms: np.ndarray | None = None
    upper_window: tuple = (0.0, 1.0)
    swing_offset: float = 0.0
    swing_held: bool = False
    upper_detour: np.ndarray | None = None


def _homogeneous(placement: np.ndarray) -> np.ndarray:
    """[4, 4] of a placement [7] (xyz + quaternion xyzw)."""
    from leas_jax.contacts.robot.model import matrix_from_quat_xyzw

    out = np.eye(4)
    out[:3, :3] = matrix_from_quat_xyzw(placement[3:])
    out[:3, 3] = placement[:3]
    return out


def _placement(homogeneous: np.ndarray) -> np.ndarray:
    """[7] xyz + quaternion xyzw of a [4, 4] placement."""
    from leas_jax.contacts.robot.model import quat_xyzw_from_matrix

    return np.r_[homogeneous[:3, 3], quat_xyzw_from_matrix(homogeneous[:3, :3])]


def posture_frames(talos, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sole placements [2, 4, 4], CoM [3] and root rotation [3, 3] of a configuration q [39]."""
    import pinocchio as pin

    data = talos.model.createData()
    pin.framesForwardKinematics(talos.model, data, q)
    feet = np.array([data.oMf[f].homogeneous for f in talos.sole_frame_ids])
    com = np.array(pin.centerOfMass(talos.model, data, q, False))
    return feet, com, np.array(data.oMi[1].rotation)


def _contacts(plan: ContactPlan, k: int) -> np.ndarray:
    """[2] bool: soles in contact at plan posture k."""
    return ~np.isnan(plan.feet[k, :, 0])


def held_root_configuration(
    talos,
    q: np.ndarray,
    feet: np.ndarray,
    rotation: np.ndarray,
    offset: np.ndarray,
    knees: np.ndarray,
    margin: float = 0.0,
) -> np.ndarray | None:
    """q [39] with its root moved by offset [3] (world, m) and turned to rotation [3, 3]
    (world_R_base_link), both soles at feet [2, 4, 4] (world); or None.

    The upper body stays as in q; each leg's six joints come from the analytic leg IK
    (`contacts.robot.ik.leg_ik_single`). None when a leg cannot reach its sole, comes within
    `margin` (rad) of its joint limits, or bends its knee less than knees [2] (rad, left and right).
    """
    from leas_jax.contacts.robot.ik import leg_ik_single
    from leas_jax.contacts.robot.model import quat_xyzw_from_matrix

    out = np.array(q, dtype=np.float64)
    out[:3] += offset
    for side, leg in enumerate(talos.legs):
        sole = feet[side]
        # the sole in the root frame (the root's inverse is its rotation's transpose)
        joints = leg_ik_single(leg, rotation.T @ sole[:3, :3], rotation.T @ (sole[:3, 3] - out[:3]))
        if joints is None or joints[3] < knees[side] - 1e-9:
            return None
        if margin > 0.0:
            lower = talos.model.lowerPositionLimit[leg.q_index] + margin
            upper = talos.model.upperPositionLimit[leg.q_index] - margin
            if ((joints < lower) | (joints > upper)).any():
                return None
        out[leg.q_index] = joints
    out[3:7] = quat_xyzw_from_matrix(rotation)  # only where both legs reach: the searches' cost
    return out


def root_dip(
    talos,
    q: np.ndarray,
    feet: np.ndarray,
    rotation: np.ndarray,
    shift: np.ndarray,
    knees: np.ndarray,
    direction: float = 1.0,
    margin: float = 0.0,
) -> float:
    """Smallest lowering (m, within 1e-7) of q's root, moved horizontally by shift [2] and turned
    to rotation [3, 3], for which `held_root_configuration` places both soles at feet [2, 4, 4];
    NaN when none up to MAX_DIP does. direction -1: the smallest rise instead, up to MAX_RISE;
    margin: rad the leg joints keep inside their limits.

    The lowerings that work form an interval (the legs reach from its low end and leave
    their joint limits past its high end): a 1 cm scan finds it, bisection its low end.
    """

    def works(dip: float) -> bool:
        offset = np.r_[shift, -direction * dip]
        return held_root_configuration(talos, q, feet, rotation, offset, knees, margin) is not None

    if works(0.0):
        return 0.0
    scan = np.arange(1, round((MAX_DIP if direction > 0 else MAX_RISE) / DIP_SCAN) + 1) * DIP_SCAN
    found = next((d for d in scan if works(d)), None)
    if found is None:
        return float("nan")
    low, high = found - DIP_SCAN, found
    while high - low > 1e-7:
        middle = 0.5 * (low + high)
        low, high = (low, middle) if works(middle) else (middle, high)
    return high


def contact_weight(samples: int, lifting: bool) -> np.ndarray:
    """[samples] weight of a single-support phase's contact end: the minimum-jerk scaling s of
    its normalised time (landing: s, its contact at the end) or 1 - s (lift: its contact at
    the start); 0 at the key posture, with zero derivatives at both ends."""
    from leas_jax.motion.paths import min_jerk

    scaling = min_jerk(np.arange(samples) / (samples - 1))
    return 1.0 - scaling if lifting else scaling


def dip_depth(needs: np.ndarray, weight: np.ndarray) -> float:
    """Smallest depth (m) with depth x weight [M] >= needs [M] (`root_dip`) at every sample;
    0 when nothing needs lowering, inf when a sample of weight 0 (the key posture) does."""
    if not (needs > 0.0).any():
        return 0.0
    positive = weight > 1e-12
    if (needs[~positive] > 0.0).any():
        return float("inf")
    return float(np.max(needs[positive] / weight[positive]))


def single_support_schedule(talos, q: np.ndarray, feet: np.ndarray, swing: int, lifting: bool, config):
    """What a single-support phase's samples share: (contact weight [M], least knee bends
    [M, 2] (rad; the key posture's bend where under `config.min_knee`, eased to it as the
    weight falls), the unit horizontal direction [2] along the stance sole towards the swing
    sole at contact, world).

    Arguments as `held_root_support`.
    """
    weight = contact_weight(len(feet), lifting)
    bent = np.array([q[leg.q_index[3]] for leg in talos.legs])
    knees = config.min_knee - np.maximum(config.min_knee - bent, 0.0) * (1.0 - weight[:, None])  # [M, 2]
    contact = feet[0 if lifting else -1]
    ahead = contact[1 - swing][:2, 0] / max(float(np.linalg.norm(contact[1 - swing][:2, 0])), 1e-9)
    toward = np.sign(ahead @ (contact[swing][:2, 3] - contact[1 - swing][:2, 3])) * ahead
    return weight, knees, toward


def held_root_support(
    talos,
    q: np.ndarray,
    feet: np.ndarray,
    rotations: np.ndarray,
    swing: int,
    lifting: bool,
    config,
    admissible=None,
) -> tuple[np.ndarray, np.ndarray]:
    """CoM references [M, 3] (world, m) of a single-support phase's samples 0..M-1, and the
    configurations [M, 39] they are taken from.

    q [39]: the phase's one-foot key posture; feet [M, 2, 4, 4]: the soles' references;
    rotations [M, 3, 3]: the root's orientation references.

    The root keeps the key posture's position where both legs reach their soles with their
    knees bent by `config.min_knee` (or, at the key posture, by as much as it bends them,
    and in between by a blend on `contact_weight`: the plan stretches its postures' legs
    to within a millimetre of their reach, knees at 0.05 rad, on steps). Where they do
    not, the root moves `config.lean` m along the stance sole (its x axis, horizontal)
    towards the swing sole's contact (the sole is 0.20 m long, 0.13 m wide) and
    comes down by the smallest depth that lets every sample's soles be reached, both
    weighted by `contact_weight` (`held_root_configuration`, `root_dip`, `dip_depth`). The
    CoM's height is that of those configurations; its horizontal position goes from the
    first's to the last's on the minimum-jerk scaling (the root moves to make up for the
    swing leg's mass, as in double support).

    Where no lowering lets both legs reach (crouched postures lift a swing sole behind the
    root with its ankle at its pitch limit), the root rises instead, by the smallest height
    up to MAX_RISE, on the same weight, and the CoM follows those configurations' own
    (no blend: the whole-body IK then reproduces their roots, whose ankles keep their margin;
    measured on eval_bridge, the blend put an ankle past its limit). Leg joints stay
    LIMIT_MARGIN inside their limits where that works.

    admissible: configurations [M, 39] -> why they cannot be taken, or None (`_clear_of_terrain`);
    None: any are.

    Raises:
        MotionError: the soles are out of the legs' reach even MAX_DIP lower or MAX_RISE higher,
            or `admissible` refuses the configurations.
    """
    import pinocchio as pin

    from leas_jax.motion.paths import lerp, min_jerk

    weight, knees, toward = single_support_schedule(talos, q, feet, swing, lifting, config)
    data = talos.model.createData()

    def attempt(margin: float) -> tuple[np.ndarray, np.ndarray]:
        """CoMs [M, 3] of the held-root configurations [M, 39] with leg joints `margin` rad inside
        their limits, and those configurations (MotionError: none)."""
        shifts = np.zeros((len(feet), 2))
        needs = np.array(
            [root_dip(talos, q, *sample, margin=margin) for sample in zip(feet, rotations, shifts, knees)]
        )
        if (needs > 0.0).any():
            shifts = config.lean * weight[:, None] * toward
            needs = np.array(
                [root_dip(talos, q, *sample, margin=margin) for sample in zip(feet, rotations, shifts, knees)]
            )
        sign = 1.0
        if np.isnan(needs).any():  # no lowering works: a rise may (crouched postures)
            rises = np.array(
                [
                    root_dip(talos, q, *sample, direction=-1.0, margin=margin)
                    for sample in zip(feet, rotations, shifts, knees)
                ]
            )
            if np.isnan(rises).any():
                sample = int(np.flatnonzero(np.isnan(needs))[0])
                raise MotionError(
                    f"at sample {sample} the soles are out of the legs' reach even with the root {MAX_DIP:g} m "
                    f"lower or {MAX_RISE:g} m higher"
                )
            needs, sign = rises, -1.0
        depth = sign * dip_depth(needs, weight)
        if not -MAX_RISE <= depth <= MAX_DIP:
            move = (
                f"come down {depth:.3f} m (at most {MAX_DIP:g} m)"
                if depth > 0
                else (f"rise {-depth:.3f} m (at most {MAX_RISE:g} m)")
            )
            raise MotionError(f"the root would have to {move} for the soles to reach")
        coms = np.empty((len(feet), 3))
        configurations = np.empty((len(feet), len(q)))
        for i, (f, shift) in enumerate(zip(feet, shifts)):
            offset = np.r_[shift, -depth * weight[i]]
            configuration = held_root_configuration(talos, q, f, rotations[i], offset, knees[i], margin)
            if configuration is None:
                raise MotionError(f"at sample {i} the soles are out of the legs' reach with the root lowered")
            coms[i] = pin.centerOfMass(talos.model, data, configuration, False)
            configurations[i] = configuration
        if sign > 0:
            coms[:, :2] = lerp(coms[0, :2], coms[-1, :2], min_jerk(np.arange(len(feet)) / (len(feet) - 1)))
        refused = admissible(configurations) if admissible else None
        if refused:
            raise MotionError(refused)
        return coms, configurations

    try:  # leg joints kept LIMIT_MARGIN inside their limits where that works
        return attempt(LIMIT_MARGIN)
    except MotionError:
        return attempt(0.0)


def profiled_support(
    talos,
    q: np.ndarray,
    feet: np.ndarray,
    rotations: np.ndarray,
    swing: int,
    lifting: bool,
    config,
    admissible=None,
) -> tuple[np.ndarray, np.ndarray]:
    """CoM references [M, 3] (world, m), and the configurations [M, 39] they are taken from, of
    a single-support phase's samples 0..M-1 whose root
    height is chosen sample by sample: where no single depth on the contact weight reaches
    every sample (`held_root_support` fails: the swing leg needs the root high at one sample
    and low at another, or a rise over MAX_RISE close to the key posture).

    Arguments as `held_root_support`. The root keeps the key posture's horizontal position
    (else moved `config.lean` along the stance sole, as there); its lowering at each sample
    lies inside what reaches (`reach_interval`, leg joints LIMIT_MARGIN inside their limits,
    else 0), the smoothest such profile at rest at both ends (`dip_profile`). The CoM is that
    of those configurations (no blend: the whole-body IK reproduces their roots).

    Raises:
        MotionError: some sample's soles are out of reach at every height, `admissible` (as
            `held_root_support`) refuses what reaches, or `config.profiled_reach` is off.
    """
    import pinocchio as pin

    if not config.profiled_reach:
        raise MotionError("the root's height is not chosen sample by sample (MotionConfig.profiled_reach)")
    weight, knees, toward = single_support_schedule(talos, q, feet, swing, lifting, config)
    data = talos.model.createData()
    lean = config.lean * weight[:, None] * toward
    unreached, refused = 0, None
    for shifts, margin in itertools.product((np.zeros((len(feet), 2)), lean), (LIMIT_MARGIN, 0.0)):
        configurations, unreached = profiled_configurations(
            talos, q, feet, rotations, shifts, knees, weight, margin
        )
        if configurations is None:
            continue
        refused = admissible(configurations) if admissible else None
        if not refused:
            return np.array(
                [pin.centerOfMass(talos.model, data, c, False) for c in configurations]
            ), configurations
    if refused:
        raise MotionError(refused)
    raise MotionError(
        f"at sample {unreached} the soles are out of the legs' reach at every root height from "
        f"{MAX_PROFILE_RISE:g} m higher to {MAX_DIP:g} m lower"
    )


def profiled_configurations(
    talos, q: np.ndarray, feet, rotations, shifts, knees, weight: np.ndarray, margin: float
) -> tuple[np.ndarray | None, int]:
    """Configurations [M, 39] of a single-support phase's samples with q's root moved
    horizontally by shifts [M, 2] (world, m) and lowered along the least-jerk profile inside
    what reaches (`reach_intervals`, `dip_profile`), or None; and the first sample found out
    of reach (0 when none is).

    feet [M, 2, 4, 4], rotations [M, 3, 3], knees [M, 2], margin: as `held_root_configuration`;
    weight [M]: `contact_weight` (its samples under 1e-3, around the key posture, keep the root
    at the key posture's height, which must reach).
    """
    low, high, out_of_reach = reach_intervals(talos, q, feet, rotations, shifts, knees, margin)
    if out_of_reach is not None:
        return None, out_of_reach
    key = weight < 1e-3
    if (low[key] > 0.0).any() or (high[key] < 0.0).any():
        return None, int(np.flatnonzero(key & ((low > 0.0) | (high < 0.0)))[0])
    offsets = np.c_[shifts, -dip_profile(low, high, weight)]
    configurations = [
        held_root_configuration(talos, q, *sample, margin) for sample in zip(feet, rotations, offsets, knees)
    ]
    if any(c is None for c in configurations):  # a gap inside a bisected interval
        return None, next(i for i, c in enumerate(configurations) if c is None)
    return np.array(configurations), 0


def shift_candidates(longest: float, step: float, toward: np.ndarray) -> np.ndarray:
    """Horizontal root shifts [C, 2] (world, m) of `shifted_support`, shortest first: none, then
    every multiple of `step` up to `longest` in 8 directions 45 deg apart, those of one length
    in decreasing alignment with toward [2] (a unit vector, world)."""
    lengths = np.arange(1, math.floor(longest / step + 1e-9) + 1) * step
    angles = np.arange(8) * (np.pi / 4)
    directions = np.c_[np.cos(angles), np.sin(angles)]
    directions = directions[np.argsort(-(directions @ toward), kind="stable")]
    return np.r_[np.zeros((1, 2)), (lengths[:, None, None] * directions[None]).reshape(-1, 2)]


def shifted_support(
    talos,
    q: np.ndarray,
    feet: np.ndarray,
    rotations: np.ndarray,
    swing: int,
    lifting: bool,
    config,
    admissible=None,
) -> tuple[np.ndarray, np.ndarray]:
    """CoM references [M, 3] (world, m), and the configurations [M, 39] they are taken from, of
    a single-support phase whose root moves horizontally, where no height profile over the
    key posture's horizontal position reaches (`profiled_support` fails: a wide or long step
    lands or lifts a sole beyond the legs' reach, or past the hip and ankle roll limits, from
    a root held over the stance sole).

    Arguments as `held_root_support`. The root moves by a shift s (horizontal, world) times
    the contact weight (0 at the key posture, s at the contact end), its height along the
    least-jerk profile inside what reaches (`profiled_configurations`); the shifts tried are
    `shift_candidates` up to `config.root_shift`, none first, each with leg joints
    LIMIT_MARGIN inside their limits, then 0; a shift is profiled only where its contact end
    alone reaches with the CoM inside at the height nearest the key posture's. The first
    whose CoM stays at least
    `config.single_support_margin` inside the stance sole at every sample (or as far as the
    key posture's own, where that is less: the plan's one-foot postures may stand 2.96 cm
    inside, hpp_rubble_1's 165) is taken (the
    upper body moves with the root, so the CoM moves with it). The CoM is that of those
    configurations (the whole-body IK reproduces their roots). Configurations that
    `admissible` (as `held_root_support`) refuses are passed over.

    Raises:
        MotionError: no shift up to `config.root_shift` does (or it is 0).
    """
    import pinocchio as pin

    if config.root_shift <= 0.0:
        raise MotionError("the root does not move horizontally in single support (MotionConfig.root_shift)")
    weight, knees, toward = single_support_schedule(talos, q, feet, swing, lifting, config)
    stance = sole_corners(feet[0], np.arange(2) != swing)
    data = talos.model.createData()
    key = support_margins(stance, pin.centerOfMass(talos.model, data, q, False)[None, :2])[0]
    inside = min(config.single_support_margin, key - 1e-6)  # never less than the key posture's own
    best = (-np.inf, None)  # (the CoM's least margin over the phase, shift) of the shifts that reach
    refused = None  # why `admissible` refused the last shift that kept the CoM inside
    end = 0 if lifting else len(feet) - 1  # the contact end, where the root is shifted most
    for shift, margin in itertools.product(
        shift_candidates(config.root_shift, ROOT_SHIFT_STEP, toward), (LIMIT_MARGIN, 0.0)
    ):
        # first the contact end alone (a whole phase's profile costs its length in such
        # searches): its soles reached, its CoM inside at the height nearest the key posture's
        low, high = reach_interval(talos, q, feet[end], rotations[end], shift, knees[end], margin)
        if np.isnan(low):
            continue
        offset = np.r_[shift, -min(max(0.0, low), high)]
        configuration = held_root_configuration(
            talos, q, feet[end], rotations[end], offset, knees[end], margin
        )
        if configuration is None:
            continue
        com = pin.centerOfMass(talos.model, data, configuration, False)
        at_end = float(support_margins(stance, com[None, :2])[0])
        if at_end < inside:
            best = max(best, (at_end, tuple(np.round(shift, 3))))
            continue
        configurations, _ = profiled_configurations(
            talos, q, feet, rotations, weight[:, None] * shift, knees, weight, margin
        )
        if configurations is None:
            continue
        coms = np.array([pin.centerOfMass(talos.model, data, c, False) for c in configurations])
        least = float(support_margins(stance, coms[:, :2]).min())
        if least < inside:
            best = max(best, (least, tuple(np.round(shift, 3))))
            continue
        refused = admissible(configurations) if admissible else None
        if not refused:
            return coms, configurations
    found = (
        f"; the best, a {np.hypot(*best[1]):.2f} m shift, keeps it {best[0] * 100:.1f} cm inside"
        if best[1] is not None
        else ""
    )
    if refused:
        found += f"; every shift that keeps it inside is refused, the last: {refused}"
    raise MotionError(
        f"no root shift up to {config.root_shift:g} m keeps the CoM {inside * 100:.3g} cm "
        f"inside the stance sole with the soles in reach{found}"
    )


def reach_intervals(
    talos, q: np.ndarray, feet, rotations, shifts, knees, margin: float, stride: int = 10
) -> tuple[np.ndarray, np.ndarray, int | None]:
    """`reach_interval` of each sample of a phase (feet [M, 2, 4, 4], rotations [M, 3, 3],
    shifts [M, 2], knees [M, 2]): (low [M], high [M], m; the first sample found out of reach,
    or None).

    Every `stride`-th sample is tried first and the search stops at the first sample out of
    reach (its interval and every one not searched NaN): a phase that cannot be made fails
    after a tenth of the searches instead of all of them (each is some 60 inverse-kinematics
    solves).
    """
    count = len(feet)
    order = np.r_[np.arange(0, count, stride), np.setdiff1d(np.arange(count), np.arange(0, count, stride))]
    intervals = np.full((count, 2), np.nan)
    for i in order:
        intervals[i] = reach_interval(talos, q, feet[i], rotations[i], shifts[i], knees[i], margin)
        if np.isnan(intervals[i, 0]):
            return intervals[:, 0], intervals[:, 1], int(i)
    return intervals[:, 0], intervals[:, 1], None


def reach_interval(
    talos,
    q: np.ndarray,
    feet: np.ndarray,
    rotation: np.ndarray,
    shift: np.ndarray,
    knees: np.ndarray,
    margin: float = 0.0,
) -> tuple[float, float]:
    """Lowest and highest lowering (m, within 1e-5; negative: a rise) of q's root, moved
    horizontally by shift [2] and turned to rotation [3, 3], for which `held_root_configuration`
    places both soles at feet [2, 4, 4] (knees [2], margin: as there); within MAX_PROFILE_RISE
    up and MAX_DIP down; (NaN, NaN) when none does.

    The lowerings that work form an interval (`root_dip`): a DIP_SCAN scan finds the first run
    of them, bisection both its ends.
    """

    def works(dip: float) -> bool:
        offset = np.r_[shift, -dip]
        return held_root_configuration(talos, q, feet, rotation, offset, knees, margin) is not None

    scan = np.arange(-round(MAX_PROFILE_RISE / DIP_SCAN), round(MAX_DIP / DIP_SCAN) + 1) * DIP_SCAN
    good = np.array([works(d) for d in scan])
    if not good.any():
        return float("nan"), float("nan")
    first = int(np.argmax(good))
    last = first + int(np.argmin(np.r_[good[first:], False])) - 1

    def edge(inside: float, outside: float) -> float:
        while abs(outside - inside) > 1e-5:
            middle = 0.5 * (inside + outside)
            inside, outside = (middle, outside) if works(middle) else (inside, middle)
        return inside

    low = scan[first] if first == 0 else edge(scan[first], scan[first - 1])
    high = scan[last] if last == len(scan) - 1 else edge(scan[last], scan[last + 1])
    return float(low), float(high)


def dip_profile(low: np.ndarray, high: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """Root lowerings [M] (m) of a single-support phase's samples, each inside [low_i, high_i]
    ([M] each, m; negative: a rise), with the least squared third differences (the least jerk:
    the acceleration grows from 0 where the root leaves its rest; a tiny pull towards 0 breaks
    ties) by bounded least squares.

    The bounds are narrowed by DIP_INSET x the contact weight on each side where they leave
    room (their middle where they do not); samples of contact weight [M] (`contact_weight`)
    under 1e-3, around the key posture, keep the root (0, which must be inside their bounds),
    and the three samples at the contact end are held level: the root starts and ends the
    phase at rest.

    Over PROFILE_KNOTS samples (a phase lengthened for its CoM's acceleration), the profile
    is solved at PROFILE_KNOTS evenly spread samples, each bounded by the bounds of every
    sample between its two neighbours, and interpolated between them by monotone cubic
    pieces (`scipy.interpolate.PchipInterpolator`): each piece lies between its two ends,
    both inside the bounds of the samples it spans. The dense solve's cost grows with the
    cube of the samples (hpp_stairs_0's lift 84 -> 85, lengthened to 2 027 samples: 0.34 s
    at knots, dense not finished after 8 min on a loaded machine); a profile
    solved at fewer samples is rougher (a 6 s landing in tests/test_motion_shift.py peaks at
    2.1 m/s^2, the same bounds solved at every sample at 0.1 m/s^2), still gentler than at
    the phase's nominal length.
    """
    from scipy.interpolate import PchipInterpolator

    room = np.minimum(DIP_INSET * weight, 0.5 * (high - low))
    lower, upper = low + room, high - room
    key = weight < 1e-3
    lower[key], upper[key] = -1e-12, 1e-12
    m = len(weight)
    if m > PROFILE_KNOTS:
        knots = np.unique(np.round(np.linspace(0, m - 1, PROFILE_KNOTS)).astype(int))
        spans = list(zip(np.r_[knots[0], knots[:-1]], np.r_[knots[1:], knots[-1]]))  # neighbour to neighbour
        coarse_lower = np.array([lower[a : b + 1].max() for a, b in spans])
        coarse_upper = np.array([upper[a : b + 1].min() for a, b in spans])
        if (coarse_lower < coarse_upper).all():  # bounded least squares needs room at every knot
            coarse = _least_jerk(coarse_lower, coarse_upper, weight[-1] > weight[0])
            return np.clip(PchipInterpolator(knots, coarse)(np.arange(m)), low, high)
    return np.clip(_least_jerk(lower, upper, weight[-1] > weight[0]), low, high)


def _least_jerk(lower: np.ndarray, upper: np.ndarray, rest_at_end: bool) -> np.ndarray:
    """Values [M] within lower [M] and upper [M] with the least squared third differences,
    the three at one end (the last where rest_at_end, else the first) equal; by bounded least
    squares (`dip_profile`)."""
    from scipy.optimize import lsq_linear

    m = len(lower)
    third = np.zeros((m - 3, m))
    for offset, value in enumerate((-1.0, 3.0, -3.0, 1.0)):
        third[np.arange(m - 3), np.arange(m - 3) + offset] = value
    # rest at the contact end too (the shift around the phase starts or ends there at rest):
    # its last three samples' lowering equal, weighted far above the jerk
    rest = np.zeros((2, m))
    end = m - 3 if rest_at_end else 0
    rest[0, end : end + 2] = rest[1, end + 1 : end + 3] = (1e3, -1e3)
    system = np.vstack([third, rest, 1e-7 * np.eye(m)])
    upper = np.maximum(upper, lower + 1e-12)  # a sample bounded to one value (lsq_linear needs room)
    return lsq_linear(system, np.zeros(len(system)), bounds=(lower, upper), method="bvls").x


def support_margin(points: np.ndarray, point: np.ndarray) -> float:
    """Signed distance, m, of point [2] inside the convex hull of points [P, 2] (negative outside)."""
    return float(support_margins(points, np.asarray(point)[None, :2])[0])


def support_margins(points: np.ndarray, queries: np.ndarray) -> np.ndarray:
    """Signed distances [N], m, of queries [N, 2] inside the convex hull of points [P, 2]
    (negative outside)."""
    from scipy.spatial import ConvexHull

    hull = ConvexHull(points)
    return -(queries @ hull.equations[:, :2].T + hull.equations[:, 2]).max(axis=1)


def sole_corners(feet: np.ndarray, on) -> np.ndarray:
    """Horizontal corners [4 S, 2] (world) of the soles in contact: feet [2, 4, 4] placements,
    on [2] bool."""
    from leas_jax.contacts.robot.model import SOLE_LENGTH, SOLE_WIDTH

    corners = np.array(
        [[sx * SOLE_LENGTH / 2, sy * SOLE_WIDTH / 2, 0.0] for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    )
    return np.concatenate([feet[s][:3, 3] + corners @ feet[s][:3, :3].T for s in (0, 1) if on[s]])[:, :2]


def centred_com(points: np.ndarray, com: np.ndarray, margin: float) -> np.ndarray:
    """The CoM [3] moved horizontally towards the centroid of points [P, 2] (a support polygon's
    corners, world) until it is `margin` m inside their convex hull, its height kept; the
    centroid when no point of that segment is; `com` itself when it already is."""
    centre = points.mean(axis=0)
    if support_margin(points, com[:2]) >= margin:
        return com.copy()
    low, high = 0.0, 1.0
    if support_margin(points, centre) >= margin:
        for _ in range(30):  # the margin is concave along the segment: bisection finds its crossing
            middle = 0.5 * (low + high)
            if support_margin(points, com[:2] + middle * (centre - com[:2])) >= margin:
                high = middle
            else:
                low = middle
    out = com.copy()
    out[:2] = com[:2] + high * (centre - com[:2])
    return out


def centred_postures(
    talos, plan: ContactPlan, frames, margin: float, ik, single_margin: float = 0.0, clearance=None
) -> tuple[np.ndarray, list[int]]:
    """The plan's postures [K, 39] with every posture after the first whose CoM is less than
    `margin` m (double support) or `single_margin` m (single support) inside its soles'
    support polygon moved (`centred_com`, whole-body IK from the posture: soles, root
    orientation and upper body kept; `_centred_configuration`), and the moved indices.

    A posture the IK cannot move, or whose move takes a joint past its limits or collides
    (`BodyClearance.collisions` of clearance, where given), stays the plan's.
    """
    q = np.array(plan.q, dtype=np.float64)
    lower, upper = talos.model.lowerPositionLimit[7:], talos.model.upperPositionLimit[7:]
    moved = []
    for k in range(1, len(plan)):
        on = _contacts(plan, k)
        wanted = margin if on.all() else single_margin
        if wanted <= 0.0:
            continue
        feet, com, rotation = frames[k]
        target = centred_com(sole_corners(feet, on), com, wanted)
        if np.allclose(target, com):
            continue
        centred = _centred_configuration(ik, q[k], feet, com, target, rotation, on)
        if centred is None or ((centred[7:] < lower) | (centred[7:] > upper)).any():
            continue
        if clearance is not None and clearance.collisions(centred):
            continue
        q[k] = centred
        moved.append(k)
    return q, moved


def _centred_configuration(ik, q, feet, com, target, rotation, on) -> np.ndarray | None:
    """Whole-body IK of posture q [39] with its CoM [3] moved to target [3], soles feet
    [2, 4, 4] (those `on` the ground), root rotation [3, 3] and upper body kept; None when
    the IK cannot reach.

    A one-foot posture's swing leg may be at its reach (darpa_0's 54: the IK misses the
    swing sole by 0.8 mm for a 3 mm move of the CoM): where the IK cannot keep the swing sole,
    the swing sole moves with the CoM (horizontally, as far), the legs as they were.
    """
    from leas_jax.motion.wbik import IKError, Targets

    attempts = [feet]
    if not on.all():
        carried = feet.copy()
        carried[~on, :2, 3] += target[:2] - com[:2]
        attempts.append(carried)
    for soles in attempts:
        try:
            return ik.solve(q, Targets(soles, target, rotation, q))
        except IKError:
            continue
    return None


def _segment_phases(
    plan,
    k: int,
    frames,
    terrain,
    config: MotionConfig,
    talos,
    balanced: bool = False,
    clearance=None,
) -> list[_PhaseSpec]:
    """Phases from plan posture k to k + 1.

    In single support the CoM follows `held_root_support` (the root held at the one-foot
    posture's placement, lowered where the swing sole needs it); the double-support shift
    around it goes to or from that phase's CoM with the swing sole on the ground.

    Args:
        frames: list over postures of (feet [2, 4, 4], com [3], root rotation [3, 3]) by FK.
        talos: `load_talos()` (the single-support CoMs).
        balanced: the single support's CoM kept inside the stance sole where `shifted_support` can.
        clearance: `BodyClearance` of the terrain, single supports kept clear of it (None: not checked).

    Raises:
        MotionError: the two postures differ in a way no phase sequence handles (both
            feet change, a foot moves while in contact, two single supports in a row).
    """
    from leas_jax.contacts.planner.transitions import swing_apex, terrain_top
    from leas_jax.motion.paths import shift_duration

    feet_a, com_a, rot_a = frames[k]
    feet_b, com_b, rot_b = frames[k + 1]
    on_a, on_b = _contacts(plan, k), _contacts(plan, k + 1)
    q_a, q_b = plan.q[k], plan.q[k + 1]
    dt = config.dt

    def shift(feet, com0, com1, rot0, rot1, upper0, upper1):
        seconds = shift_duration(
            float(np.linalg.norm(com1 - com0)), config.com_acceleration, config.min_double_support, dt
        )
        window = upper_body_window(clearance, upper0, upper1) or (0.0, 1.0)  # None: the check says where
        # the upper body's minimum-jerk move inside its window keeps each joint within
        # SPEED_MARGIN of its velocity limit (peak speed 1.875 x distance / duration)
        speeds = (
            talos.model.velocityLimit[UPPER_BODY - 1 :] * config.velocity_ratio * SPEED_MARGIN
        )  # v: 6 root
        turn = float((np.abs(upper1[UPPER_BODY:] - upper0[UPPER_BODY:]) / speeds).max())
        seconds = max(seconds, math.ceil(1.875 * turn / (window[1] - window[0]) / dt - 1e-9) * dt)
        return _PhaseSpec(
            "shift", (k, k + 1), -1, round(seconds / dt), feet, feet, com0, com1, rot0, rot1, upper0, upper1,
            float("nan"), None, window,
        )  # fmt: skip

    if on_a.all() and on_b.all():
        for side in (0, 1):
            if not np.allclose(feet_a[side], feet_b[side], atol=1e-6):
                raise MotionError(
                    f"postures {k} and {k + 1}: the {SIDES[side]} sole moves while both are in contact"
                )
        return [shift(feet_a, com_a, com_b, rot_a, rot_b, q_a, q_b)]
    if on_a.all() and on_b.sum() == 1:
        swing = int(np.flatnonzero(~on_b)[0])
        lifted = feet_a.copy()
        lifted[swing] = feet_b[swing]
        start, end = feet_a[swing][:3, 3], feet_b[swing][:3, 3]
        top = terrain_top(terrain, start, end) + config.swing_clearance
        apex = max(top, start[2], end[2])
        lift = _PhaseSpec(
            "lift", (k, k + 1), swing, round(config.lift_duration / dt), feet_a, lifted, com_b, com_b,
            rot_a, rot_b, q_b, q_b, apex,
        )  # fmt: skip
        lift, coms = _single_support(talos, lift, k, config, balanced, clearance)
        coms[-1] = com_b
        return [
            shift(feet_a, com_a, coms[0], rot_a, rot_a, q_a, q_b),
            dataclasses.replace(lift, com0=coms[0], coms=coms[1:]),
        ]
    if on_a.sum() == 1 and on_b.all():
        swing = int(np.flatnonzero(~on_a)[0])
        stance = 1 - swing
        if not np.allclose(feet_a[stance], feet_b[stance], atol=1e-6):
            raise MotionError(f"postures {k} and {k + 1}: the {SIDES[stance]} (stance) sole moves")
        apex = swing_apex(terrain, feet_a[swing][:3, 3], feet_b[swing][:3, 3], config.swing_clearance)
        landed = feet_a.copy()
        landed[swing] = feet_b[swing]
        land = _PhaseSpec(
            "land", (k, k + 1), swing, round(config.land_duration / dt), feet_a, landed, com_a, com_a,
            rot_a, rot_b, q_a, q_a, apex,
        )  # fmt: skip
        land, coms = _single_support(talos, land, k, config, balanced, clearance)
        return [
            dataclasses.replace(land, com1=coms[-1], coms=coms[1:]),
            shift(feet_b, coms[-1], com_b, rot_b, rot_b, q_a, q_b),
        ]
    raise MotionError(
        f"postures {k} and {k + 1}: contacts {on_a.astype(int).tolist()} -> {on_b.astype(int).tolist()} "
        "(a motion goes from double support to one foot or back)"
    )


def _single_support(
    talos, spec: _PhaseSpec, k: int, config: MotionConfig, balanced: bool = False, clearance=None
) -> tuple[_PhaseSpec, np.ndarray]:
    """A lift or land spec, lengthened where its CoM moves far or fast or its joints turn fast,
    and its CoM references [n + 1, 3] of samples 0..n (`_single_support_coms`).

    The phase lasts long enough for the CoM to stay under `config.single_support_acceleration`:
    its peak acceleration along a minimum-jerk move of its end-to-end distance
    (`paths.shift_duration`) and the peak horizontal acceleration of its references
    (`stretched_samples`: where the root rises, the CoM follows the swing leg's own path, on
    the swing windows). The references are functions of normalised time, so a longer phase
    has them slower; up to STRETCHES lengthenings. balanced, clearance: as `_single_support_coms`.

    Raises:
        MotionError: naming postures k and k + 1.
    """
    from leas_jax.motion.paths import shift_duration

    limit, dt = config.single_support_acceleration, config.dt
    speeds = talos.model.velocityLimit[6:] * config.velocity_ratio * SPEED_MARGIN
    spec, coms, configurations, profiled = _single_support_coms(talos, spec, k, config, balanced, clearance)
    for _ in range(STRETCHES):
        distance = float(np.linalg.norm(coms[-1] - coms[0]))
        seconds = shift_duration(distance, limit, spec.samples * dt, dt)
        samples = max(
            round(seconds / dt),
            stretched_samples(coms, spec.samples, limit, dt, vertical=profiled),
            speed_samples(configurations, spec.samples, speeds, dt),
        )
        if samples <= spec.samples:
            break
        spec = dataclasses.replace(spec, samples=samples)  # its bulges tried again from none
        spec, coms, configurations, profiled = _single_support_coms(
            talos, spec, k, config, balanced, clearance
        )
    return spec, coms


def peak_horizontal_acceleration(points: np.ndarray, dt: float, vertical: bool = False) -> float:
    """Largest horizontal acceleration, m/s^2, of points [M, 3] (world, m) sampled every dt s,
    by second differences (0 under 3 samples); vertical: of all three coordinates."""
    if len(points) < 3:
        return 0.0
    axes = 3 if vertical else 2
    second = (points[2:, :axes] - 2.0 * points[1:-1, :axes] + points[:-2, :axes]) / dt**2
    return float(np.linalg.norm(second, axis=1).max())


def stretched_samples(
    points: np.ndarray, samples: int, limit: float, dt: float, vertical: bool = False
) -> int:
    """Samples (at least `samples`) of a phase whose path points [samples + 1, 3] (world, m; a
    function of normalised time) keeps its peak horizontal acceleration (vertical: of all three
    coordinates) within `limit`, m/s^2, when played over them: accelerations scale with the
    inverse square of the duration."""
    peak = peak_horizontal_acceleration(points, dt, vertical)
    if peak <= limit:
        return samples
    return max(samples, math.ceil(samples * math.sqrt(peak / limit) - 1e-9))


def speed_samples(configurations: np.ndarray, samples: int, speeds: np.ndarray, dt: float) -> int:
    """Samples (at least `samples`) of a phase whose configurations [samples + 1, 39] (functions
    of normalised time, sampled every dt s) keep every joint's speed within speeds [32], rad/s,
    when played over them: speeds scale with the inverse of the duration."""
    peak = float((np.abs(np.diff(configurations[:, 7:], axis=0)) / dt / speeds).max())
    if peak <= 1.0:
        return samples
    return max(samples, math.ceil(samples * peak - 1e-9))


def _single_support_coms(
    talos, spec: _PhaseSpec, k: int, config: MotionConfig, balanced: bool = False, clearance=None
) -> tuple[_PhaseSpec, np.ndarray, np.ndarray, bool]:
    """The spec with its swing path's bulge, CoMs [n + 1, 3] and configurations [n + 1, 39] of a
    lift or land spec's samples 0..n: `held_root_support`'s, else `profiled_support`'s, else
    `shifted_support`'s (balanced: the latter's first, whose CoM stays inside the stance sole);
    and whether a height profile (either of the latter) made them.

    Each is taken only where its configurations keep clear of the terrain and of themselves
    (`_clear_of_terrain`; clearance: the `BodyClearance`, None: not checked); where none is,
    the swing path bulges away from the stance sole by each of SWING_BULGES in turn (a held
    one over at least `bulge_samples`).

    Raises:
        MotionError: naming postures k and k + 1 and the three reasons (without a bulge).
    """
    from leas_jax.motion.paths import slerp

    admissible = _clear_of_terrain(clearance, spec.upper0, config)
    bulges = ((0.0, False),) + (SWING_BULGES if admissible else ())
    first = None  # the reasons without a bulge
    for offset, held in bulges:
        samples = max(spec.samples, bulge_samples(spec.kind, offset, config)) if held else spec.samples
        spec = dataclasses.replace(spec, swing_offset=offset, swing_held=held, samples=samples)
        fractions = np.arange(spec.samples + 1) / spec.samples
        rotations = slerp(spec.rot0, spec.rot1, turn_scaling(spec, fractions))
        feet = swing_feet(spec, fractions)
        arguments = (talos, spec.upper0, feet, rotations, spec.swing, spec.kind == "lift", config, admissible)
        if balanced:
            try:
                return spec, *shifted_support(*arguments), True
            except MotionError:
                pass  # made as before: its equilibrium check fails again and says so
        reasons = []
        for builder in (held_root_support, profiled_support, shifted_support):
            try:
                return spec, *builder(*arguments), builder is not held_root_support
            except MotionError as exc:
                reasons.append(str(exc))
        first = first or reasons
    held, profiled, shifted = first
    raise MotionError(
        f"postures {k} and {k + 1}: {spec.kind}: {held}; sample by sample: {profiled}; shifting the root: {shifted}"
    )


def bulge_samples(kind: str, offset: float, config: MotionConfig) -> int:
    """Samples of a lift or land whose swing sole's held bulge of `offset` m
    (`paths.HELD_BULGES`) goes out and back with a peak sideways acceleration of at most
    `config.bulge_acceleration`, m/s^2: its shorter span is a minimum-jerk move of `offset`
    (`paths.shift_duration`, on steps of that span's share of a sample)."""
    from leas_jax.motion.paths import HELD_BULGES, shift_duration

    span = min(t1 - t0 for t0, t1 in HELD_BULGES[kind])
    return round(
        shift_duration(offset, config.bulge_acceleration, 0.0, span * config.dt) / (span * config.dt)
    )


def upper_body_window(clearance, q_a: np.ndarray, q_b: np.ndarray) -> tuple[float, float] | None:
    """Span of a shift's normalised time over which its upper body goes from key posture q_a's
    [39] to q_b's (the arms between half-sitting and held in); None where no span clears.

    Over the whole shift, the arms can sweep through the terrain that both key postures
    clear: the root moves towards a wall as the arms come in (hpp_talos_stairs15's shifts
    beside the stair's wall). So the arms move in the first UPPER_BODY_SPLIT of the shift
    where their whole path clears the terrain with the rest of the body as in q_a, else in
    the last with the rest as in q_b (`arm_path_clear`); over the whole shift where the upper
    body does not change or clearance is None.
    """
    if clearance is None or np.allclose(q_a[UPPER_BODY:], q_b[UPPER_BODY:]):
        return (0.0, 1.0)
    for span, body in (((0.0, UPPER_BODY_SPLIT), q_a), ((1.0 - UPPER_BODY_SPLIT, 1.0), q_b)):
        if arm_path_clear(clearance, body, q_a, q_b):
            return span
    return None


def arm_path_clear(clearance, body: np.ndarray, q_a: np.ndarray, q_b: np.ndarray) -> bool:
    """Whether body [39] (root and legs) with its upper body going straight from q_a's to q_b's
    (joint space, 11 points) collides nowhere (`BodyClearance.collisions`)."""
    from leas_jax.motion.paths import lerp

    path = np.repeat(body[None], 11, axis=0)
    path[:, UPPER_BODY:] = lerp(q_a[UPPER_BODY:], q_b[UPPER_BODY:], np.linspace(0.0, 1.0, 11))
    return all(clearance.collisions(q) is None for q in path)


def tucked_arms(keys: np.ndarray, clearance) -> tuple[np.ndarray, list[int]]:
    """Key postures [K, 39] whose upper body changes only where a shift can change it clear of
    the terrain, and the postures changed.

    Where the arms cannot change between postures k and k + 1 (`upper_body_window` None: a
    wall beside the path that both postures clear, but not the arms' way between them), the
    change moves to an earlier pair: postures k - j + 1..k take k + 1's upper body, for the
    smallest j up to ARM_CHANGE_REACH whose postures stay collision-free and whose new pair
    (k - j, k - j + 1) has a clear span; else to a later pair the same way. The plan's
    postures hold the arms in where they must; holding them in longer, before or after,
    changes no contact (the CoM moves by the arms' mass, which the motion's checks judge).
    """
    keys = np.array(keys, dtype=np.float64)
    changed = set()
    for k in range(len(keys) - 1):
        if upper_body_window(clearance, keys[k], keys[k + 1]) is not None:
            continue
        for j, earlier in itertools.product(range(1, ARM_CHANGE_REACH + 1), (True, False)):
            held = list(range(k - j + 1, k + 1)) if earlier else list(range(k + 1, k + j + 1))
            source, pair = (keys[k + 1], (k - j, k - j + 1)) if earlier else (keys[k], (k + j, k + j + 1))
            if min(pair) < 0 or max(pair) >= len(keys):
                continue
            trial = keys.copy()
            trial[held, UPPER_BODY:] = source[UPPER_BODY:]
            if any(clearance.collisions(trial[i]) for i in held):
                continue
            if upper_body_window(clearance, trial[pair[0]], trial[pair[1]]) is None:
                continue
            keys, changed = trial, changed | set(held)
            break
    return keys, sorted(changed)


def _clear_of_terrain(clearance, q: np.ndarray, config: MotionConfig):
    """The `admissible` test of a single support whose one-foot key posture is q [39]: it
    refuses configurations [M, 39] in which a geometry other than the feet comes within
    `config.body_clearance` of the terrain, or within the key posture's own distance where that
    is less (the plan's postures are only collision-free), saying which and at what sample;
    None where clearance is None or the margin is 0 (nothing refused)."""
    if clearance is None or config.body_clearance <= 0.0:
        return None
    # the key posture itself passes: a tenth of a millimetre under its own distance
    margin = max(min(config.body_clearance, clearance.distance(q, config.body_clearance)) - 1e-4, 0.0)

    def admissible(configurations: np.ndarray) -> str | None:
        found = clearance.first_too_close(configurations, margin)
        return None if found is None else f"at sample {found[0]}, {found[1]}"

    return admissible


def turn_scaling(spec: _PhaseSpec, fractions: np.ndarray) -> np.ndarray:
    """Progress [N] in [0, 1] of a phase's turns at normalised times fractions [N]: the
    minimum-jerk scaling in a shift; in single support the swing sole's travel window, on
    which the root turns too (the hip yaw between them then goes straight from one key
    posture's to the other's, within its limits)."""
    from leas_jax.motion.paths import LAND_WINDOWS, LIFT_WINDOWS, min_jerk, window

    if spec.swing < 0:
        return min_jerk(fractions)
    return window(fractions, (LIFT_WINDOWS if spec.kind == "lift" else LAND_WINDOWS)[1])


def swing_feet(spec: _PhaseSpec, fractions: np.ndarray) -> np.ndarray:
    """Sole references [N, 2, 4, 4] (world) of a phase at normalised times fractions [N] in [0, 1].

    The swing sole follows `paths.swing_path` below spec.apex (LIFT_WINDOWS or
    LAND_WINDOWS), bulging spec.swing_offset away from the stance sole (held out where
    spec.swing_held), and turns while it travels; at fraction 1 it is exactly at spec.feet1.
    """
    from leas_jax.motion.paths import HELD_BULGES, LAND_WINDOWS, LIFT_WINDOWS, slerp, swing_path

    feet = np.repeat(spec.feet0[None], len(fractions), axis=0)
    if spec.swing >= 0:
        start, end = spec.feet0[spec.swing], spec.feet1[spec.swing]
        windows = LIFT_WINDOWS if spec.kind == "lift" else LAND_WINDOWS
        feet[:, spec.swing, :3, :3] = slerp(start[:3, :3], end[:3, :3], turn_scaling(spec, fractions))
        feet[:, spec.swing, :3, 3] = swing_path(
            start[:3, 3],
            end[:3, 3],
            spec.apex,
            fractions,
            windows,
            spec.swing_offset,
            away_from_stance(spec),
            HELD_BULGES[spec.kind] if spec.swing_held else None,
        )
        feet[np.asarray(fractions) >= 1.0, spec.swing] = spec.feet1[spec.swing]
    return feet


def away_from_stance(spec: _PhaseSpec) -> np.ndarray:
    """Horizontal unit vector [2] (world) square to a single support's swing travel, on the side
    away from the stance sole (along the stance-to-swing direction where the sole does not travel)."""
    start, end = spec.feet0[spec.swing][:2, 3], spec.feet1[spec.swing][:2, 3]
    outward = 0.5 * (start + end) - spec.feet0[1 - spec.swing][:2, 3]
    travel = end - start
    if np.linalg.norm(travel) < 1e-3:
        return outward / max(float(np.linalg.norm(outward)), 1e-9)
    square = np.array([-travel[1], travel[0]]) / np.linalg.norm(travel)
    return square if square @ outward >= 0.0 else -square


def detour_profile(fractions: np.ndarray) -> np.ndarray:
    """Weight [N] of an arm detour at normalised times fractions [N] in [0, 1]: sin^2(pi t),
    0 with zero speed at both ends, 1 at mid-phase."""
    return np.sin(np.pi * np.asarray(fractions)) ** 2


def colliding_arms(messages) -> set[int]:
    """Sides (0 left, 1 right) whose arm or gripper a phase's collision messages name
    (`BodyClearance.collisions`: "A collides with B"; None entries: nothing collides)."""
    sides = set()
    for message in messages:
        for name in (message or "").split(" collides with "):
            if name.startswith(("arm_", "gripper_")):
                sides.add(0 if name.split("_")[1] == "left" else 1)
    return sides


def arm_detour(model, spec: _PhaseSpec, sides: set, detour: tuple) -> np.ndarray:
    """Upper-body offsets [39] of one ARM_DETOURS entry (shoulder pitch, roll outwards, elbow;
    rad) on the arms of `sides`, each cut so that the phase's upper body (straight from
    spec.upper0's to spec.upper1's) stays LIMIT_MARGIN inside its joint limits."""
    offsets = np.zeros(model.nq)
    for side in sides:
        name = SIDES[side]
        outwards = 1.0 if side == 0 else -1.0  # the right arm's roll mirrors the left's
        for joint, value in zip((1, 2, 4), (detour[0], outwards * detour[1], detour[2])):
            index = model.joints[model.getJointId(f"arm_{name}_{joint}_joint")].idx_q
            ends = (spec.upper0[index], spec.upper1[index])
            lowest = model.lowerPositionLimit[index] + LIMIT_MARGIN - min(ends)
            highest = model.upperPositionLimit[index] - LIMIT_MARGIN - max(ends)
            offsets[index] = min(max(value, min(lowest, 0.0)), max(highest, 0.0))
    return offsets


def phase_references(spec: _PhaseSpec, dt: float):
    """Task references of a phase's samples 1..n (sample 0 is the previous phase's end).

    The CoM is spec.coms where set (single support), else straight from com0 to com1.

    Returns:
        list of n wbik.Targets (feet [2, 4, 4], CoM [3], root rotation [3, 3], upper body [39]).
    """
    from leas_jax.motion.paths import lerp, min_jerk, slerp, window
    from leas_jax.motion.wbik import Targets

    fractions = np.arange(1, spec.samples + 1) / spec.samples
    s = min_jerk(fractions)
    coms = lerp(spec.com0, spec.com1, s) if spec.coms is None else spec.coms
    rots = slerp(spec.rot0, spec.rot1, turn_scaling(spec, fractions))
    uppers = lerp(spec.upper0, spec.upper1, window(fractions, spec.upper_window))
    if spec.upper_detour is not None:
        uppers = uppers + detour_profile(fractions)[:, None] * spec.upper_detour[None]
    feet = swing_feet(spec, fractions)
    return [Targets(feet[i], coms[i], rots[i], uppers[i]) for i in range(spec.samples)]


def _swing_clearance(terrain, spec: _PhaseSpec, references, config: MotionConfig) -> str | None:
    """Why a phase's swing sole meets the terrain, or None.

    A sole corner may sink `terrain_tolerance` below the surface under it, except within
    `contact_zone` of height above its placement at lift-off or landing.
    """
    from leas_jax.contacts.robot.model import SOLE_LENGTH, SOLE_WIDTH

    if spec.swing < 0:
        return None
    corners = np.array(
        [[sx * SOLE_LENGTH / 2, sy * SOLE_WIDTH / 2, 0.0] for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    )
    contact_z = spec.feet0[spec.swing][2, 3] if spec.kind == "lift" else spec.feet1[spec.swing][2, 3]
    for i, ref in enumerate(references):
        sole = ref.feet[spec.swing]
        if sole[2, 3] - contact_z < config.contact_zone:
            continue
        world = sole[:3, 3] + corners @ sole[:3, :3].T
        gaps = world[:, 2] - terrain.height_at(world[:, :2])
        if gaps.min() < -config.terrain_tolerance:
            return (
                f"the swing sole's corner is {-gaps.min() * 100:.1f} cm inside the terrain at sample {i + 1}"
            )
    return None


def make_motion(plan: ContactPlan, config: MotionConfig = MotionConfig(), check: bool = True) -> Motion:
    """A whole-body motion through every key posture of `plan`, at rest at each.

    A single support that fails the equilibrium check is made again with its CoM kept inside
    the stance sole (`shifted_support`, the shifts from none up; where it cannot, as before),
    and one that still fails, or whose stance sole's centre of pressure comes within
    `MotionConfig.pressure_margin` of its edges, slower (`MotionConfig.slowed_duration`); at
    most two remakes. Every other phase is made as before (and not sampled again). A one-foot
    posture centred in its stance sole (`centred_postures`) whose single support cannot be
    made is taken as the plan has it.

    Args:
        plan: the contact plan (at least 2 postures).
        config: timing, paths, IK and check settings.
        check: raise MotionError on the first sample that fails `check_motion`.

    Returns:
        Motion sampled every config.dt seconds; motion.failures lists the checks' failures
        (empty when check is True).

    Raises:
        MotionError: a phase cannot be made (the message names it and says why).
    """
    from leas_jax.contacts.robot.clearance import BodyClearance
    from leas_jax.contacts.robot.model import load_talos
    from leas_jax.motion.wbik import WholeBodyIK
    from leas_jax.terrain import loads_terrain

    if len(plan) < 2:
        raise MotionError(f"the plan has {len(plan)} posture(s); a motion needs at least 2")
    talos = load_talos()
    terrain = loads_terrain(plan.terrain, source="<plan terrain>")
    ik = WholeBodyIK(talos, config.ik_iterations, config.ik_damping, config.ik_tolerance)
    clearance = BodyClearance(talos, terrain)
    original = plan
    frames = [posture_frames(talos, q) for q in plan.q]
    keys, centred = centred_postures(
        talos, plan, frames, config.support_margin, ik, config.single_support_margin, clearance
    )
    one_foot = {k for k in centred if not _contacts(plan, k).all()}  # one-foot postures centred
    keys, tucked = tucked_arms(keys, clearance)
    moved = sorted(set(centred) | set(tucked))
    if moved:
        plan = dataclasses.replace(plan, q=keys)
        frames = [posture_frames(talos, q) for q in plan.q]
    balanced = set()  # segments k whose single support keeps its CoM inside the stance sole
    slowed = set()  # segments k whose single support is also slower (`MotionConfig.slowed_duration`)
    slow_config = dataclasses.replace(
        config,
        single_support_acceleration=config.slowed_acceleration,
        lift_duration=config.lift_duration * config.slowed_duration,
        land_duration=config.land_duration * config.slowed_duration,
    )
    segments = {}  # (k, balanced, slowed): its phase specs, kept across the remakes
    solved = {}  # phases sampled, kept across the remakes (`_sampled_motion`)
    remakes = 0
    while True:
        specs, failed = [], None
        for k in range(len(plan) - 1):
            key = (k, k in balanced, k in slowed)
            if key not in segments:
                try:
                    segments[key] = _segment_phases(
                        plan, k, frames, terrain, slow_config if key[2] else config, talos, key[1], clearance
                    )
                except MotionError:
                    failed = {k, k + 1} & one_foot
                    if not failed:
                        raise
                    break
            specs.extend(segments[key])
        if failed:  # a centred one-foot posture whose single support cannot be made: the plan's, as given
            for j in failed:
                keys[j, :UPPER_BODY] = original.q[j, :UPPER_BODY]
                frames[j] = posture_frames(talos, keys[j])
                for key in [key for key in segments if key[0] in (j - 1, j)]:
                    del segments[key]
            one_foot -= failed
            moved = sorted(set(moved) - (failed - set(tucked)))
            plan = dataclasses.replace(plan, q=keys)
            continue
        motion, collided = _sampled_motion(
            plan, original, moved, specs, frames, terrain, config, talos, ik, clearance, solved
        )
        failures = check_motion(motion, config, clearance, collided)
        if remakes == 2:
            break
        remakes += 1
        tipping = {
            motion.phases[index].postures[0]
            for _, index, name, _ in failures
            if name == "equilibrium" and motion.phases[index].single_support
        }
        rebalance = tipping - balanced if config.root_shift > 0.0 else set()
        slow = set()
        if config.slowed_duration > 0.0:
            slow = ((tipping - rebalance) | off_centre_segments(motion, config.pressure_margin)) - slowed
        if not rebalance and not slow:
            break
        balanced, slowed = balanced | rebalance, slowed | slow
    if check and failures:
        sample, index, name, message = failures[0]
        raise MotionError(
            f"{motion.phases[index].describe(config.dt)}: {name} fails at t = {sample * config.dt:.2f} s: {message}"
            f" ({len(failures)} failing samples)"
        )
    motion.failures.extend(failures)
    return motion


def _sampled_motion(
    plan, original, moved, specs, frames, terrain, config: MotionConfig, talos, ik, clearance, solved=None
) -> tuple[Motion, list]:
    """The Motion of phase specs along plan (its key postures, centred) by whole-body IK,
    sample by sample, with velocities, accelerations, torques and wrenches, and what collides
    at each sample (`BodyClearance.collisions` of clearance, a message or None), a phase whose
    arms collide made again with a detour (`detoured_phase`); original: the plan as given
    (`Motion.plan_q`), moved: the key postures reached otherwise (`Motion.moved_keys`). Raises
    MotionError naming the phase whose swing meets the terrain, whose IK fails or ends off the
    next key posture. solved: {id(spec): (spec, first configuration [39], (spec, references,
    configurations, messages))} of phases sampled before, reused where a phase starts from the
    same configuration, and added to (None: nothing kept)."""
    q_samples, feet_samples, com_samples, contact_samples = [plan.q[0]], [frames[0][0]], [frames[0][1]], []
    contact_samples.append(_contacts(plan, 0))
    collided = [clearance.collisions(plan.q[0])]
    phases, key_index = [], [0]
    for spec in specs:
        start = len(q_samples) - 1
        phase = Phase(spec.kind, start, start + spec.samples, spec.postures, spec.swing)
        ends_segment = _ends_segment(specs, spec)
        earlier = (solved or {}).get(id(spec))  # it holds spec itself: no other object takes its id
        if earlier is not None and earlier[0] is spec and np.array_equal(earlier[1], q_samples[-1]):
            sampled = earlier[2]
        else:
            sampled = _sampled_phase(spec, phase, q_samples[-1], terrain, config, talos, ik, clearance)
            if solved is not None:
                solved[id(spec)] = (spec, q_samples[-1], sampled)
        spec, references, configurations, messages = sampled
        in_contact = np.array([side != spec.swing for side in (0, 1)])
        for q, ref, message in zip(configurations, references, messages):
            q_samples.append(q)
            feet_samples.append(ref.feet)
            com_samples.append(ref.com)
            contact_samples.append(in_contact)
            collided.append(message)
        last = spec.postures[1]
        if ends_segment:
            gap = _configuration_gap(talos.model, q_samples[-1], plan.q[last])
            if gap > KEY_POSTURE_TOL:
                raise MotionError(
                    f"{phase.describe(config.dt)}: the IK ends {gap:.1e} from posture {last} (another IK branch)"
                )
            q_samples[-1] = plan.q[last].copy()
            contact_samples[-1] = _contacts(plan, last)
            collided[-1] = clearance.collisions(q_samples[-1])
            key_index.append(len(q_samples) - 1)
        phases.append(phase)
    q = np.array(q_samples)
    contact = np.array(contact_samples)
    v, a = _derivatives(talos.model, q, config.dt)
    tau, wrenches = _torques(talos, q, v, a, contact)
    feet = np.array([[_placement(f) for f in pair] for pair in feet_samples])
    return Motion(
        time=np.arange(len(q)) * config.dt,
        q=q,
        v=v,
        a=a,
        tau=tau,
        wrenches=wrenches,
        contact=contact,
        feet=feet,
        com=np.array(com_samples),
        key_index=np.array(key_index),
        phases=tuple(phases),
        plan_q=np.array(original.q),
        plan_feet=np.array(original.feet),
        moved_keys=np.array(moved, dtype=np.int64),
        terrain=plan.terrain,
        dt=config.dt,
    ), collided


def _sampled_phase(
    spec: _PhaseSpec, phase: Phase, start_q: np.ndarray, terrain, config, talos, ik, clearance
):
    """(spec, references, configurations [n, 39], collision messages [n]) of a phase sampled
    from start_q [39], its arms detoured where they collide (`detoured_phase`, whose spec it
    then is); MotionError where its swing sole meets the terrain or its IK fails."""
    references = phase_references(spec, config.dt)
    reason = _swing_clearance(terrain, spec, references, config)
    if reason:
        raise MotionError(f"{phase.describe(config.dt)}: {reason}")
    configurations = _phase_configurations(ik, start_q, references, phase, config.dt)
    messages = [clearance.collisions(q) for q in configurations]
    sampled = (spec, references, configurations, messages)
    sides = colliding_arms(messages)
    if sides:
        return detoured_phase(spec, phase, sides, start_q, talos, ik, clearance, config.dt) or sampled
    return sampled


def _phase_configurations(ik, q0: np.ndarray, references, phase: Phase, dt: float) -> np.ndarray:
    """Configurations [n, 39] of a phase's samples 1..n by whole-body IK from q0 [39], each
    sample from the last; MotionError naming the phase and sample where the IK fails."""
    from leas_jax.motion.wbik import IKError

    configurations, q = [], q0
    for i, ref in enumerate(references):
        try:
            q = ik.solve(q, ref)
        except IKError as exc:
            raise MotionError(f"{phase.describe(dt)}: sample {i + 1}: {exc}") from None
        configurations.append(q)
    return np.array(configurations)


def detoured_phase(
    spec: _PhaseSpec, phase: Phase, sides: set, q0: np.ndarray, talos, ik, clearance, dt: float
):
    """The first ARM_DETOURS entry (on the arms of `sides`, `arm_detour`) whose phase collides
    nowhere: (spec, references, configurations [n, 39], collision messages [n]) of it, or None
    where none does. A detour is left at its first colliding sample or IK failure."""
    from leas_jax.motion.wbik import IKError

    for detour in ARM_DETOURS:
        offsets = arm_detour(talos.model, spec, sides, detour)
        if not offsets.any():
            continue
        trial = dataclasses.replace(spec, upper_detour=offsets)
        references = phase_references(trial, dt)
        configurations, q = [], q0
        for ref in references:
            try:
                q = ik.solve(q, ref)
            except IKError:
                break
            if clearance.collisions(q):
                break
            configurations.append(q)
        if len(configurations) == len(references):
            return trial, references, np.array(configurations), [None] * len(references)
    return None


def _ends_segment(specs: list, spec: _PhaseSpec) -> bool:
    """Whether `spec` is the last phase between its two postures (its end is a key instant)."""
    same = [s for s in specs if s.postures == spec.postures]
    return same[-1] is spec


def _configuration_gap(model, q0: np.ndarray, q1: np.ndarray) -> float:
    """Largest coordinate of Pinocchio's `difference(q0, q1)` (m and rad)."""
    import pinocchio as pin

    return float(np.abs(pin.difference(model, q0, q1)).max())


def _derivatives(model, q: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Velocities and accelerations [N, 38] of configurations q [N, 39] by central differences.

    The first and last samples are at rest (zero velocity and acceleration).
    """
    import pinocchio as pin

    steps = np.array([pin.difference(model, q[i], q[i + 1]) for i in range(len(q) - 1)]) / dt  # [N-1]
    v = np.zeros((len(q), model.nv))
    a = np.zeros((len(q), model.nv))
    v[1:-1] = 0.5 * (steps[:-1] + steps[1:])
    a[1:-1] = (steps[1:] - steps[:-1]) / dt
    return v, a


def _torques(talos, q, v, a, contact) -> tuple[np.ndarray, np.ndarray]:
    """Joint torques [N, 32] and sole wrenches [N, 2, 6] of the motion (dynamics.contact_torques)."""
    from leas_jax.motion.dynamics import contact_torques

    data = talos.model.createData()
    tau = np.empty((len(q), 32))
    wrenches = np.empty((len(q), 2, 6))
    for i in range(len(q)):
        tau[i], wrenches[i], _ = contact_torques(
            talos.model, data, q[i], v[i], a[i], talos.sole_frame_ids, contact[i], talos.mass
        )
    return tau, wrenches


def check_motion(
    motion: Motion, config: MotionConfig = MotionConfig(), clearance=None, collided=None
) -> list[tuple[int, int, str, str]]:
    """Samples of a motion that fail a check.

    Checks at every sample: joint positions within the URDF's limits; joint velocities
    within `velocity_ratio` of the URDF's; static equilibrium with the CoM's acceleration
    (hpp-centroidal-dynamics robustness >= `min_robustness` over the sole corners in
    contact); in single support, the stance sole's centre of pressure from the motion's
    wrenches on the sole (`pressure_margins` >= 0: the swing leg's angular momentum, which the
    equilibrium check leaves out, moves it too); joint torques within `torque_ratio` of the
    effort limits; the stored torques
    equal to a fresh inverse dynamics of (q, v, a) (so edited torques are caught too); no
    collision with the terrain or between the legs and the body, as the verifier checks key
    postures (`clearance.BodyClearance.collisions`; clearance: one built on the motion's
    terrain, else made here; collided: its messages per sample where already found, [N] of
    str or None, else found here).

    Returns:
        list of (sample index, phase index, check name, message), in time order per check.
    """
    from leas_jax.contacts.robot.clearance import BodyClearance
    from leas_jax.contacts.robot.equilibrium import HppEquilibrium
    from leas_jax.contacts.robot.model import load_talos
    from leas_jax.terrain import loads_terrain

    talos = load_talos()
    if clearance is None:
        clearance = BodyClearance(talos, loads_terrain(motion.terrain, source="<motion terrain>"))
    model = talos.model
    lower, upper = model.lowerPositionLimit[7:], model.upperPositionLimit[7:]
    speed = model.velocityLimit[6:] * config.velocity_ratio
    effort = model.effortLimit[6:] * config.torque_ratio
    failures = []

    def fail(sample, name, message):
        failures.append((int(sample), motion.phase_at(int(sample)), name, message))

    joints = [model.names[j] for j in range(2, model.njoints)]
    over = (motion.q[:, 7:] < lower - 1e-9) | (motion.q[:, 7:] > upper + 1e-9)
    for sample, joint in zip(*np.nonzero(over)):
        fail(sample, "joint limits", f"{joints[joint]} = {motion.q[sample, 7 + joint]:.3f} rad")
    fast = np.abs(motion.v[:, 6:]) > speed
    for sample, joint in zip(*np.nonzero(fast)):
        fail(sample, "velocity limits", f"{joints[joint]} at {motion.v[sample, 6 + joint]:.2f} rad/s")
    ratio = np.abs(motion.tau) / effort
    for sample, joint in zip(*np.nonzero(ratio > 1.0)):
        fail(
            sample,
            "torque limits",
            f"{joints[joint]} needs {motion.tau[sample, joint]:.1f} N m ({ratio[sample, joint]:.2f} x its limit)",
        )
    fresh, _ = _torques(talos, motion.q, motion.v, motion.a, motion.contact)
    wrong = np.abs(fresh - motion.tau).max(axis=1) > 1e-6 * (1.0 + np.abs(fresh).max(axis=1))
    for sample in np.flatnonzero(wrong):
        fail(sample, "inverse dynamics", "the stored torques differ from rnea's")
    solver = HppEquilibrium(talos.mass)
    acceleration = np.zeros_like(motion.com)
    acceleration[1:-1] = (motion.com[2:] - 2 * motion.com[1:-1] + motion.com[:-2]) / motion.dt**2
    for sample in range(len(motion.q)):
        feet = np.where(motion.contact[sample][:, None], motion.feet[sample], np.nan)
        value = _robustness(solver, feet, motion.com[sample], acceleration[sample])
        if not value >= config.min_robustness:
            fail(sample, "equilibrium", f"robustness {value:.3g} < {config.min_robustness}")
        collision = clearance.collisions(motion.q[sample]) if collided is None else collided[sample]
        if collision:
            fail(sample, "collisions", collision)
    margins = pressure_margins(motion)
    for sample in np.flatnonzero(margins < 0.0):
        fail(sample, "centre of pressure", f"{-margins[sample] * 100:.1f} cm outside the stance sole")
    failures.sort(key=lambda item: item[0])
    return failures


def pressure_margins(motion: Motion) -> np.ndarray:
    """[N] m: how far inside its sole rectangle (SOLE_LENGTH x SOLE_WIDTH, sole frame) the
    stance sole's centre of pressure lies at each single-support sample, from the motion's
    wrenches (negative: outside); NaN in double support and where the sole carries under 1 N."""
    from leas_jax.contacts.robot.model import SOLE_LENGTH, SOLE_WIDTH

    single = motion.contact.sum(axis=1) == 1
    wrench = motion.wrenches[np.arange(len(motion.q)), np.argmax(motion.contact, axis=1)]  # [N, 6]
    loaded = single & (wrench[:, 2] > 1.0)
    force = np.where(loaded, wrench[:, 2], 1.0)
    along, across = np.abs(wrench[:, 4] / force), np.abs(wrench[:, 3] / force)
    return np.where(loaded, np.minimum(SOLE_LENGTH / 2 - along, SOLE_WIDTH / 2 - across), np.nan)


def off_centre_segments(motion: Motion, margin: float) -> set[int]:
    """Postures k whose single support (k to k + 1) holds a sample whose centre of pressure is
    less than `margin`, m, inside the stance sole (`pressure_margins`)."""
    margins = pressure_margins(motion)
    return {
        phase.postures[0]
        for phase in motion.phases
        if phase.single_support
        and np.nanmin(margins[phase.start + 1 : phase.stop + 1], initial=np.inf) < margin
    }


def _robustness(solver, feet: np.ndarray, com: np.ndarray, acceleration: np.ndarray) -> float:
    """hpp-centroidal-dynamics robustness of feet [2, 7] (NaN rows in the air) at a CoM [3] accelerating [3]."""
    from leas_jax.contacts.robot.equilibrium import sole_corners

    points, normals = sole_corners(feet)
    if len(points) == 0:
        return -np.inf
    solver.set_contacts(points, normals)
    return solver.robustness(com, acceleration)
