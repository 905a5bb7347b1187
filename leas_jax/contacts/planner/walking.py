"""The walking loop: from one planning pose of the guide to the next, keep or step.

At each planning pose the generator first tries to keep both contacts (HPP's
"maintain contacts"); if that fails, a foot leaves its comfort region, or a foot lags
more than the step trigger behind its nominal place, the foot that lags most steps
(HPP's "generate contacts"): a single-support posture (foot in the air, NaN row; root
shifted over the stance sole; balanced on the stance foot alone), then a double-support
posture with the foot on a foothold near where it should be `lookahead` s ahead on the
guide. The other foot is tried if the most lagging one cannot step; steps that bring
their foot nearer its target (`min_step_gain`) are tried on both feet before a step that
does not; where neither foot can step toward its `lookahead` target, both try toward
their places under the planning pose (`fallback_lookahead`). At most
`max_steps_per_pose` steps per planning pose (docs/design.md §6). With
`GeneratorConfig.transitions`, a single support must also lift its foot off and each foothold
take its landing as a whole-body motion takes them (`transitions.TransitionCheck`).

Host-only, not jittable.
"""

from __future__ import annotations

import math

import numpy as np

from leas_jax.contacts.planner.config import GeneratorConfig
from leas_jax.contacts.planner.footholds import SCREEN_CHUNK, Footholds
from leas_jax.contacts.planner.projection import ContactPosture, PostureProjection, rotz
from leas_jax.contacts.planner.transitions import TransitionCheck
from leas_jax.contacts.robot.model import LEFT, RIGHT, SOLE_LENGTH, SOLE_WIDTH


