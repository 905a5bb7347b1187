"""Contact generator at the limits of rough ground: a riser about as high as Talos's knee is
climbed by holding the root back over the lower sole (`GeneratorConfig.step_up_root_shifts`);
a field of debris tiles narrower than a turned sole is crossed by turning the soles to fit
(`GeneratorConfig.sole_turns`)."""

import sys
from pathlib import Path

import numpy as np
import pytest

from leas_jax.contacts import GeneratorConfig, verify
from leas_jax.contacts.planner.generator import ContactGenerator
from leas_jax.contacts.planner.projection import rotz
from leas_jax.terrain import loads_terrain

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "studies"))
from generator_debris import debris_terrain, diagonal_guide  # noqa: E402

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


def test_a_sole_turns_to_fit_a_small_tile():
    """Crossed at 0.4 rad to the tiles' axes, no tile holds a sole at the guide's yaw: without
    turns both feet stay on the ground before the tiles, the root walks on beyond them and the
    plan stops (feet lagging, CoM out of the support); with them the soles turn to each tile's
    axis and the whole guide is covered and verified."""
    terrain, guide = debris_terrain(), diagonal_guide(0.4)
    stuck, reasons = ContactGenerator(terrain, GeneratorConfig(sole_turns=())).stop_reasons(guide, DT)
    assert stuck.coverage < 0.5
    assert np.nanmax(stuck.feet[:, :, 0]) < 1.5  # no sole on a tile
    assert reasons["no foothold"] + reasons["equilibrium"] > 0
    plan = ContactGenerator(terrain).plan(guide, DT)
    assert plan.coverage == 1.0
    assert verify(plan).ok
    on_tiles = (plan.feet[:, :, 0] > 1.5) & (plan.feet[:, :, 0] < 3.0)
    quat = plan.feet[on_tiles][:, 3:]
    sole_yaw = np.arctan2(
        2 * (quat[:, 3] * quat[:, 2] + quat[:, 0] * quat[:, 1]), 1 - 2 * (quat[:, 1] ** 2 + quat[:, 2] ** 2)
    )
    assert len(sole_yaw) > 0 and np.all(np.abs(sole_yaw - 0.4) > 0.05)  # turned off the guide's yaw
