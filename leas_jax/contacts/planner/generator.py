"""Contact generator: guide path -> quasi-static contact plan for Talos (RB-PRM style).

Host-only (Pinocchio, coal, hpp-centroidal-dynamics, SciPy), not jittable.

Algorithm (docs/design.md §6, after the RB-PRM contact generator of Tonneau et al., T-RO
2018, used by the paper through [7]); its stages, in the order a guide meets them, are
modules of this package:

1. Contact planning runs on a subsampled guide: a pose every `planning_interval` s plus the last.
2. `stance`: both soles at their half-sitting places under guide pose 0, moved onto
   support surfaces.
3. `walking`: at each planning pose, keep both contacts, or step the foot that lags most
   (then the other), onto footholds near where it should be `lookahead` s ahead.
4. `footholds`: the ranked sole placements of a step (leg sample database, support
   surfaces, narrow-beam lanes).
5. `projection`: every posture of the stages above, root placed and checked (IK and joint
   limits, terrain and self collision, equilibrium); with `GeneratorConfig.transitions`, also
   each single support's lift-off and landing (`transitions`).
6. The generator stops at the first planning pose it cannot pass; `last_valid_index`
   is the guide index of the last posture, `coverage` its arc-length fraction.

Settings: `config.GeneratorConfig`.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from leas_jax.contacts.plan import ContactPlan, coverage_of
from leas_jax.contacts.planner.config import GeneratorConfig
from leas_jax.contacts.planner.footholds import Footholds
from leas_jax.contacts.planner.projection import ContactPosture, PostureProjection
from leas_jax.contacts.planner.stance import initial_stance
from leas_jax.contacts.planner.surfaces import surface_arrays
from leas_jax.contacts.planner.transitions import TransitionCheck
from leas_jax.contacts.planner.walking import Walking
from leas_jax.contacts.robot.database import leg_database
from leas_jax.contacts.robot.model import LEFT, NOMINAL_ROOT_HEIGHT, RIGHT, load_talos
from leas_jax.errors import UsageError


class ContactGenerator:
    """Contact generator for one terrain; reuses its collision objects across guides.

    Host-only, not jittable; holds Pinocchio/coal/LP solver state, so use one per
    process or thread.

    Args:
        terrain: a leas_jax.terrain.Terrain.
        config: generator settings.

    Attributes:
        projection, footholds, walking: its stages (see the module docstring).
    """

    def __init__(self, terrain, config: GeneratorConfig = GeneratorConfig()):
        self.terrain = terrain
        self.config = config
        self.talos = load_talos()
        databases = (leg_database(LEFT, config.database), leg_database(RIGHT, config.database))
        self.projection = PostureProjection(terrain, self.talos, config)
        self.footholds = Footholds(terrain, self.talos, surface_arrays(terrain, config.mu), databases, config)
        transitions = (
            None
            if config.transitions is None
            else TransitionCheck(terrain, self.projection, config.transitions)
        )
        self.walking = Walking(self.projection, self.footholds, config, transitions)

    def double_support(self, pose) -> ContactPosture | None:
        """The first posture of a plan whose guide starts at `pose`, or None.

        Host-only, not jittable. Both soles at their half-sitting places under the pose,
        moved onto support surfaces (best candidate each), then every check of a
        posture: leg IK and joint limits, equilibrium, terrain and self collision, with
        the root allowed its usual offsets (`max_root_offset_xy`, `max_root_offset_z`).

        Args:
            pose: [4] root pose (x, y, z, yaw), world frame, z = base_link height.

        Returns:
            the double-support posture (guide_index 0), or None where the generator
            cannot stand there.
        """
        start = self._stance(np.asarray(pose, dtype=np.float64))
        return None if start is None else start[1]

    def _stance(self, pose):
        """`stance.initial_stance` at a root pose [4]: (soles, posture) or None."""
        return initial_stance(pose, self.footholds, self.projection, self.config)

    def plan(self, guide, timestep: float) -> ContactPlan:
        """Contact plan along a guide path (see the module docstring).

        Host-only, not jittable.

        Args:
            guide: [T, 4] root poses (x, y, z, yaw), world frame, z = base_link height.
            timestep: s between guide poses.

        Returns:
            ContactPlan with the postures up to the first planning pose that fails.
        """
        guide = np.asarray(guide, dtype=np.float64)
        if guide.ndim != 2 or guide.shape[1] != 4 or len(guide) == 0:
            raise UsageError(f"guide must have shape [T, 4] with T >= 1, got {guide.shape}")
        if not np.all(np.isfinite(guide)):
            raise UsageError("guide contains NaN or inf")
        if not (timestep > 0 and math.isfinite(timestep)):
            raise UsageError(f"timestep must be a positive number of seconds, got {timestep!r}")
        cfg = self.config
        postures: list[ContactPosture] = []
        last_valid = -1
        if self.projection.rejections is not None:
            self.projection.rejections.clear()
        start = self._stance(guide[0])
        if start is not None:
            feet, first = start
            postures.append(first)
            last_valid = 0
            passed = [(0, list(feet), 1)]  # (guide index, feet, postures so far) per planning pose
            for index in planning_indices(len(guide), cfg.planning_stride(timestep)):
                last_valid = self._reach(guide, timestep, last_valid, index, feet, postures)
                if last_valid != index:
                    last_valid = self._retry(guide, timestep, index, passed, feet, postures, last_valid)
                if last_valid != index:
                    break
                passed.append((index, list(feet), len(postures)))
        return self._make_plan(guide, timestep, postures, last_valid)

    def _retry(
        self, guide, timestep, failed: int, passed: list, feet, postures: list, last_valid: int
    ) -> int:
        """Plan again to planning pose `failed` with each of `retry_settings` in turn, from
        `retry_backtrack` planning poses before it (`passed` holds (guide index, feet,
        postures so far) at each planning pose reached; mutates it, `feet` and `postures`).

        Returns `failed` where a setting passes it (`passed` then ends at the pose before),
        else `last_valid`, with `feet`, `postures` and the rejection counts as the
        generator's own settings left them."""
        cfg = self.config
        keep = max(len(passed) - 1 - cfg.retry_backtrack, 0)
        indices = [index for index, _, _ in passed[keep + 1 :]] + [failed]
        own = (list(feet), list(postures), self._rejections_copy())
        for overrides in cfg.retry_settings:
            start, start_feet, count = passed[keep]
            feet[:] = start_feet
            del postures[count:]
            reached, at = [], start
            self._set_stage_config(cfg.retried(overrides))
            try:
                for index in indices:
                    at = self._reach(guide, timestep, at, index, feet, postures)
                    if at != index:
                        break
                    reached.append((index, list(feet), len(postures)))
            finally:
                self._set_stage_config(cfg)
            if at == failed:
                passed[keep + 1 :] = reached[:-1]
                return failed
        feet[:], postures[:] = own[0], own[1]
        if own[2] is not None:
            self.projection.rejections.clear()
            self.projection.rejections.update(own[2])
        return last_valid

    def _set_stage_config(self, config: GeneratorConfig) -> None:
        """The settings every stage reads from now on (see `GeneratorConfig.retried`)."""
        self.projection.config = self.footholds.config = self.walking.config = config

    def _rejections_copy(self) -> Counter | None:
        rejections = self.projection.rejections
        return None if rejections is None else Counter(rejections)

    def _reach(self, guide, timestep, last_valid: int, index: int, feet, postures: list) -> int:
        """Plan from guide pose `last_valid` to planning pose `index`, appending to `postures`
        (mutates `feet`): directly, else through `refined_indices` (the feet follow a fast
        turn through the root's yaws on the way). Returns the last guide index reached."""
        added = self._advance(guide, timestep, index, feet)
        if added is not None:
            postures.extend(added)
            return index
        for finer in refined_indices(last_valid, index, self.config.refine_stride):
            added = self._advance(guide, timestep, finer, feet)
            if added is None:
                break
            postures.extend(added)
            last_valid = finer
        return last_valid

    def _advance(self, guide, timestep, index: int, feet) -> list[ContactPosture] | None:
        """`Walking.advance` to planning pose `index`; `feet` is left as it was where it fails."""
        if self.projection.rejections is not None:
            self.projection.rejections.clear()  # counted per planning pose (`stop_reasons`)
        before = list(feet)
        added = self.walking.advance(guide, timestep, index, feet)
        if added is None:
            feet[:] = before
        return added

    def stop_reasons(self, guide, timestep: float) -> tuple[ContactPlan, Counter]:
        """A guide's plan, and why it stops: the checks that rejected the postures tried at
        the planning pose it could not pass.

        Host-only, not jittable. Counts are by check ("leg IK", "root height", "equilibrium",
        "no foothold", "terrain collision: arm", "self collision: leg", ...; the body part
        from `robot.collision.body_part`); empty when the plan covers the whole guide. The plan
        is the one `plan` gives.

        Args:
            guide: [T, 4] root poses (x, y, z, yaw), world frame.
            timestep: s between guide poses.
        """
        self.projection.rejections = Counter()
        try:
            plan = self.plan(guide, timestep)
            reasons = (
                Counter() if plan.last_valid_index == len(plan.guide) - 1 else self.projection.rejections
            )
        finally:
            self.projection.rejections = None
        return plan, reasons

    def _make_plan(self, guide, timestep, postures, last_valid) -> ContactPlan:
        if postures:
            q = np.stack([p.q for p in postures])
            feet = np.stack([p.feet for p in postures])
            guide_index = np.array([p.guide_index for p in postures], dtype=np.int64)
        else:
            q, feet, guide_index = np.zeros((0, 39)), np.zeros((0, 2, 7)), np.zeros(0, dtype=np.int64)
        return ContactPlan(
            q=q,
            feet=feet,
            guide_index=guide_index,
            last_valid_index=last_valid,
            coverage=coverage_of(guide, last_valid),
            terrain=self.terrain.text,
            guide=guide,
            timestep=timestep,
        )