class Walking:
    """Steps of both feet along a guide, on the postures and footholds of one terrain.

    Args:
        projection: the terrain's posture projection.
        footholds: the terrain's footholds.
        config: generator settings.
        transitions: None, or the lift-offs and landings to check as single supports and
            footholds are chosen (`GeneratorConfig.transitions`).
    """

    def __init__(
        self,
        projection: PostureProjection,
        footholds: Footholds,
        config: GeneratorConfig,
        transitions: TransitionCheck | None = None,
    ):
        self.projection = projection
        self.footholds = footholds
        self.config = config
        self.transitions = transitions
        self._nominal_xy = [tuple(row[:2].tolist()) for row in projection.talos.nominal_sole_in_root]

    def _foot_lag(self, guide_pose, side, pos, rot) -> tuple[float, float]:
        """(horizontal distance, |yaw difference|) of a sole to its nominal place under a guide pose."""
        yaw0 = float(guide_pose[3])
        c, s = math.cos(yaw0), math.sin(yaw0)
        dx, dy = float(pos[0] - guide_pose[0]), float(pos[1] - guide_pose[1])
        nx, ny = self._nominal_xy[side]
        dist = math.hypot(c * dx + s * dy - nx, -s * dx + c * dy - ny)
        yaw = math.atan2(rot[1, 0], rot[0, 0]) - yaw0
        return dist, abs((yaw + math.pi) % (2 * math.pi) - math.pi)

    def comfortable(self, guide_pose, contacts) -> bool:
        """Whether every contact sole (side, pos [3], rot [3, 3]) lies in its comfort region
        under a guide pose [4]: `max_foot_offset` from its nominal place, `max_foot_yaw` in yaw."""
        cfg = self.config
        for side, pos, rot in contacts:
            dist, yaw = self._foot_lag(guide_pose, side, pos, rot)
            if dist > cfg.max_foot_offset or yaw > cfg.max_foot_yaw:
                return False
        return True

    def _lag_score(self, guide_pose, side, pos, rot) -> float:
        """A sole's lag behind its nominal place, in step triggers (> 1: it should step)."""
        dist, yaw = self._foot_lag(guide_pose, side, pos, rot)
        return max(dist / self.config.step_trigger, yaw / self.config.step_trigger_yaw)

    def _step_gap(self, pos, target_pos) -> float:
        """How far a sole at pos [3] is from a step target, in step triggers (horizontal).

        Position only: on a narrow beam soles turn to its axis, away from the target's yaw,
        and a yaw term made every such step look like no progress."""
        return (
            math.hypot(float(pos[0] - target_pos[0]), float(pos[1] - target_pos[1]))
            / self.config.step_trigger
        )

    def step(
        self,
        guide,
        timestep,
        index: int,
        feet,
        side: int,
        min_gain: float | None,
        lookahead: float,
    ) -> tuple[list[ContactPosture] | None, bool]:
        """Move foot `side` at planning index `index`.

        min_gain: None, or the least cut of the foot's gap to its step target (`_step_gap`)
        a placement must bring, unless it brings the gap under 1.
        lookahead: s; the step target is the foot's nominal place under the guide pose this
        far ahead of the planning pose.

        Returns:
            ([single-support, double-support] postures, or None), and whether `min_gain`
            passed over a placement (without it the step might succeed)."""
        cfg = self.config
        pose = guide[index]
        other = 1 - side
        stance = (other, feet[other][0], feet[other][1])
        old_pos, old_rot = feet[side]
        ahead = guide[min(index + int(round(lookahead / timestep)), len(guide) - 1)]
        target_pos, target_yaw = self.footholds.nominal_placement(ahead, side)
        target_pos = self.footholds.beam_lane(side, target_pos, target_yaw)
        lift = self._swing_lift(old_pos, target_pos)
        lifted = [(old_pos + np.array([0.0, 0.0, lift]), old_rot, False)]
        # Or under its hip, as high above its last contact (or above the half-sitting sole
        # height where that is higher, as on a step up). The half-sitting height alone put the
        # foot 12 cm underground under a root 0.85 m above the ground, where crouched walking
        # fails otherwise (the trailing foot cannot stay flat: ankle pitch < -1.31 rad).
        nominal_pos, _ = self.footholds.nominal_placement(pose, side)
        nominal_pos[2] = max(nominal_pos[2], old_pos[2]) + lift
        lifted.append((nominal_pos, rotz(pose[3]), False))
        # Or swing_clearance farther out, following the root's shift toward the stance sole:
        # where that sole is nearer the guide's line than its nominal place, the stance
        # shin meets a foot held under its hip.
        outward = rotz(pose[3])[:, 1] * (1.0 if side == LEFT else -1.0)
        lifted.append((nominal_pos + cfg.swing_clearance * outward, rotz(pose[3]), True))
        single = self._lifted(pose, index, stance, (side, lifted), feet[other][0][:2], feet[side])
        if single is None and cfg.single_support_com_inset is not None:
            # The root shift that brings the CoM over the sole's centre can put the body into
            # the terrain (an arm into a pillar beside the path), or a crouched swing knee
            # against the stance knee at lift-off; a CoM target on the sole, inset from its
            # edges, nearer the guide, needs a shorter shift.
            nearer = self._sole_point_toward(feet[other], pose[:2], cfg.single_support_com_inset)
            single = self._lifted(pose, index, stance, (side, lifted), nearer, feet[side])
        if single is None:
            return None, False
        double, held_back = self._land(
            pose, index, feet, side, stance, target_pos, target_yaw, min_gain, single
        )
        return (None if double is None else [single, double]), held_back

    def _lifted(self, pose, index: int, stance, air, com_target, contact) -> ContactPosture | None:
        """The one-foot posture (`PostureProjection.posture` with `air`, the CoM aimed at
        com_target [2]) whose swing foot can leave `contact` (pos [3], rot [3, 3]) where
        transitions are checked (`TransitionCheck.lift_off`), or None."""
        single = self.projection.posture(pose, index, [stance], air=air, com_target=com_target)
        if single is None or self.transitions is None:
            return single
        if self.transitions.lift_off(single, air[0], contact) is not None:
            self.projection.count_rejection("transition: lift-off")
            return None
        return single

    def _swing_lift(self, old_pos, target_pos) -> float:
        """m, how high above its last contact old_pos [3] a foot stepping toward target_pos
        [3] (world) is held in the air: `swing_lift_on_rise` where the terrain between them
        rises more than `swing_rise` above that contact (`Footholds.rise`), else `swing_lift`."""
        cfg = self.config
        if cfg.swing_lift_on_rise is not None and self.footholds.rise(old_pos, target_pos) > cfg.swing_rise:
            return cfg.swing_lift_on_rise
        return cfg.swing_lift

    def _land(
        self,
        pose,
        index: int,
        feet,
        side: int,
        stance,
        target_pos,
        target_yaw: float,
        min_gain,
        single: ContactPosture,
    ) -> tuple[ContactPosture | None, bool]:
        """The double-support posture of foot `side` landing near a step target (mutates
        `feet` on success), and whether `min_gain` passed over a placement (see `step`).

        pose: [4] planning pose; stance: (side, pos [3], rot [3, 3]) of the other sole;
        target_pos: [3] world; target_yaw: rad; single: the one-foot posture the foot lands
        from (its landing checked where transitions are, `TransitionCheck.landing`)."""
        cfg = self.config
        old_pos = feet[side][0]
        # Same candidates, in the same order, as `candidates(...)[:max_candidates]`, but
        # screened a few at a time: the first or second usually gives a posture, and
        # screening the whole pool at once costs a quarter of a plan's time.
        pool_pos, pool_rot = self.footholds.candidate_pool(
            side, pose, target_pos, target_yaw, avoid=feet[1 - side]
        )
        needed = math.inf if min_gain is None else max(1.0, self._step_gap(old_pos, target_pos) - min_gain)
        tried, held_back = 0, False
        for start in range(0, len(pool_pos), SCREEN_CHUNK):
            chunk = slice(start, start + SCREEN_CHUNK)
            keep = self.footholds.screen(side, pose, pool_pos[chunk], pool_rot[chunk])
            for pos, rot in zip(pool_pos[chunk][keep], pool_rot[chunk][keep]):
                if tried == cfg.max_candidates:
                    return None, held_back
                tried += 1
                contacts = [stance, (side, pos, rot)]
                if self._step_gap(pos, target_pos) > needed:
                    held_back = True
                    continue
                if not self.comfortable(pose, contacts[1:]):
                    continue
                double = self.projection.posture(pose, index, contacts)
                if double is None:
                    continue
                if self.transitions is not None and self.transitions.landing(
                    single, side, (pos, rot), double
                ):
                    self.projection.count_rejection("transition: landing")
                    continue
                feet[side] = (pos, rot)
                return double, held_back
        if tried == 0:
            self.projection.count_rejection("no foothold")
        return None, held_back

    def step_either(self, guide, timestep, index: int, feet, order) -> list[ContactPosture] | None:
        """Step one foot, trying the sides in `order`: first with `min_step_gain`, then, on
        the sides where that test passed a placement over, without it; all of this toward
        the `lookahead` target, then toward the `fallback_lookahead` one. Postures or None.

        Both sides try the far target before either tries the near one: a short step of the
        first side can leave the feet where the next planning poses fail, where the other
        side's full step would not."""
        cfg = self.config
        lookaheads = [cfg.lookahead]
        if cfg.fallback_lookahead is not None and cfg.fallback_lookahead != cfg.lookahead:
            lookaheads.append(cfg.fallback_lookahead)
        for lookahead in lookaheads:
            retry = []
            for side in order:
                stepped, held_back = self.step(
                    guide, timestep, index, feet, side, cfg.min_step_gain, lookahead
                )
                if stepped is not None:
                    return stepped
                if held_back:
                    retry.append(side)
            for side in retry:
                stepped, _ = self.step(guide, timestep, index, feet, side, None, lookahead)
                if stepped is not None:
                    return stepped
        return None

    @staticmethod
    def _sole_point_toward(foot, xy, inset: float) -> np.ndarray:
        """[2] the point of a sole's rectangle shrunk by `inset` (m) nearest to `xy` [2] (world).

        foot: (pos [3], rot [3, 3]) world sole placement; the rectangle is taken in its yaw frame.
        """
        pos, rot = foot
        yaw = math.atan2(float(rot[1, 0]), float(rot[0, 0]))
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = float(xy[0]) - float(pos[0]), float(xy[1]) - float(pos[1])
        u = min(max(c * dx + s * dy, -(SOLE_LENGTH / 2 - inset)), SOLE_LENGTH / 2 - inset)
        v = min(max(-s * dx + c * dy, -(SOLE_WIDTH / 2 - inset)), SOLE_WIDTH / 2 - inset)
        return np.array([float(pos[0]) + c * u - s * v, float(pos[1]) + s * u + c * v])

    def advance(self, guide, timestep, index: int, feet) -> list[ContactPosture] | None:
        """Postures that bring the robot to planning pose `index` (mutates `feet`), or None.

        Args:
            guide: [T, 4] root poses (x, y, z, yaw), world frame.
            timestep: s between guide poses.
            index: the planning pose's guide index.
            feet: [left, right] current sole placements (pos [3], rot [3, 3]), world.
        """
        cfg = self.config
        pose = guide[index]

        def stance():
            return [(side, feet[side][0], feet[side][1]) for side in (LEFT, RIGHT)]

        def scores():
            return [self._lag_score(pose, side, *feet[side]) for side in (LEFT, RIGHT)]

        # The posture keeping both contacts is built only when it is used: here if no foot
        # lags, else after the steps, if none was possible (`step` changes `feet` only when
        # it succeeds, so `stance()` is then still the one of this point).
        comfortable = self.comfortable(pose, stance())
        keep = None
        if comfortable and max(scores()) <= 1.0:
            keep = self.projection.posture(pose, index, stance())
            if keep is not None:
                return [keep]
            comfortable = False  # built and failed: not again below
        added: list[ContactPosture] = []
        for _ in range(cfg.max_steps_per_pose):
            lag = scores()
            stepped = self.step_either(
                guide, timestep, index, feet, sorted((LEFT, RIGHT), key=lambda s: -lag[s])
            )
            if stepped is None:
                break
            added.extend(stepped)
            if self.comfortable(pose, stance()):
                return added  # its last double-support posture stands at this pose
        if not added and comfortable:
            keep = self.projection.posture(pose, index, stance())
        if not added and keep is not None:
            return [keep]  # no step possible but the stance still holds: step later
        return None
