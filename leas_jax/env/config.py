"""Static configuration of the LeaS environment.

Every default is the paper's value or the one docs/design.md §5 gives, with its
unit and source. These dataclasses are frozen and hashable: they fix shapes
and are baked into compiled code (gymnax's static `EnvParams` habit).
"""

import math
from dataclasses import dataclass, field


@dataclass(frozen=True)
class ReachabilityConfig:
    """Cylinders of the reachability condition, root frame (origin at base_link, z up, yaw only).

    docs/design.md §5 starts from the `talos_trunk` and `talos_*leg_rom` volumes of the HPP
    Talos data (trunk r 0.30 m [-0.63, +0.60], legs r 0.25 m [-1.06, -0.54]). The
    defaults below were calibrated by studies/reachability_calibration.py against
    the contact generator *walking* (`--truth walking --poses 48000`: a pose is feasible
    when the generator covers a 0.36 m straight guide from it; 48 000 poses of
    terrains/training_arena.toml). The static truth (one balanced, collision-free
    double-support posture) lets the root down to about 0.5 m, where the generator does not walk.

    Against the current generator these defaults give sensitivity 95.7 % and specificity
    90.0 % on the 48 000 poses (95.7 / 90.0 % on the two thirds the search fits, 95.6 /
    90.1 % on the held-out third) and 95.5 / 90.2 % on 36 000 fresh poses
    (studies/reachability_validation.py, seed 1). Cylinders alone cannot: their best
    at >= 95 % sensitivity is 95.4 / 84.8 %. The three optional terms below close the gap
    and are on by default: the lookahead legs 0.30 m ahead (ground where the next steps
    land), the foothold (a sole-sized disk of even ground near each leg) and the hands
    (the half-sitting grippers beside the trunk cylinder).
    docs/results/2026-11-22-reachability-48000-poses/ holds these figures;
    docs/results/INDEX.md, "Reachability calibration", the earlier defaults and theirs.
    """

    # m, trunk cylinder radius: calibrated (docs/design.md §5: 0.30, talos_trunk boxes span x ±0.2, y ±0.3)
    trunk_radius: float = 0.30
    # m below the root: calibrated; the root stays 0.475 m above everything within
    # trunk_radius (docs/design.md §5: -0.63, the hip); leg_top
    # keeps it 0.75 m above the ground under the legs, the hands term clear beside it
    trunk_bottom: float = -0.475
    trunk_top: float = 0.60  # m above the root: head (no effect on a heightfield, which has no overhangs)
    # m, radius of each leg cylinder: calibrated (docs/design.md §5: 0.25, talos_*leg_rom); the generator
    # needs ground near the nominal sole place, so a wide disk over-accepts
    leg_radius: float = 0.05
    leg_lateral_offset: float = 0.085  # m, leg cylinder centres at (0, ±offset) in the root frame
    # m below the root: lowest reachable sole height, calibrated (docs/design.md §5: -1.06); the generator
    # stands up to ~1.18 m above the soles (root lowered by at most 0.10 m)
    leg_bottom: float = -1.175
    leg_top: float = (
        -0.75
    )  # m below the root: highest reachable sole height, calibrated (docs/design.md §5: -0.54)
    # Optional terms (studies/reachability_false_positives.py finds the false positives
    # they target). The calibration turns all three on.
    # m, lookahead: a second pair of leg cylinders at (leg_forward, ±leg_lateral_offset) in the
    # root frame (same radius and band) must touch too: ground where the next steps land.
    # 0 disables it. Calibrated: 0.30 m (the walking truth covers a 0.36 m guide).
    leg_forward: float = 0.30
    # m, foothold: radius of the sole disk whose height spread is measured (the 0.20 x 0.13 m
    # sole has an inscribed radius of 0.065 m and a circumscribed one of 0.12 m)
    foothold_radius: float = 0.08
    # m, foothold: the flattest sole disk is searched within this radius of each leg centre
    foothold_search: float = 0.10
    # m, foothold: each leg needs, within foothold_search of its centre, a sole disk of radius
    # foothold_radius over solid terrain (no void) whose heights span at most this. None disables it.
    # Calibrated: 0.04 m (a 10-degree slope spans 0.03 m over the disk; rubble and stair
    # edges more).
    foothold_spread: float | None = 0.04
    # Hands: the Talos model keeps its arms at the half-sitting posture, where the grippers
    # reach 0.55 m sideways from the root, 0.04-0.21 m ahead of it and down to 0.39 m below it
    # (measured on the model's collision geometry), outside the trunk cylinder: guides
    # 0.3-0.55 m from a wall or pillar pass the trunk term and the generator stops there with a
    # gripper in the obstacle. Each hand disk, of radius hand_radius centred at
    # (hand_forward, ±hand_lateral) in the root frame, must hold no terrain above
    # z + hand_bottom. None disables the term. Calibrated: 0.13 m, against the generator with
    # its arms rigid at half-sitting; it now holds them in (0.38 m sideways) where they would
    # meet the terrain (GeneratorConfig.upper_bodies), so the term is stricter than it.
    hand_radius: float | None = 0.13
    hand_forward: float = 0.12  # m, hand disk centres ahead of the root (the grippers span 0.04-0.21 m)
    hand_lateral: float = 0.45  # m, hand disk centres beside the root (the grippers span 0.35-0.55 m)
    hand_bottom: float = -0.40  # m below the root: the grippers' lowest point is 0.39 m below it


