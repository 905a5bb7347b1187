"""`leas run`'s report end to end on a tiny policy (slow tier: evaluation, baselines, navigate)."""

import json

import pytest


@pytest.mark.slow
def test_the_run_report_writes_every_section(run_dir, tmp_path):
    import shutil

    from leas_jax.eval.report import write_report

    out = tmp_path / "run"
    shutil.copytree(run_dir, out / "geometric")
    path = write_report(out, n_episodes=4, compare_starts=1, baseline_starts=1, workers=1)
    text = path.read_text()
    headings = [line for line in text.splitlines() if line.startswith("## ")]
    assert headings[0] == "## Geometric training" and "## Against the baselines" in headings
    assert headings[-1] == "## Navigate"
    summary = json.loads((out / "eval.json").read_text())
    assert set(summary) == {"geometric", "baselines", "navigate"}
    assert summary["geometric"]["episodes_per_metric"] == 4
    for figure in (
        "learning_curves.png",
        "rollouts_arena.png",
        "rollouts_ground.png",
        "evaluation/ground.png",
    ):
        assert (out / figure).stat().st_size > 0, figure
