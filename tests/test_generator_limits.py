"""Contact generator on one step up: a riser about as high as Talos's knee is climbed by holding
the root back over the lower sole (`GeneratorConfig.step_up_root_shifts`)."""

import numpy as np
import pytest

from leas_jax.contacts import GeneratorConfig, verify
from leas_jax.contacts.planner.generator import ContactGenerator
from leas_jax.contacts.planner.projection import rotz
from leas_jax.terrain import loads_terrain

DT = 0.1  # s between guide poses
SPEED = 0.18  # m/s, the env's target speed
ROOT = 1.0  # m, the root above the terrain under it
RISER_X = 3.0  # m, where the step rises


def step_terrain(height: float):
    """Flat ground to x = 3, then ground `height` m higher (6 x 2 m, void beside)."""
    return loads_terrain(
        'name = "step"\nbounds = [[0.0, 0.0], [6.0, 2.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
        f"[[box]]\ncenter = [1.5, 1.0, -0.25]\nsize = [3.0, 2.0, 0.5]\n"
        f"[[box]]\ncenter = [4.5, 1.0, {height - 0.25}]\nsize = [3.0, 2.0, 0.5]\n"
    )


def step_guide(height: float) -> np.ndarray:
    """[T, 4] straight guide along y = 1 from x = 1.5 over the riser, the root ROOT above the
    terrain under it."""
    end = 4.5 + height
    count = int(np.ceil((end - 1.5) / (SPEED * DT))) + 1
    x = np.linspace(1.5, end, count)
    z = ROOT + np.where(x >= RISER_X, height, 0.0)
    return np.stack([x, np.ones(count), z, np.zeros(count)], axis=1)


@pytest.mark.parametrize("height", [0.29, 0.30, 0.31, 0.32, 0.33])
def test_a_step_up_as_high_as_the_knee_is_climbed(height):
    """Straight guides up 0.29-0.34 m risers stopped at the riser's foot, the lower leg's thigh
    against its edge, while 0.35-0.475 m ones passed; the root held back passes them."""
    plan = ContactGenerator(step_terrain(height)).plan(step_guide(height), DT)
    assert plan.coverage == 1.0
    assert verify(plan).ok
    assert np.nanmax(plan.feet[-1][:, 2]) == pytest.approx(height)  # standing on the tread


def test_without_the_held_back_root_the_riser_stops_the_guide_at_its_foot():
    """The same 0.30 m step with `step_up_root_shifts` off: the plan stops before the riser,
    where its leg meets the terrain."""
    config = GeneratorConfig(step_up_root_shifts=())
    generator = ContactGenerator(step_terrain(0.30), config)
    plan, reasons = generator.stop_reasons(step_guide(0.30), DT)
    assert plan.coverage < 0.5
    assert float(plan.guide[plan.last_valid_index, 0]) < RISER_X
    assert reasons["terrain collision: leg"] > 0


def test_the_root_is_held_back_only_for_a_sole_above_and_ahead_of_the_other():
    """`_held_back` builds nothing for level soles or a higher sole behind the lower one
    (a step down): those keep the usual root places only."""
    generator = ContactGenerator(step_terrain(0.30))
    projection = generator.projection
    pose = np.array([2.93, 1.0, 1.0, 0.0])
    flat = np.eye(3)
    low = (0, np.array([2.78, 1.085, 0.0]), flat)
    ahead = (1, np.array([3.11, 0.915, 0.30]), flat)
    behind = (1, np.array([2.60, 0.915, 0.30]), flat)
    level = (1, np.array([2.87, 0.915, 0.0]), flat)
    args = (pose, 0, rotz(0.0), pose[:2])
    target = np.array([2.9, 1.0])
    assert projection._held_back(*args, target, [low, level], "half_sitting") is None
    assert projection._held_back(*args, target, [low, behind], "half_sitting") is None
    # The step up the plan stopped at: no posture at the guide's root or over the support
    # (the shifts off), one with the root held back behind the guide's.
    off = ContactGenerator(step_terrain(0.30), GeneratorConfig(step_up_root_shifts=())).projection
    assert off.posture(pose, 0, [low, ahead]) is None
    held = projection.posture(pose, 0, [low, ahead])
    assert held is not None
    assert held.q[0] <= pose[0] - min(generator.config.step_up_root_shifts) + 1e-9


def test_held_back_distances_stay_within_the_root_bound():
    with pytest.raises(ValueError, match="step_up_root_shifts"):
        GeneratorConfig(step_up_root_shifts=(0.2,))
