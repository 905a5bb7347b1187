"""Transitions between key postures: can Talos move into and out of a single support?

A contact plan's key postures are each checked (`projection`). A whole-body motion between
them (`leas_jax.motion`) also passes through configurations no key posture holds:

- at a single support's **lift-off**, both soles are still on their contacts while the root
  and upper body are already the one-foot posture's (its CoM over the stance sole);
- at its **touchdown**, the swing sole is on its new contact and the root still held where the
  one-foot posture has it;
- on the way, the swing sole rises to the landing's apex (`swing_apex`), travels at that height
  and comes down over its new contact; it is checked risen, halfway and over the contact.
- the double support a landing settles into is shifted through with both soles down; the
  motion holds only single supports clear of the terrain by a margin, so the landing's key
  posture is held to it here.

Where the root of the one-foot posture stays, a crouched plan's knees meet at lift-off, and a
far foothold is out of the swing leg's reach at touchdown; `make_motion` then refuses the
plan, which the key postures alone passed (docs/results/2026-12-06-motion-held-bulge). Each of
these configurations is taken here as the motion takes it (`leas_jax.motion.motion.
held_root_configuration`): the one-foot posture with its root lowered by the least depth, else
raised by the least height, at which both legs reach the soles by analytic IK with their knees
bent (`TransitionConfig.root_offsets`); there every geometry but the feet must be
`body_clearance` clear of the terrain, and no geometry in self collision
(`robot.clearance.BodyClearance.too_close`). The root's own turn between postures is not
followed: the one-foot posture's orientation stands for the lift-off's.

Host-only (Pinocchio, coal), not jittable.
"""

from __future__ import annotations

import numpy as np

from leas_jax.contacts.planner.config import TransitionConfig
from leas_jax.contacts.planner.projection import ContactPosture, PostureProjection
from leas_jax.contacts.robot.clearance import BodyClearance
from leas_jax.contacts.robot.model import SOLE_LENGTH, SOLE_WIDTH, matrix_from_quat_xyzw


def terrain_top(terrain, start: np.ndarray, end: np.ndarray) -> float:
    """Highest terrain (m) under a sole moved straight from start [3] to end [3], world.

    The terrain is sampled under the sole rectangle (its corners and centre) at 21 points
    along the straight segment.
    """
    reach = np.hypot(SOLE_LENGTH, SOLE_WIDTH) / 2
    line = np.linspace(start[:2], end[:2], 21)
    offsets = np.array([[0.0, 0.0], [reach, 0.0], [-reach, 0.0], [0.0, reach], [0.0, -reach]])
    heights = terrain.height_at((line[:, None, :] + offsets[None]).reshape(-1, 2))
    return float(heights.max())


def swing_apex(terrain, start: np.ndarray, end: np.ndarray, clearance: float) -> float:
    """Height (m) of a swing path's apex: `clearance` above both ends [3] and the terrain between."""
    return max(float(start[2]), float(end[2]), terrain_top(terrain, start, end)) + clearance


def halfway_rotation(rot0: np.ndarray, rot1: np.ndarray) -> np.ndarray:
    """[3, 3] the rotation halfway along the geodesic from rot0 [3, 3] to rot1 [3, 3]."""
    import pinocchio as pin

    return rot0 @ pin.exp3(0.5 * pin.log3(rot0.T @ rot1))


