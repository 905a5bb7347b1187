"""terrains/checks/: hand-written check terrains with a [scenario] table (`leas evaluate --terrain`)."""

from pathlib import Path

import numpy as np
import pytest

from leas_jax.eval.scenarios import route
from leas_jax.terrain import load_terrain

CHECKS = sorted((Path(__file__).resolve().parents[1] / "terrains" / "checks").glob("*.toml"))


@pytest.mark.parametrize("path", CHECKS, ids=lambda p: p.stem)
def test_check_terrain_loads_with_a_scenario_on_its_ground(path):
    terrain = load_terrain(path)
    assert terrain.scenario is not None and terrain.scenario.n_starts >= 60
    start = np.asarray(terrain.scenario.start_region).mean(axis=0)
    assert terrain.height_at(start) == pytest.approx(0.0, abs=1e-6)
    assert terrain.height_at(route(terrain.scenario)[-1]) == pytest.approx(0.0, abs=1e-6)


def test_pillars_check_puts_two_gates_across_the_way():
    """The start-target line (y = 4 m) is clear; across it at x = 5.5 and 7.0 m, pillars stand
    0.7 to 1.0 m either side of it."""
    terrain = load_terrain(next(p for p in CHECKS if p.stem == "pillars"))
    x = np.arange(4.0, 8.8, 0.01)
    assert terrain.height_at(np.stack([x, np.full_like(x, 4.0)], axis=1)).max() == pytest.approx(
        0.0, abs=1e-6
    )
    for gate in (5.5, 7.0):
        y = np.arange(2.5, 5.5, 0.01)
        tall = y[terrain.height_at(np.stack([np.full_like(y, gate), y], axis=1)) > 1.0]
        assert tall.min() == pytest.approx(3.0, abs=0.02) and tall.max() == pytest.approx(5.0, abs=0.02)
        assert not ((tall > 3.3 + 0.01) & (tall < 4.7 - 0.01)).any()


def test_pillars_in_the_way_check_blocks_the_straight_line():
    """Pillars stand on the start-target line (y = 4 m) at x = 5.5 and 8.5 m, and a gate of two
    either side of it at x = 7.0 m, 0.55 m from it; the ground round them is clear."""
    terrain = load_terrain(next(p for p in CHECKS if p.stem == "pillars_in_the_way"))
    x = np.arange(4.0, 10.5, 0.01)
    tall = x[terrain.height_at(np.stack([x, np.full_like(x, 4.0)], axis=1)) > 1.0]
    assert tall.size and ((np.abs(tall - 5.5) < 0.16) | (np.abs(tall - 8.5) < 0.16)).all()
    assert (np.abs(tall - 5.5) < 0.16).any() and (np.abs(tall - 8.5) < 0.16).any()
    y = np.arange(2.5, 5.5, 0.01)
    tall = y[terrain.height_at(np.stack([np.full_like(y, 7.0), y], axis=1)) > 1.0]
    assert tall.min() == pytest.approx(3.15, abs=0.02) and tall.max() == pytest.approx(4.85, abs=0.02)
    assert not ((tall > 3.45 + 0.01) & (tall < 4.55 - 0.01)).any()
    assert terrain.height_at(np.array([[7.0, 1.5], [7.0, 6.5]])).max() == pytest.approx(0.0, abs=1e-6)
