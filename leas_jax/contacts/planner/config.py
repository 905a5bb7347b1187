"""Settings of the contact generator (docs/design.md §6); every stage reads them."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from leas_jax.contacts.robot.database import DatabaseConfig
from leas_jax.contacts.robot.model import FRICTION


@dataclass(frozen=True)
class TransitionConfig:
    """What the generator asks of the configurations a whole-body motion passes through between
    key postures (`transitions.TransitionCheck`): at a single support's lift-off (both soles
    still on their contacts, the root and upper body already the one-foot posture's) and its
    touchdown (the swing sole on its new contact, the root still held), and over the new contact
    at the landing's apex. Each must be reachable with the root moved up or down as
    `leas_jax.motion` moves it, clear of the terrain, and free of self collision.

    The defaults are the motion's own bounds (`leas_jax.motion.config.MotionConfig` and
    `leas_jax.motion.motion`; tests/test_contacts_transitions.py holds them equal): a plan made
    with them checked holds no lift-off or touchdown that `make_motion` refuses for reach or
    clearance at its ends.
    """

    min_knee: float = 0.3  # rad, knee bend at a contact end (MotionConfig.min_knee)
    body_clearance: float = (
        0.01  # m, geometries other than the feet from the terrain (MotionConfig.body_clearance)
    )
    apex_clearance: float = 0.05  # m, the landing's apex above the terrain (MotionConfig.swing_clearance)
    max_dip: float = 0.30  # m, the root's lowering in single support (motion.MAX_DIP)
    max_rise: float = 0.15  # m, and its rise (motion.MAX_RISE)
    root_step: float = 0.02  # m, between the root heights tried (`root_offsets`)

    def root_offsets(self) -> list[float]:
        """m, vertical root offsets in the order the motion tries them (`motion.root_dip`): 0,
        then lower by `root_step` down to -max_dip, then higher up to max_rise."""
        return [0.0] + [-d for d in self._steps_to(self.max_dip)] + self._steps_to(self.max_rise)

    def _steps_to(self, bound: float) -> list[float]:
        """m, multiples of `root_step` under `bound`, then `bound` itself (none where it is 0)."""
        steps = [self.root_step * k for k in range(1, math.ceil(bound / self.root_step - 1e-9))]
        return steps + ([bound] if bound > 0.0 else [])


@dataclass(frozen=True)
class GeneratorConfig:
    """Settings of the contact generator; defaults from docs/design.md §6 and the Talos model.

    A default chosen against a failure names the test that guards it
    (tests/test_contacts_generator.py).
    """

    # s between planning poses: every 5th guide pose at the env's 0.1 s (docs/design.md §6),
    # whatever the guide's own timestep, so a guide sampled every 0.01 s as HPP's generator
    # samples a path (RBKino, `BaselineConfig.rbkino_timestep`) is planned as often in time.
    planning_interval: float = 0.5
    # Where a planning pose cannot be reached from the last one, the generator plans again at
    # every this-many guide poses between them. A root turning 30-100 degrees within 0.5 s
    # (RBKino starting turned away from its goal, Table II) leaves the feet beyond the hip-yaw
    # and comfort limits at the next planning pose; stepping at the yaws on the way follows
    # it. HPP's generator, which the paper's Table II used, samples the guide every 0.01 s
    # (hpp-rbprm-corba's abstract_contact_generator.py, `dt`), with no bound on the steps
    # per second (docs/results/2026-12-02-refined-planning-poses;
    # test_a_fast_turn_is_followed_through_the_poses_between). None: never.
    refine_stride: int | None = 1
    lookahead: float = 0.7  # s, where a moving foot should land on the guide, docs/design.md §6 (0.6-0.8 s)
    # s, where a step aims when no foothold near the `lookahead` target gives a posture: the
    # foot's place under the planning pose itself. A guide drifting sideways puts the
    # lookahead target of the foot on the far side onto the other sole (then no candidate
    # is left), and one turning or nearing an edge puts it where the leg cannot stand;
    # the nearer target is what the foot needs to follow the root at all
    # (test_a_step_falls_back_to_the_place_under_the_root). None: no fallback.
    fallback_lookahead: float | None = 0.0
    mu: float = FRICTION  # friction coefficient, docs/design.md §6 checks 1 and 4
    # m, horizontal lag of a foot behind its nominal place that makes it step. Small enough
    # that on a slow climb (LeaS slows to ~0.06 m/s on eval_stairs, its root rising with each
    # tread) the trailing foot follows before its leg is overstretched
    # (test_slow_leas_climb_of_eval_stairs_is_covered); smaller means more footsteps on flat ground.
    step_trigger: float = 0.07
    step_trigger_yaw: float = 0.20  # rad, yaw lag that makes a foot step (~ pi/9 rad/s x 0.5 s x 1.15)
    # Steps that bring their foot nearer its step target come first: the horizontal gap, in
    # step triggers, cut by at least this much, or to under 1. Only when neither foot has such
    # a step may one step with less. Without it, beside a void, a foot whose place is out of
    # reach keeps stepping in place while the other, which could lead, never moves
    # (test_the_foot_that_can_lead_steps_first_beside_a_void).
    # None: any step, the most lagging foot first.
    min_step_gain: float | None = 0.5
    # m, comfort region: sole to its nominal place in the root frame. A foot farther out
    # steps; a foothold farther out is not a candidate. 0.25 m stopped guides on rubble and
    # stairs where the one tile a foot could take lay 0.26-0.32 m out (with
    # `candidate_radius` 0.30 and `max_candidates` 24: 70.7 -> 84.0 % of the shipped policy's
    # arena guides, docs/results/2026-12-02-retry-settings). Leg IK, collisions and
    # equilibrium bound every posture anyway; HPP's generator keeps a contact as long as
    # its limb reaches it.
    max_foot_offset: float = 0.32
    # rad, comfort region in yaw; the hip-yaw joints allow 0.35 rad inward, 1.57 rad outward
    max_foot_yaw: float = 0.5
    max_steps_per_pose: int = 2  # steps per planning pose (0.5 s at the default planning_interval)
    max_root_offset_xy: float = (
        0.12  # m, root shift off the guide to reach equilibrium (~ half the foot spacing + margin)
    )
    # m, the same bound for a single-support posture, where the CoM must be over the stance
    # sole. That sole may lie `max_foot_offset` (0.32 m) from its nominal place, itself 0.085 m
    # beside the root: with max_root_offset_xy the generator accepted feet it could not then
    # balance on (the most frequent reason its plans stopped on policy guides, 45 of 116 in
    # docs/results/2026-12-02-arms-in; 0.20 m with a 0.25 m comfort region). HPP's generator
    # asks no balance of a one-contact state at all (hpp-rbprm ContactGenHelper,
    # stableForOneContact = false by default); this one keeps it, quasi-static, with the
    # root shifted this far (test_single_support_over_a_far_stance_sole).
    max_single_support_offset_xy: float = 0.25
    # m, where no stance under the guide's first pose passes every check, both soles' targets
    # are moved together this far in each of 8 root-frame directions (nearest first; the
    # first candidate of each foot), the root following within `max_root_offset_xy`. Beside a
    # 0.1 m box the shin's ankle linkage, 4 cm above the sole and out past its side, meets
    # the box at the nominal stance and at every candidate near it: 17 of the shipped policy's
    # 256 arena guides stopped at their first pose, 16 of them so
    # (docs/results/2026-12-02-step-fallback; test_first_stance_steps_away_from_a_box_beside_a_shin).
    # () tries the nominal stance only.
    stance_shifts: tuple = (0.05, 0.10)
    # m, where an arm or gripper meets the terrain in every upper body (`upper_bodies`, the
    # last with its shoulders 0.38 m to the side), the root shifted this far sideways off the
    # guide, either side (nearest first; the usual root bounds hold). The training condition's
    # trunk cylinder lets a guide pass a pillar or wall 0.30 m from the root
    # (test_root_steps_sideways_off_a_pillar_the_arms_meet). () never.
    arm_clearance_shifts: tuple = (0.06, 0.12)
    # m, where a leg meets the terrain in a double-support posture with one sole more than
    # `swing_rise` above the other and ahead of it (a foot on a riser's tread, the other on the
    # ground before it), the root held this far back along the heading (nearest first; the
    # usual root bounds hold): the lower leg's knee, 0.2 m ahead of its ankle, otherwise meets
    # the edge of a riser about as high as the knee. Straight guides up 0.29-0.34 m steps
    # stopped at the riser's foot while lower and higher ones passed
    # (docs/results/2026-12-06-generator-steps; test_a_step_up_as_high_as_the_knee_is_climbed).
    # () never.
    step_up_root_shifts: tuple = (0.04, 0.08, 0.12)
    max_root_offset_z: float = 0.10  # m, root lowering when a leg is overstretched (stairs of 0.15 m rise)
    min_knee: float = (
        0.05  # rad, knee bend kept when lowering the root (away from the straight-leg singularity)
    )
    # m, database samples this close to a step target are candidates: on rubble the nearest
    # tile a sole fits on lies up to 0.3 m from where the foot should go
    candidate_radius: float = 0.30
    candidate_slab: float = 0.10  # m, samples this close (vertically) to a face are dropped on it
    candidate_grid: float = 0.01  # m, candidates closer than this are merged (one per cell)
    max_candidates: int = 24  # candidates tried per step (in rank order)
    # On a beam (a face narrower than `beam_width` across one of its edges), a sole turned
    # by at most `beam_align_yaw` to the beam's axis is a candidate too, after the one at
    # the guide's yaw at the same place. eval_bridge's 0.30 m beam leaves 2 cm beside two
    # soles side by side; at 11 degrees off its axis they need 5 cm more, and guides wander
    # that much (test_soles_turn_to_a_narrow_bridge_axis). Beams only: soles aligned to every
    # face's edges miss stair treads. Walking along such a beam, each foot's step target also
    # moves into its lane (`footholds.Footholds.beam_lane`).
    beam_width: float = 0.5  # m; the arena's bridges are 0.30-0.45 m wide, its stair treads 0.30 m deep
    beam_align_yaw: float = (
        0.35  # rad, the hip-yaw joint's inward limit (max_foot_yaw is 0.5); 0 disables (lanes too)
    )
    # rad, turns of a sole off the step's yaw tried, smallest first and each way, on a face that
    # holds no candidate sole at the step's yaw (nor at a beam's axis): a 0.30 x 0.20 m debris
    # tile holds the 0.20 x 0.13 m sole only within 20 degrees of one of its axes, and a guide
    # crossing a field of them at 40 degrees (slalom_debris) left both feet on the ground
    # before it (test_a_sole_turns_to_fit_a_small_tile). Up to `max_foot_yaw`; the leg's IK
    # then bounds the turn by its hip-yaw joint (0.35 rad inward). () never.
    sole_turns: tuple = tuple(round(0.05 * k, 2) for k in range(1, 11))
    beam_drop: float = 0.05  # m, a beam's lanes need terrain this much lower this far beyond both its edges
    # m, sole rectangle kept this far inside the face polygon (docs/design.md §6's 5 mm tolerance). Two
    # soles side by side take 2 x 0.13 + feet_gap + 2 x edge_margin, which must fit eval_bridge's
    # 0.30 m (test_narrow_bridge_crossed_on_its_centre_line).
    edge_margin: float = 0.005
    cover_tol: float = (
        0.005  # m, a sole is covered if the terrain rises more than this above it (docs/design.md §6: 5 mm)
    )
    feet_gap: float = 0.01  # m, minimal gap between the two sole rectangles (see edge_margin)
    swing_lift: float = 0.05  # m, height of a foot in the air above its last contact
    # m: where the terrain between a foot's last contact and its step target rises more than
    # `swing_rise` above that contact (a stair's riser ahead), the foot in the air is held this
    # high above the contact instead, clear of the riser its shin or toe meets at swing_lift.
    # Only where it rises: held this high on flat ground, the feet also followed a 4 rad/s
    # turn in place (test_turning_too_fast_stops) that the low swing's leg collisions stop;
    # docs/results/2026-12-05-swing-lift-on-rise. None: swing_lift everywhere.
    swing_lift_on_rise: float | None = None
    swing_rise: float = 0.03  # m, 6 x cover_tol, under the arena's lowest riser
    swing_clearance: float = (
        0.05  # m, how far out of its hip a lifted foot may be held (walking.Walking.step)
    )
    # m: where single support with the CoM over the stance sole's centre fails, the CoM is
    # aimed instead at the point of that sole, this far inside its edges, nearest the guide
    # root (a shorter root shift; eval_circuit's pillars). 3 cm leaves twice flat_com_margin. None: off.
    single_support_com_inset: float | None = 0.03
    min_robustness: float = (
        1.0  # hpp-centroidal-dynamics robustness kept (>= 0 is the contract; ~3 mm of CoM margin)
    )
    # m, on horizontal faces a CoM this far inside the support polygon is in equilibrium
    # without solving the LP (equilibrium.flat_support_margin); 1.5 cm is ~5 x the CoM
    # margin of min_robustness, so the shortcut never accepts what the LP would reject
    flat_com_margin: float = 0.015
    # Upper-body postures a posture may hold (`robot.model.UPPER_BODY_POSTURES`), in the order
    # tried: the next one only where an arm or gripper of the one before meets the terrain.
    # The arms held in clear walls and pillars 0.17 m nearer the root than half-sitting's
    # (test_arms_held_in_pass_a_pillar_beside_the_path); ("half_sitting",) is the paper's
    # rigid upper body.
    upper_bodies: tuple[str, ...] = ("half_sitting", "arms_in")
    database: DatabaseConfig = field(default_factory=DatabaseConfig)
    # Where a planning pose cannot be reached, the generator goes back `retry_backtrack`
    # planning poses and plans that stretch again with each of these alternative settings in
    # turn (overrides of this config's fields, ((name, value), ...) each), then goes on with
    # its own. The plan is greedy: a foot placed well for the next pose can leave the feet
    # where a pose 1-2 s on fails, and which setting avoids it differs from guide to guide
    # (farther-ahead steps before a climb, a longer root shift over a far stance sole on
    # rubble; a swing held high over a riser); see docs/results/2026-12-02-retry-settings and
    # 2026-12-05-swing-lift-on-rise. Only the walking settings in
    # RETRY_FIELDS may change. () never retries.
    retry_settings: tuple = (
        (("lookahead", 0.9),),
        (("candidate_radius", 0.40), ("max_candidates", 48)),
        (("max_foot_offset", 0.40),),
        (("lookahead", 0.5),),
        (("step_trigger", 0.05),),
        (("swing_lift", 0.03),),
        (("swing_lift_on_rise", 0.15),),
        (("lookahead", 1.1),),
    )
    retry_backtrack: int = 4  # planning poses re-planned before the one that failed (2 s)
    # None, or the transitions between key postures a whole-body motion needs, checked as each
    # single support and each landing is chosen (`TransitionConfig`). Off by default: the paper's
    # generator checks key postures only, and the figures of the policy's evaluation are
    # measured that way; `leas navigate --motion` and `leas evaluate --motion` turn it on.
    # Without it, 22 of 55 verified plans over every scene failed `make_motion`, 18 of them in a
    # single support's lift or landing (docs/results/2026-12-06-motion-held-bulge).
    transitions: TransitionConfig | None = None

    def __post_init__(self):
        from leas_jax.contacts.robot.model import UPPER_BODY_POSTURES

        unknown = [name for name in self.upper_bodies if name not in UPPER_BODY_POSTURES]
        if not self.upper_bodies or unknown:
            raise ValueError(
                f"GeneratorConfig.upper_bodies must name one or more of {sorted(UPPER_BODY_POSTURES)}, "
                f"got {self.upper_bodies!r}"
            )
        if not (isinstance(self.planning_interval, (int, float)) and 0.0 < self.planning_interval < math.inf):
            raise ValueError(
                f"GeneratorConfig.planning_interval must be a positive number of seconds, "
                f"got {self.planning_interval!r}"
            )
        if self.refine_stride is not None and not (
            isinstance(self.refine_stride, int) and self.refine_stride >= 1
        ):
            raise ValueError(
                f"GeneratorConfig.refine_stride must be None or an int >= 1, got {self.refine_stride!r}"
            )
        if not (isinstance(self.retry_backtrack, int) and self.retry_backtrack >= 0):
            raise ValueError(
                f"GeneratorConfig.retry_backtrack must be an int >= 0, got {self.retry_backtrack!r}"
            )
        for overrides in self.retry_settings:
            self.retried(overrides)
        _check_distances("stance_shifts", self.stance_shifts, "max_root_offset_xy", self.max_root_offset_xy)
        _check_distances(
            "step_up_root_shifts", self.step_up_root_shifts, "max_root_offset_xy", self.max_root_offset_xy
        )
        _check_distances(
            "arm_clearance_shifts",
            self.arm_clearance_shifts,
            "max_single_support_offset_xy",
            self.max_single_support_offset_xy,
        )

    def planning_stride(self, timestep: float) -> int:
        """Guide poses per planning pose for a guide sampled every `timestep` s (>= 1)."""
        return max(1, int(round(self.planning_interval / timestep)))

    def retried(self, overrides) -> GeneratorConfig:
        """This config with one entry of `retry_settings` applied (and no retries of its own).

        Raises ValueError on a field outside RETRY_FIELDS or a malformed entry."""
        try:
            changes = dict(overrides)
        except (TypeError, ValueError):
            raise ValueError(
                f"GeneratorConfig.retry_settings entries must be ((name, value), ...), got {overrides!r}"
            ) from None
        unknown = sorted(set(changes) - RETRY_FIELDS)
        if unknown:
            raise ValueError(
                f"GeneratorConfig.retry_settings may change only {sorted(RETRY_FIELDS)}, got {unknown}"
            )
        return replace(self, retry_settings=(), **changes)


# Settings the generator reads at each step (not when it builds its stages): what a retry
# (`GeneratorConfig.retry_settings`) may change on the same stages. The root's bounds
# (`max_root_offset_xy`, `max_single_support_offset_xy`, `max_root_offset_z`) are not among
# them: they say how closely a plan follows its guide, which `contacts.verify` checks.
RETRY_FIELDS = frozenset(
    {
        "lookahead",
        "fallback_lookahead",
        "step_trigger",
        "step_trigger_yaw",
        "min_step_gain",
        "max_foot_offset",
        "max_foot_yaw",
        "max_steps_per_pose",
        "candidate_radius",
        "max_candidates",
        "swing_lift",
        "swing_lift_on_rise",
        "swing_rise",
        "swing_clearance",
    }
)


def _check_distances(name: str, values, bound_name: str, bound: float) -> None:
    """Raise ValueError unless every one of `values` is a distance in (0, bound] m."""
    if not all(isinstance(d, (int, float)) and 0.0 < d <= bound for d in values):
        raise ValueError(
            f"GeneratorConfig.{name} must be distances in (0, {bound_name} = {bound}] m, got {values!r}"
        )


def motion_generator_config() -> GeneratorConfig:
    """The generator's defaults with the transitions a whole-body motion needs checked
    (`TransitionConfig`): how `leas navigate --motion` and `leas evaluate --motion` plan."""
    return GeneratorConfig(transitions=TransitionConfig())
