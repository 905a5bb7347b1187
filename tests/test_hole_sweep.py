"""`leas hole-sweep`: eval_hole's scenario with other hole widths."""

import json

import numpy as np
import pytest

from leas_jax.cli import main
from leas_jax.errors import UsageError
from leas_jax.eval.sweeps import hole_terrain, hole_width_sweep, parse_widths
from leas_jax.files import REPO_ROOT
from leas_jax.terrain import load_terrain


def test_the_default_width_is_eval_hole():
    committed = load_terrain(REPO_ROOT / "terrains" / "eval_hole.toml")
    swept = hole_terrain(3.0)
    np.testing.assert_array_equal(committed.raster(), swept.raster())
    for key, value in vars(committed.scenario).items():
        assert np.array_equal(
            np.asarray(getattr(swept.scenario, key), dtype=object), np.asarray(value, dtype=object)
        ), key


def test_a_narrow_hole_has_ground_beside_it_and_starts_behind_it():
    terrain = hole_terrain(1.0)
    heights = terrain.height_at(
        np.array([(5.0, 4.0), (5.0, 3.45), (5.0, 4.55), (5.0, 3.55), (3.9, 4.0), (6.1, 4.0)])
    )
    assert heights[0] == pytest.approx(-2.0) and heights[3] == pytest.approx(-2.0)  # inside the 1 m hole
    assert heights[1] == pytest.approx(0.0) and heights[2] == pytest.approx(0.0)  # 5 cm beside it
    assert heights[4] == pytest.approx(0.0) and heights[5] == pytest.approx(0.0)  # before and after it
    (_, y0), (_, y1) = terrain.scenario.start_region
    assert (y0, y1) == (3.5, 4.5)


@pytest.mark.parametrize(
    "text, fragment",
    [("0.5,abc", "comma-separated numbers"), ("0,1", "(0, 7]"), ("7.5", "(0, 7]"), ("", "(0, 7]")],
)
def test_bad_widths_name_the_argument(text, fragment):
    with pytest.raises(UsageError, match="--widths") as info:
        parse_widths(text)
    assert fragment in str(info.value)


def test_parse_widths_sorts_and_merges():
    assert parse_widths("1.5, 0.6,1.5") == (0.6, 1.5)


def test_sweep_writes_its_outputs_and_rblin_falls_in_every_hole(tmp_path):
    report = hole_width_sweep(
        (0.6, 3.0), methods=("rblin",), n_starts=2, workers=0, out=tmp_path, progress=False
    )
    assert [(r["width"], r["method"], r["n"]) for r in report["rows"]] == [
        (0.6, "rblin", 2),
        (3.0, "rblin", 2),
    ]
    # the straight lines from behind the hole to the target cross it: never a success, plans stop at the edge
    assert all(r["success"] == 0.0 and 5.0 < r["coverage"] < 60.0 for r in report["rows"])
    assert report["view_half_width"] == pytest.approx(0.45)
    saved = json.loads((tmp_path / "hole_sweep.json").read_text())
    assert saved["rows"] == report["rows"]
    for name in ("hole_sweep.md", "hole_sweep.png", "hole_0.6m.png", "hole_3m.png"):
        assert (tmp_path / name).stat().st_size > 0, name


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (
            ["hole-sweep", "--widths", "9", "--methods", "rblin", "--out", "o"],
            "--widths: expected widths in (0, 7] m",
        ),
        (["hole-sweep", "--out", "o"], "--checkpoint is required"),
        (["hole-sweep", "--methods", "rblin,fly", "--out", "o"], "unknown method(s) fly"),
    ],
)
def test_usage_errors_are_one_line(capsys, tmp_path, monkeypatch, argv, fragment):
    monkeypatch.chdir(tmp_path)
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and fragment in err, err