@dataclass(frozen=True)
class HeightmapConfig:
    """The 11 x 7 heightmap of the observation (paper §III-B, Fig. 3; thesis of the first author)."""

    forward_step: float = 0.08  # m, spacing of the 9 points ahead
    forward_count: int = 9
    backward_step: float = 0.20  # m, spacing of the 2 points behind
    backward_count: int = 2
    lateral_step: float = 0.15  # m, spacing of the 7 columns, y = 0.15 j, j = -3..3
    lateral_half_count: int = 3
    clip_low: float = -1.4  # m, heights are (terrain - root z) clipped to [clip_low, clip_high]
    clip_high: float = -0.2  # m

    @property
    def size(self) -> int:
        return (self.forward_count + self.backward_count) * (2 * self.lateral_half_count + 1)


@dataclass(frozen=True)
class RewardWeights:
    """Weights of the reward terms (paper Table I)."""

    direction: float = 1.0  # w_dir
    orientation: float = 0.4  # w_ori
    effort_orientation: float = 0.1  # w_eff_ori
    effort_acceleration: float = 0.1  # w_eff_acc
    alive: float = 1.0  # w_alive
    # Not in the paper (0 disables it): w_clear, weight of the clearance term
    # (`reachability.clearance_shortfall`): minus the fraction of the six poses shifted by
    # `EnvConfig.clearance_margin` along the root frame's axes that are invalid. It warns
    # the policy before a near-miss instead of only ending the episode at one.
    clearance: float = 0.0


@dataclass(frozen=True)
class CurriculumConfig:
    """How envs move between the difficulty rows of a curriculum arena (a terrain with a
    `[curriculum]` table; `leas_jax.terrain.curriculum`). legged_gym's `terrain_levels` rule:
    at the end of an episode, an env that walked at least `level_up_distance` from its start
    goes one row up, one that walked less than `level_down_distance` one row down; past the
    top row it goes to a random row (so the hardest rows do not hold every env)."""

    # m, half a 6 m tile (legged_gym promotes at half its tile's length)
    level_up_distance: float = 3.0
    # m: legged_gym demotes below half the distance its command asks for in an episode; the
    # target direction here turns at random, so a fixed 1.5 m (a fifth of 400 steps at
    # 0.18 m/s) marks an episode that failed early or stood still
    level_down_distance: float = 1.5
    initial_max_level: int = 2  # first episodes start on rows 0..this (legged_gym: 5 of 10)


CLEARANCE_CONDITIONS = ("condition", "cylinders")
# Values of EnvConfig.condition whose network the heightfield carries (weights: learned_weights)
NETWORK_CONDITIONS = ("learned", "walkability")  # values of EnvConfig.clearance_condition


