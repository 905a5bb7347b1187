"""studies/reachability_validation.py: intervals, the root-frame heightmap, the learned
reference on data with a known answer, and a small end-to-end run on the arena."""

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from leas_jax.stats import rates, wilson
from leas_jax.terrain import load_terrain

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "studies"), str(ROOT / "benchmarks")]
import common  # noqa: E402
import reachability_calibration as rc  # noqa: E402
import reachability_validation as rv  # noqa: E402

WALL = load_terrain(
    Path(__file__).parent / "data" / "slab_with_wall.toml"
)  # ground at 0, wall x 4.3-4.7, y 1-5


def test_wilson_interval_by_hand():
    lo, hi = wilson(95, 100)
    assert lo == pytest.approx(0.8882, abs=1e-4) and hi == pytest.approx(0.9785, abs=1e-4)
    lo, hi = wilson(0, 10)
    assert lo == pytest.approx(0.0, abs=1e-12) and 0.2 < hi < 0.35
    assert all(math.isnan(v) for v in wilson(0, 0))


def test_rates_carry_the_wilson_intervals_of_both_rates():
    predicted = np.array([True] * 19 + [False] + [True] * 2 + [False] * 8)
    truth = np.array([True] * 20 + [False] * 10)
    r = rates(predicted, truth)
    assert (r["tp"], r["fn"], r["fp"], r["tn"]) == (19, 1, 2, 8)
    assert r["sensitivity"] == pytest.approx(0.95) and r["specificity"] == pytest.approx(0.8)
    assert r["sensitivity_95ci"] == wilson(19, 20) and r["specificity_95ci"] == wilson(8, 10)


def _value_at(features, x, y):
    """The heightmap entry at root-frame (x, y) (grid of rv.HEIGHTMAP_*)."""
    gx = np.arange(rv.HEIGHTMAP_X[0], rv.HEIGHTMAP_X[1] + 1e-9, rv.HEIGHTMAP_STEP)
    gy = np.arange(rv.HEIGHTMAP_Y[0], rv.HEIGHTMAP_Y[1] + 1e-9, rv.HEIGHTMAP_STEP)
    k, m = int(np.argmin(np.abs(gx - x))), int(np.argmin(np.abs(gy - y)))
    return features[..., k * len(gy) + m]


def test_local_heightmap_turns_with_the_root():
    # 0.4 m before the wall, facing it (yaw 0) and facing away (yaw pi).
    poses = np.array([[3.9, 3.0, 1.0, 0.0], [3.9, 3.0, 1.0, math.pi], [0.1, 3.0, 1.0, 0.0]])
    features = rv.local_heightmap(WALL, poses)
    assert features.shape == (3, 26 * 33)
    assert _value_at(features[0], 0.48, 0.0) == pytest.approx(0.4)  # wall ahead: 0.5 m above, clipped
    assert _value_at(features[0], -0.40, 0.0) == pytest.approx(-1.0)  # ground behind
    assert _value_at(features[1], 0.48, 0.0) == pytest.approx(-1.0)  # turned away: ground ahead
    assert _value_at(features[1], -0.40, 0.0) == pytest.approx(0.4)  # and the wall behind (x 4.30)
    assert _value_at(features[1], -0.36, 0.0) == pytest.approx(-1.0)
    # 0.1 m from the raster's edge: points behind it read the void (-2 m), clipped to -1.6
    assert _value_at(features[2], -0.40, 0.0) == pytest.approx(rv.HEIGHTMAP_CLIP[0])
    assert _value_at(features[2], 0.0, 0.0) == pytest.approx(-1.0)


def test_learned_reference_finds_a_separable_rule():
    rng = np.random.default_rng(0)
    x = rng.normal(size=(3000, 4)).astype(np.float32)
    y = x[:, 0] + 0.5 * x[:, 1] > 0.2  # a rule a tree ensemble learns almost exactly
    rows = rv.learned_reference(x[:2000], y[:2000], x[2000:], y[2000:], sizes=(500, 2000))
    assert [r["poses"] for r in rows] == [500, 2000]
    assert rows[1]["fitted"] == 1800 and rows[1]["threshold_poses"] == 200
    assert rows[1]["test"]["sensitivity"] > 0.9
    assert rows[1]["specificity_at_target"] > 0.9
    assert rows[1]["specificity_at_target"] >= rows[0]["specificity_at_target"] - 0.02
    with pytest.raises(ValueError, match="exceeds"):
        rv.learned_reference(x[:100], y[:100], x[2000:], y[2000:], sizes=(200,))


def test_validation_end_to_end_on_fresh_arena_poses(tmp_path, monkeypatch):
    monkeypatch.setattr(rc, "REPO", tmp_path)  # the ground-truth cache
    monkeypatch.setattr(common, "RESULTS", tmp_path / "results")
    calibration = tmp_path / "calibration.json"
    calibration.write_text(json.dumps({"chosen_with_hands": {"trunk_radius": 0.3, "trunk_bottom": -0.6}}))
    rv.main(
        [
            "--poses",
            "40",
            "--seed",
            "3",
            "--truth",
            "static",
            "--workers",
            "1",
            "--calibration-json",
            str(calibration),
        ]
    )
    report = json.loads((tmp_path / "results" / "reachability_validation.json").read_text())
    static = report["truths"]["static"]
    assert report["poses"] == 40 and 0 < static["feasible"] < 40
    assert set(static["validation"]) == {"defaults", "training", "chosen_with_hands of calibration.json"}
    for figures in static["validation"].values():
        assert figures["tp"] + figures["fn"] == static["feasible"]
        assert figures["tp"] + figures["fn"] + figures["fp"] + figures["tn"] == 40
    assert (tmp_path / ".cache" / "reachability_ground_truth_static_seed3_40.npz").is_file()


def test_validation_refuses_the_calibration_seed_and_bad_json(tmp_path, capsys):
    with pytest.raises(SystemExit):
        rv.main(["--seed", "0"])
    assert "calibration's own poses" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        rv.main(["--poses", "10", "--calibration-json", str(tmp_path / "missing.json")])
    assert "missing.json" in capsys.readouterr().err