def planning_indices(length: int, stride: int) -> list[int]:
    """Guide indices the generator plans at after the first pose: every `stride`-th, and the last."""
    indices = list(range(stride, length, stride))
    if length > 1 and (not indices or indices[-1] != length - 1):
        indices.append(length - 1)
    return indices


def refined_indices(last_valid: int, failed: int, stride: int | None) -> list[int]:
    """Guide indices to plan at, every `stride`-th after `last_valid` and ending at `failed`,
    where planning pose `failed` could not be reached from `last_valid`; empty where that
    is no finer (stride None, or not below the gap)."""
    if stride is None or stride >= failed - last_valid:
        return []
    indices = list(range(last_valid + stride, failed, stride))
    return indices + [failed]


_GENERATORS: dict = {}


def plan_contacts(
    terrain, guide, timestep: float, config: GeneratorConfig = GeneratorConfig()
) -> ContactPlan:
    """Contact plan of a guide path on a terrain (docs/design.md §6).

    Host-only, not jittable. Reuses one ContactGenerator per (terrain object, config)
    in the process (the latest one only), so repeated calls on one terrain share its
    collision objects.

    Args:
        terrain: a leas_jax.terrain.Terrain.
        guide: [T, 4] root poses (x, y, z, yaw), world frame, z = base_link height
            (NOMINAL_ROOT_HEIGHT above the ground for standing on flat ground).
        timestep: s between guide poses.
        config: generator settings.

    Returns:
        ContactPlan.
    """
    return _generator(terrain, config).plan(guide, timestep)


