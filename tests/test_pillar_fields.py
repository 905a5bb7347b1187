"""The pillar-field family of studies/pillar_fields.py: seeded fields of pillars standing in
the way, and its table."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from leas_jax.env import heightfield_from_terrain
from leas_jax.env.field import sample_nearest_xy
from leas_jax.terrain import load_terrain

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "studies"))
import pillar_fields  # noqa: E402


@pytest.mark.parametrize("seed", range(12))
def test_a_field_blocks_the_straight_line_and_leaves_a_metre_between_pillars(seed):
    pillars = pillar_fields.pillar_boxes(seed)
    assert pillar_fields.PILLAR_COUNT[0] <= len(pillars) <= pillar_fields.PILLAR_COUNT[1]
    assert sum(abs(y - pillar_fields.START[1]) < pillar_fields.ON_LINE for _, y, _, _ in pillars) >= 2
    for k, (x, y, side, _) in enumerate(pillars):
        assert pillar_fields.PILLAR_SIDE[0] <= side <= pillar_fields.PILLAR_SIDE[1]
        for x2, y2, side2, _ in pillars[k + 1 :]:
            assert math.hypot(x - x2, y - y2) - (side + side2) / math.sqrt(2) >= pillar_fields.MIN_GAP


def test_a_field_file_loads_with_its_scenario_and_a_pillar_on_the_line(tmp_path):
    path = tmp_path / "field.toml"
    path.write_text(pillar_fields.pillar_field(3, starts=7))
    terrain = load_terrain(path)
    assert terrain.scenario.n_starts == 7 and terrain.scenario.seed == 3
    np.testing.assert_allclose(terrain.scenario.target, pillar_fields.TARGET)
    field = heightfield_from_terrain(terrain)
    x = np.arange(pillar_fields.START[0], pillar_fields.TARGET[0], 0.02, dtype=np.float32)
    heights = np.asarray(sample_nearest_xy(field, field.heights, x, np.full_like(x, pillar_fields.START[1])))
    assert heights.max() == pytest.approx(pillar_fields.PILLAR_HEIGHT, abs=0.02)
    assert heights[0] == pytest.approx(0.0, abs=1e-6) and heights[-1] == pytest.approx(0.0, abs=1e-6)
    assert pillar_fields.pillar_field(3, starts=7) == path.read_text()  # seeded


def test_the_pillar_table_pools_the_fields_with_intervals():
    results = {
        "policies": {"a": "run_a"},
        "results": {
            "a": {
                "0": {"n": 10, "success": 10, "mean_coverage": 1.0},
                "1": {"n": 10, "success": 4, "mean_coverage": 0.9},
            }
        },
    }
    text = pillar_fields.markdown(results)
    assert "| a | 20 | 70.0 [48.1, 85.5] | 1 / 2 | 95.0 |" in text
    assert "| a | 10/10 | 4/10 |" in text