class TransitionCheck:
    """The lift-off, apex and touchdown configurations of single supports on one terrain.

    Host-only, not jittable; one per process or thread (it shares the projection's state).

    Args:
        terrain: a leas_jax.terrain.Terrain.
        projection: the terrain's posture projection (its Talos, leg IK and collision objects).
        config: the bounds taken from the motion.
    """

    def __init__(self, terrain, projection: PostureProjection, config: TransitionConfig):
        self.terrain = terrain
        self.projection = projection
        self.config = config
        self.clearance = BodyClearance(projection.talos, terrain)
        self._offsets = config.root_offsets()
        self._margin_of: tuple[bytes, float] | None = None

    def lift_off(self, single: ContactPosture, swing: int, contact) -> str | None:
        """Why the swing foot cannot leave `contact` for the one-foot posture `single`, or None.

        Args:
            single: a one-foot posture (its `feet` row `swing` NaN).
            swing: the side in the air (LEFT or RIGHT).
            contact: (pos [3], rot [3, 3]) the swing sole's placement before, world.
        """
        soles = [(1 - swing, *self._stance(single, swing)), (swing, *contact)]
        reason = self._held(single.q, soles, np.full(2, self.config.min_knee))
        return None if reason is None else f"lift-off: {reason}"

    def landing(self, single: ContactPosture, swing: int, contact, settled: ContactPosture) -> str | None:
        """Why the swing foot of `single` cannot come down on `contact`, or None: the sole
        risen to the apex where it is, halfway to the contact at the apex, over it at the apex,
        then on it (touchdown); and the double support the motion then shifts into, `settled`,
        must keep `body_clearance` from the terrain too (a key posture is only collision-free:
        on 0.20 m stairs a landing posture held a knee 1.2 mm from the next nosing, and the
        knee touched it in simulation, docs/results/2026-12-07-motion-transitions).

        Args:
            single: a one-foot posture (its `feet` row `swing` NaN, its swing sole in the air).
            swing: the side in the air.
            contact: (pos [3], rot [3, 3]) the new placement, world.
            settled: the double-support posture with the swing sole on `contact`.
        """
        cfg = self.config
        reason = self.clearance.too_close(settled.q, cfg.body_clearance)
        if reason is not None:
            return f"settled: {reason}"
        stance = (1 - swing, *self._stance(single, swing))
        lifted = self.projection.talos.sole_placements(single.q)[swing]
        start, start_rot = lifted[:3], matrix_from_quat_xyzw(lifted[3:])
        pos, rot = contact
        apex = swing_apex(self.terrain, start, pos, cfg.apex_clearance)
        bent = np.array([single.q[leg.q_index[3]] for leg in self.projection.talos.legs])
        in_air = np.minimum(cfg.min_knee, bent)  # the motion eases its knee bound off at the key posture
        halfway = np.r_[0.5 * (start[:2] + pos[:2]), apex]
        for name, sole, knees in (
            ("risen to the apex", (np.r_[start[:2], apex], start_rot), in_air),
            ("halfway at the apex", (halfway, halfway_rotation(start_rot, rot)), in_air),
            ("over the contact at the apex", (np.r_[pos[:2], apex], rot), in_air),
            ("touchdown", (pos, rot), np.full(2, cfg.min_knee)),
        ):
            reason = self._held(single.q, [stance, (swing, *sole)], knees)
            if reason is not None:
                return f"{name}: {reason}"
        return None

    @staticmethod
    def _stance(single: ContactPosture, swing: int) -> tuple[np.ndarray, np.ndarray]:
        """(pos [3], rot [3, 3]) of the stance sole of a one-foot posture, world."""
        row = single.feet[1 - swing]
        return row[:3], matrix_from_quat_xyzw(row[3:])

    def _margin(self, q: np.ndarray) -> float:
        """m, the clearance asked of configurations near key posture q [39]: `body_clearance`,
        or q's own distance to the terrain where that is less (a key posture is only
        collision-free), less 0.1 mm; as `leas_jax.motion.motion` asks it."""
        key = q.tobytes()
        if self._margin_of is None or self._margin_of[0] != key:
            reach = self.config.body_clearance
            self._margin_of = (key, max(min(reach, self.clearance.distance(q, reach)) - 1e-4, 0.0))
        return self._margin_of[1]

    def _held(self, q: np.ndarray, soles, knees: np.ndarray) -> str | None:
        """Why key posture q [39] cannot be put onto soles [(side, pos [3], rot [3, 3])] of both
        legs, or None: the root moved to the first height of `TransitionConfig.root_offsets` at
        which both legs reach with their knees bent at least knees [2] (rad), as the motion
        moves it (the least lowering, else the least rise), must then be clear of the terrain
        and of itself. The motion does not search other heights for clearance: a crouched
        lift-off whose knees meet at the held root but part 14 cm higher is refused there too."""
        talos = self.projection.talos
        root_R = matrix_from_quat_xyzw(q[3:7])
        for dz in self._offsets:
            root_p = q[:3] + np.array([0.0, 0.0, dz])
            leg_q = self.projection.legs_ik(root_R, root_p, soles)
            if leg_q is None or (leg_q[:, 3] < knees - 1e-9).any():
                continue
            moved = q.copy()
            moved[:3] = root_p
            for side, leg in enumerate(talos.legs):
                moved[leg.q_index] = leg_q[side]
            return self.clearance.too_close(moved, self._margin(q))
        cfg = self.config
        return (
            f"the soles are out of the legs' reach at every root height from {cfg.max_dip:g} m lower "
            f"to {cfg.max_rise:g} m higher"
        )
