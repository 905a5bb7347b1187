"""Shared pieces of the motion tests: a short contact plan on flat ground."""

import numpy as np

from leas_jax.contacts import plan_contacts
from leas_jax.contacts.plan import ContactPlan
from leas_jax.terrain import load_terrain


def straight_plan(length: float = 0.6) -> ContactPlan:
    """Contact plan of a straight 0.18 m/s guide on eval_ground's flat floor, `length` m long."""
    terrain = load_terrain("terrains/eval_ground.toml")
    seconds = length / 0.18
    t = np.arange(0, round(seconds / 0.1) + 6) * 0.1
    x = 4.0 + 0.18 * np.minimum(t, seconds)
    guide = np.stack([x, np.full_like(x, 4.0), np.full_like(x, 1.0), np.zeros_like(x)], axis=1)
    plan = plan_contacts(terrain, guide, timestep=0.1)
    assert plan.coverage == 1.0
    return plan
