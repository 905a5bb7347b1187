"""Initial stance: both soles on support surfaces under the guide's first pose (host-only).

The first stage of the generator: both soles at their half-sitting places under guide
pose 0, moved onto support surfaces (`footholds`), in one double-support posture that
passes every check (`projection`); where none does, the same with both soles' places moved
together a few cm (`GeneratorConfig.stance_shifts`); docs/design.md §6. Not jittable.
"""

from __future__ import annotations

import numpy as np

from leas_jax.contacts.planner.config import GeneratorConfig
from leas_jax.contacts.planner.footholds import Footholds
from leas_jax.contacts.planner.projection import ContactPosture, PostureProjection, rotz
from leas_jax.contacts.robot.model import LEFT, RIGHT


def initial_stance(
    pose, footholds: Footholds, projection: PostureProjection, config: GeneratorConfig
) -> tuple[list, ContactPosture] | None:
    """Initial stance at a guide's first pose: `nominal_stance`, else `shifted_stance`.

    Args:
        pose: [4] root pose (x, y, z, yaw), world frame, z = base_link height.
        footholds, projection: the terrain's stages.
        config: generator settings.

    Returns:
        ([left, right] sole placements (pos [3], rot [3, 3]), the posture at `pose`), or None
        where the generator cannot stand there.
    """
    found = nominal_stance(pose, footholds, projection, config)
    return found if found is not None else shifted_stance(pose, footholds, projection, config)


def stance_shifts(distances) -> np.ndarray:
    """[8 x len(distances), 2] root-frame (forward, left) offsets of the soles' places: 8
    directions (45 degrees apart) at each distance, nearest first."""
    angles = np.arange(8) * (np.pi / 4)
    return np.array([(d * np.cos(a), d * np.sin(a)) for d in sorted(distances) for a in angles]).reshape(
        -1, 2
    )


def shifted_stance(
    pose, footholds: Footholds, projection: PostureProjection, config: GeneratorConfig
) -> tuple[list, ContactPosture] | None:
    """The first stance, in `stance_shifts(config.stance_shifts)` order, with both soles'
    targets moved by that root-frame offset (the first candidate of each foot) whose posture
    at `pose` passes every check; the root shifts toward the soles within
    `max_root_offset_xy` as in any double-support posture. None if none does.

    Args and returns: as `initial_stance`.
    """
    pose = np.asarray(pose, dtype=np.float64)
    root_R = rotz(pose[3])
    for offset in stance_shifts(config.stance_shifts):
        shift = root_R[:2, :2] @ offset
        soles = first_soles(footholds, np.array([pose[0] + shift[0], pose[1] + shift[1], pose[2], pose[3]]))
        if soles is None:
            continue
        posture = projection.posture(pose, 0, [(LEFT, *soles[0]), (RIGHT, *soles[1])])
        if posture is not None:
            return soles, posture
    return None


def first_soles(footholds: Footholds, pose) -> list | None:
    """[left, right] the first candidate of each foot at its nominal place under `pose` [4]
    (the right one's avoids the left one), or None where a foot has none."""
    left_target, left_yaw = footholds.nominal_placement(pose, LEFT)
    left = footholds.first_candidate(LEFT, pose, left_target, left_yaw)
    if left is None:
        return None
    right_target, right_yaw = footholds.nominal_placement(pose, RIGHT)
    right = footholds.first_candidate(RIGHT, pose, right_target, right_yaw, left)
    return None if right is None else [left, right]


def nominal_stance(
    pose, footholds: Footholds, projection: PostureProjection, config: GeneratorConfig
) -> tuple[list, ContactPosture] | None:
    """Initial stance with the feet at their nominal places under `pose` moved onto faces.

    The best candidate of each foot first (the right one's avoids the left one); if
    that stance fails a check (a sole across a rubble tile's edge tilts the legs
    out of balance), pairs of lower-ranked candidates, by increasing rank sum,
    up to `max_candidates` stances in all.

    Args:
        pose: [4] root pose (x, y, z, yaw), world frame, z = base_link height.
        footholds, projection: the terrain's stages.
        config: generator settings.

    Returns:
        ([left, right] sole placements (pos [3], rot [3, 3]), the posture, guide_index 0),
        or None where the generator cannot stand there.
    """
    soles = first_soles(footholds, pose)
    if soles is None:
        projection.count_rejection("no foothold")
        return None
    posture = projection.posture(pose, 0, [(LEFT, *soles[0]), (RIGHT, *soles[1])])
    if posture is not None:
        return soles, posture
    left_target, left_yaw = footholds.nominal_placement(pose, LEFT)
    right_target, right_yaw = footholds.nominal_placement(pose, RIGHT)
    lefts = list(zip(*footholds.candidates(LEFT, pose, left_target, left_yaw)))
    rights = {}  # left rank -> right candidates avoiding that left sole
    pairs = sorted(
        ((i, j) for i in range(len(lefts)) for j in range(config.max_candidates)),
        key=lambda ij: (ij[0] + ij[1], ij[0]),
    )
    tried = 0
    for i, j in pairs[1:]:
        if i not in rights:
            rights[i] = list(zip(*footholds.candidates(RIGHT, pose, right_target, right_yaw, lefts[i])))
        if j >= len(rights[i]):
            continue
        if tried == config.max_candidates:
            break
        tried += 1
        posture = projection.posture(pose, 0, [(LEFT, *lefts[i]), (RIGHT, *rights[i][j])])
        if posture is not None:
            return [lefts[i], rights[i][j]], posture
    return None
