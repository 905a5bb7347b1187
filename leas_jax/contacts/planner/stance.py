"""Initial stance: both soles on support surfaces under the guide's first pose (host-only).

The first stage of the generator: both soles at their half-sitting places under guide
pose 0, moved onto support surfaces (`footholds`), in one double-support posture that
passes every check (`projection`); docs/design.md §6. Not jittable.
"""

from __future__ import annotations

from leas_jax.contacts.planner.config import GeneratorConfig
from leas_jax.contacts.planner.footholds import Footholds
from leas_jax.contacts.planner.projection import ContactPosture, PostureProjection
from leas_jax.contacts.robot.model import LEFT, RIGHT


def initial_stance(
    pose, footholds: Footholds, projection: PostureProjection, config: GeneratorConfig
) -> tuple[list, ContactPosture] | None:
    """Initial stance at a guide's first pose: feet at their nominal places moved onto faces.

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
    left_target, left_yaw = footholds.nominal_placement(pose, LEFT)
    right_target, right_yaw = footholds.nominal_placement(pose, RIGHT)
    left = footholds.first_candidate(LEFT, pose, left_target, left_yaw)
    if left is None:
        projection.count_rejection("no foothold")
        return None
    right = footholds.first_candidate(RIGHT, pose, right_target, right_yaw, left)
    if right is None:
        projection.count_rejection("no foothold")
        return None
    posture = projection.posture(pose, 0, [(LEFT, *left), (RIGHT, *right)])
    if posture is not None:
        return [left, right], posture
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
