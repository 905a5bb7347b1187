"""Settings of motion generation and of its simulation, with units and sources."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class MotionConfig:
    """How `make_motion` times and shapes a whole-body motion along a contact plan.

    Every key posture of the plan is reached at rest (quasi-static walking, as the
    plan's postures are static equilibria): the CoM moves only in double support, from one
    posture's CoM to the next; in single support it stays over the stance sole while the
    swing foot lifts to the plan's single-support posture and lands on its next placement.
    """

    # Sampling of the joint trajectory, s (100 Hz).
    dt: float = 0.01
    # Single support: lift-off to the plan's single-support posture, then landing, s. The
    # HPP group's Talos demos use 1.2-1.6 s of single support; 0.6 + 0.8 = 1.4 s, the
    # landing longer because it carries the foot forward.
    lift_duration: float = 0.6
    land_duration: float = 0.8
    # Double support: at least this long, s (HPP's Talos demos: 0.2-0.5 s, longer when
    # quasi-static), and long enough that the CoM's peak acceleration along its
    # minimum-jerk path stays under `com_acceleration`, m/s^2: the zero-moment point then
    # stays within com_acceleration * h / g = 0.25 * 0.88 / 9.81 = 2.2 cm of the CoM's
    # projection (h: Talos's CoM height at half-sitting, 0.88 m), a tenth of the sole's width
    # away from a static stance.
    min_double_support: float = 0.5
    com_acceleration: float = 0.25
    # Swing foot: the landing path's apex is at least this far above the terrain under the
    # foot's straight path and above both end placements, m (the plan's single-support
    # postures lift the foot 5-15 cm).
    swing_clearance: float = 0.05
    # Where the swing path must bulge out while the legs pass the stance leg (a held bulge,
    # `motion.SWING_BULGES`), its sideways peak acceleration, m/s^2: the phase lasts long
    # enough. Held out 6-10 cm within a 0.6-0.8 s phase, the swing leg took the stance ankle
    # or hip roll to 1.07-1.08 x its effort limit on eval_bridge; at 2 m/s^2 the plans that
    # need it peak at 0.76-0.77 x (docs/results/2026-12-06-motion-held-bulge).
    bulge_acceleration: float = 2.0
    # Single support where the swing sole cannot reach its contact from the one-foot
    # posture's root (the plan stretches its legs to within a millimetre of their reach,
    # knees at 0.05 rad, on steps): towards the contact the root moves `lean` m towards it
    # along the stance sole (0.20 m long: the CoM stays over it; on eval_stairs this keeps
    # the front shin off the next step's nosing at lift-off) and comes down until both knees
    # are bent by `min_knee`, rad (a straight knee is the IK's singular point; measured on
    # eval_stairs: 0.05 rad drives the swing knee past its 7 rad/s limit at lift-off).
    lean: float = 0.015
    min_knee: float = 0.3
    # Where no single depth (or rise) on the contact weight lets the legs reach every sample
    # of a single support, the root's height is chosen sample by sample inside what reaches,
    # the least-jerk profile at rest at both ends (`motion.profiled_support`).
    # navigate's plans on rough scenes need it: rubbles_stairs_2_0's landing 49 -> 50 needs
    # the root 3-9 cm higher late in the swing but at most 1 cm higher at the contact, and
    # rubble_0's landing 75 -> 76 a 0.14 m rise in mid-swing (MAX_RISE: 0.15 m on the weight).
    # Only phases the held-root depth cannot make use it. False: those phases fail as before.
    profiled_reach: bool = True
    # Where no height profile reaches either (a wide or long step on rough ground: the swing
    # sole lands or lifts beyond the legs' reach, or past the hip and ankle roll limits, from
    # the root over the stance sole), the root moves horizontally too, by up to `root_shift`,
    # m, on the contact weight, while the CoM stays `single_support_margin`, m, inside the
    # stance sole at every sample (`motion.shifted_support`; the sole is 0.13 m wide, the
    # plan's one-foot postures' CoMs some 6 cm inside it). A single support that fails the
    # equilibrium check is made that way once more. Measured on the 14 phases of navigate's
    # rough-scene plans that no root height reached
    # (docs/results/2026-12-06-motion-root-shift/room.py): with the root anywhere within
    # 0.10 m horizontally, every sample of 10 of them reaches with the CoM 2.8-6.5 cm inside.
    # 0: those phases fail as before, and no phase is made again.
    root_shift: float = 0.10
    # The same margin holds the one-foot key postures (`motion.centred_postures`): one whose
    # CoM is less than this far inside its stance sole is reached with its CoM moved inside,
    # its soles, root orientation and upper body kept, where that stays within the joint
    # limits and collides nowhere. The contact generator's one-foot postures need only be in
    # equilibrium: rubbles_stairs_3_1's 239 holds its CoM 4.8 mm from the sole's side edge,
    # and Talos rolled over that edge and fell there
    # (docs/results/2026-12-07-motion-arm-detours: diagnose.txt, and the motions executed).
    single_support_margin: float = 0.03
    # Single-support configurations (held, profiled or shifted root) keep every geometry of
    # Talos but the feet this far from the terrain, m, or as far as the plan's one-foot
    # posture where it is closer (its postures are only collision-free): the first of those
    # ways that does is taken. MuJoCo tracks the motion within 1-1.5 cm; the stance knee of
    # a root lowered in front of a 0.20 m riser came within 2 mm of the next step's nosing on
    # hpp_stairs and touched it in simulation (docs/results/2026-12-06-motion-clearance).
    # 0: only the motion's collision check (every sample, `check_motion`) applies.
    body_clearance: float = 0.01
    # Double-support key postures whose CoM lies closer than this to the edge of their soles'
    # support polygon (convex hull of both soles' corners, horizontal projection), m, are
    # reached with their CoM moved towards the polygon's centre until it is this far inside
    # (whole-body IK, soles, root orientation and upper body kept). The contact generator
    # puts some landing postures' CoM at their heels (eval_stairs: 4.5-7 mm inside, hpp
    # robustness 2-7 where most postures have ~95): the motion's shift there then fails the
    # equilibrium check with the CoM's acceleration, or Talos tips over backwards in MuJoCo
    # when its tracking error exceeds that margin. The margin covers the shift's zero-moment
    # point offset (up to 2.2 cm at `com_acceleration`, above) and the tracked CoM's error
    # (1-1.5 cm in MuJoCo on eval_bridge's plans): at 0.03 m Talos rolled over the diagonal
    # edge between two soles' corners in a shift of navigate's eval_bridge plans (the CoM
    # 1.5-3 cm inside, both soles tilting). 0: every key posture is the plan's own.
    support_margin: float = 0.05
    # Single support lasts longer than lift_duration or land_duration where the CoM moves
    # far (the root comes down and up on steps): its peak acceleration along the
    # minimum-jerk move stays under this, m/s^2 (on eval_stairs a 0.11 m move in 0.6 s,
    # 1.8 m/s^2, took the equilibrium robustness below 0).
    single_support_acceleration: float = 0.5
    # The stance sole's centre of pressure in single support, from the motion's own inverse
    # dynamics (`Motion.wrenches`: the CoM's acceleration and the swing leg's angular momentum,
    # which the equilibrium check leaves out), must lie on the sole (`check_motion`, "centre
    # of pressure"), and a single support that keeps it less than this far inside the sole's
    # edges, m, is made again slower (`slowed_duration`). MuJoCo tracks the CoM within
    # 1-1.5 cm; on darpa_0 the plan's single supports took it to a sole's toe, where Talos
    # rolled over the edge and fell (docs/results/2026-12-07-motion-arm-detours).
    pressure_margin: float = 0.02
    # A single support made again slower (one that still fails the equilibrium check with its
    # CoM kept inside the stance sole, `root_shift`, or keeps its centre of pressure under
    # `pressure_margin`): its lift and landing last `slowed_duration` times as long and its
    # CoM accelerates at most `slowed_acceleration`, m/s^2 (a CoM 3 cm inside the sole's edge
    # leaves the zero-moment point inside it up to 3 cm * g / h = 0.33 m/s^2, h = 0.90 m). Made
    # without it and without centring its one-foot postures, talos_stairs15_0's landing
    # 25 -> 26 swung the CoM sideways at 0.41 m/s^2 and took the robustness to -0.68; either
    # remedy alone makes it. On darpa_0 single supports twice as long kept every centre of
    # pressure 1.4 cm inside its sole, against 0.04 cm outside
    # (docs/results/2026-12-07-motion-arm-detours/diagnose.txt). 0: not made again.
    slowed_acceleration: float = 0.25
    slowed_duration: float = 2.0
    # Sole corners on the swing path may sink this far below the terrain surface, m (the
    # 5 mm contact tolerance of docs/design.md §6 check 1), except in the first and last
    # `contact_zone` of height above the contact plane, where the sole leaves or meets it.
    terrain_tolerance: float = 0.005
    contact_zone: float = 0.01
    # Whole-body IK: Newton iterations per sample, damping of the least squares, and the
    # task error accepted at each sample (m for positions, rad for orientations).
    ik_iterations: int = 30
    ik_damping: float = 1e-8
    ik_tolerance: float = 1e-9
    # Checks along the motion: equilibrium robustness of hpp-centroidal-dynamics with the
    # CoM's acceleration (docs/design.md §6 check 4 holds key postures to >= 0), and the
    # fraction of the URDF's effort and velocity limits a sample may use.
    min_robustness: float = 0.0
    torque_ratio: float = 1.0
    velocity_ratio: float = 1.0


@dataclass(frozen=True)
class SimulationConfig:
    """How `simulate` executes a motion in MuJoCo and judges the result.

    Controller: joint torques = inverse-dynamics feed-forward of the motion (Pinocchio's
    rnea with the contact wrenches the motion plans) + joint PD on the motion's joint
    positions and velocities, clipped to the URDF's effort limits.
    """

    # Physics step, s (1 kHz); the controller runs at every step.
    timestep: float = 0.001
    # PD gains from each joint's diagonal of the mass matrix at half-sitting (armature
    # included): kp = M_ii omega^2, kd = 2 zeta M_ii omega, so every joint alone is a
    # critically damped oscillator of natural frequency `omega`, rad/s (10 Hz; omega * dt =
    # 0.06, far inside the explicit-PD stability bound of 2).
    omega: float = 62.8
    zeta: float = 1.0
    # Leg joints hold the whole robot: their stiffness must exceed gravity's, m g h =
    # 90.3 kg * 9.81 m/s^2 * 0.88 m = 780 N m/rad about an ankle, or a rigid stance tips
    # over. Leg kp is at least `leg_stiffness`, N m/rad (4 x that), with kd for damping
    # ratio `zeta` on the joint's own inertia.
    leg_stiffness: float = 3000.0
    # Land each swing sole on its planned world placement (`simulate.LandingCorrection`):
    # the robot creeps under MuJoCo's soft frictional contacts (tenths of a millimetre per
    # phase, the whole robot with its soles), and without it the landing error passes 3 cm
    # after 130-240 s of motion on flat ground and on eval_stairs. False: joint references alone.
    landing_correction: bool = True
    # Iterations of MuJoCo's noslip solver (`mjOption.noslip_iterations`) after its main
    # solver: its soft frictional contacts hold a sustained tangential load by a creep
    # velocity, not by static friction, so soles on a slope slide downhill though the load is
    # well inside the friction cone (eval_circuit's 10 deg ramp, mu = 0.5: 1-2.5 cm per double
    # support, falling after 12 steps up it). 5 suppress that creep (circuit_0: 1.4 mm at most
    # over 1 226 s, simulation 1.4 x slower). Over every scene's verified plans, the same
    # motions executed: 2 more with 5 (circuit_1, rubbles_stairs_1_1), none fewer
    # (docs/results/2026-12-06-motion-clearance). 0: MuJoCo's default, the soles creep
    # (`mjx_replay` replays with it).
    noslip_iterations: int = 5
    # Collision surface of a terrain with meshes (`robot.physics_terrain_mjcf`, one of
    # `robot.MESH_CONTACTS`): "columns", a convex column under each convex piece of its
    # faces, so that a tilted face stays a plane, or "raster", boxes over its 2 cm heights
    # raster, a tilted face a staircase of 5 mm steps (15 deg). Boxes-only terrains are their
    # boxes either way. On the raster, talos_plateformes_0 fell on its 15 deg platforms and
    # darpa_0 on its tilted blocks (docs/results/2026-12-07-motion-mesh-contact).
    mesh_contact: str = "columns"
    # Friction cone of the contacts (`mjOption.cone`: "pyramidal" or "elliptic") and the
    # ratio of the frictional to the normal constraints' impedance (`mjOption.impratio`).
    # With MuJoCo's default impratio 1 a sole loaded along a 15 deg face creeps down it
    # though the load stays well inside the friction cone (talos_plateformes_0 on columns: a
    # tangential force 0.23-0.31 of the normal one against mu = 0.5, up to 1.2 cm in a phase,
    # the noslip solver on; docs/results/2026-12-07-motion-mesh-contact/diagnose.txt). At 10
    # the same soles hold (0.16 cm at most over the motion) and a sole-sized box pushed along
    # a 15 deg slope stays (tests/test_motion_terrain.py). Elliptic cones, which MuJoCo's
    # documentation pairs with impratio > 1, made talos_stairs15_0 fall in a landing at every
    # impratio tried (1, 10, 100) where pyramidal ones execute it (cones.txt there).
    cone: str = "pyramidal"
    impratio: float = 10.0
    # Seconds simulated after the motion's last sample (the robot must stay up).
    settle: float = 0.5
    # Success: the root (base_link) stays above `min_root_height` over the higher sole in
    # contact, m (half-sitting puts it 1.02 m above the soles; a fall takes it under 0.5 m),
    # and tilts at most `max_tilt`, rad (angle between the root z axis and world z).
    min_root_height: float = 0.6
    max_tilt: float = 0.5
    # Each sole lands within `landing_position` (m) and `landing_angle` (rad) of its planned
    # placement and slips at most `max_slip` while in support, m (the task's bounds).
    landing_position: float = 0.03
    landing_angle: float = 0.0873  # 5 deg
    max_slip: float = 0.01