@dataclass(frozen=True)
class EnvConfig:
    """LeaS MDP parameters (docs/design.md §5)."""

    timestep: float = 0.10  # s, paper Table I
    episode_length: int = 400  # steps, paper Table I
    target_speed: float = 0.18  # m/s, paper §IV
    v_max: float = 0.30  # m/s, HPP Talos scripts (vMax)
    a_max: float = 0.10  # m/s^2 per unit action norm, HPP Talos scripts (aMax)
    # m/s^2 per unit of a_z; None: a_max, one bound for the three axes. The paper gives
    # no vertical bound; HPP's Talos path planners bound x and y by aMax and z apart,
    # by Kinodynamic/verticalAccelerationBound (3.0 in hpp-rbprm-corba's talos scenarios,
    # 10.0 in older scripts). The effort reward stays in action units. Its effect on
    # arena validity: docs/results/INDEX.md, "Environment".
    vertical_a_max: float | None = None
    omega_max: float = math.pi / 9.0  # rad/s, thesis of the first author
    # Actions accelerate the root in its own (yaw-rotated) frame. The paper says
    # "accelerations of the robot on each axis" without a frame; the root frame
    # makes the policy invariant to the world yaw, as its observation already is.
    actions_in_root_frame: bool = True
    reset_max_speed: float = 0.07  # m/s, initial speed along the heading drawn in [0, this]
    # Nominal height of base_link above the ground at reset. Talos half-sitting
    # puts base_link about 1.0 m above its soles (measured on the
    # example-robot-data model by leas_jax.contacts).
    nominal_root_height: float = 1.0  # m
    target_reached_distance: float = 0.20  # m, epsilon of the evaluation termination (docs/design.md §5)
    stop_at_target: bool = False  # evaluation mode: end an episode when the root is within epsilon
    # m, shift of the clearance term's six probe poses (used when rewards.clearance != 0);
    # 0.10 m kept quick policies' arena validity >= 92 % at two training seeds where 0.08 m
    # gave 89.1 % once and 0.12 m slowed them to 0.13 m/s (docs/results/INDEX.md,
    # "The clearance term")
    clearance_margin: float = 0.10
    # What judges the clearance term's six probe poses: "condition", the termination
    # condition itself (`condition`), or "cylinders", the cylinders of `reachability` whatever
    # the condition. Under the learned condition the probes are six more network evaluations
    # per step: `quick` training then costs 2.3-2.7 x the cylinders' per env step, 1.5 x with
    # the cylinders judging the probes; but so trained, no policy crossed eval_bridge (40 %
    # judged by the network) and one seed of three stopped at 0.07 m/s (2 cores, 3 seeds;
    # docs/results/2026-12-04-learned-clearance). Hence the network by default.
    clearance_condition: str = "condition"
    reset_attempts: int = 4  # candidate poses drawn per reset; the first valid one is used
    # Where resets start: "condition", near grid points where `condition`'s
    # cylinders hold for every yaw (the paper's resets), or "generator", at poses where the
    # Talos contact generator stands in double support: `spawn_yaws` random yaws at each of
    # those grid points, each verified (`leas_jax.feasibility.spawns`, cached per terrain and
    # generator). With "condition", 8 % of the training arena's spawn points at a random yaw
    # are poses the generator cannot stand on, and 10 of the shipped policy's 64 guides
    # failed at their first pose (docs/results/2026-12-01-verified-spawns).
    spawns: str = "condition"
    spawn_yaws: int = 2  # "generator" spawns: yaws verified per grid point (5.3 ms CPU each)
    # Termination condition: "cylinders", the paper's reachability condition with
    # `reachability`'s cylinders and terms, or "learned", the network of
    # `leas_jax.env.learned_feasibility` trained on the contact generator's walking verdicts
    # (`leas feasibility condition`), with its weights in `learned_weights` (an .npz,
    # relative to the repository root unless it exists as given). The spawn points stay those
    # of the cylinders in both cases (a fallback that is valid for every yaw).
    condition: str = "cylinders"
    learned_weights: str = "checkpoints/feasibility/walking.npz"
    # The network's decision threshold (a logit) as a termination, where it is not the one stored
    # with its weights; None: the stored one. The walkability model stores the lattice's, set for
    # 95 % sensitivity on single poses; an episode must pass 400 of them.
    condition_threshold: float | None = None
    reachability: ReachabilityConfig = field(default_factory=ReachabilityConfig)
    curriculum: CurriculumConfig = field(default_factory=CurriculumConfig)
    heightmap: HeightmapConfig = field(default_factory=HeightmapConfig)
    rewards: RewardWeights = field(default_factory=RewardWeights)

    @property
    def observation_size(self) -> int:
        """3 (velocity, root frame) + 1 (target angle) + heightmap."""
        return 4 + self.heightmap.size