def _generator(terrain, config: GeneratorConfig) -> ContactGenerator:
    """The process's ContactGenerator for (terrain object, config): the latest one is kept."""
    key = (id(terrain), config)
    generator = _GENERATORS.get("latest")
    if generator is None or generator[0] != key or generator[1].terrain is not terrain:
        generator = (key, ContactGenerator(terrain, config))
        _GENERATORS["latest"] = generator
    return generator[1]


def double_support_posture(
    terrain, pose, config: GeneratorConfig = GeneratorConfig()
) -> ContactPosture | None:
    """Balanced, collision-free double-support posture of Talos at a root pose, or None.

    Host-only, not jittable. What the generator does for the first posture of a plan
    (`ContactGenerator.double_support`); the ground truth the reachability condition
    is calibrated against (studies/reachability_calibration.py). Reuses the
    process's generator like `plan_contacts`.

    Args:
        terrain: a leas_jax.terrain.Terrain.
        pose: [4] root pose (x, y, z, yaw), world frame, z = base_link height.
        config: generator settings.
    """
    return _generator(terrain, config).double_support(pose)


__all__ = [
    "ContactGenerator",
    "ContactPosture",
    "GeneratorConfig",
    "NOMINAL_ROOT_HEIGHT",
    "double_support_posture",
    "plan_contacts",
]
