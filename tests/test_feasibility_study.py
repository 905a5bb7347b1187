"""studies/feasibility_study.py: the two-level bootstrap, the table and plot, and the whole
study end to end on tiny settings (four methods, tiny training and evaluation)."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "studies"))
import feasibility_study as fs  # noqa: E402

from leas_jax.errors import UsageError  # noqa: E402


def test_bootstrap_interval_brackets_the_mean_and_widens_with_seed_spread():
    rng = np.random.default_rng(0)
    tight = [rng.normal(0.5, 0.1, 200) for _ in range(3)]
    spread = [rng.normal(m, 0.1, 200) for m in (0.2, 0.5, 0.8)]
    mean, lo, hi = fs.bootstrap_interval(tight)
    assert lo < mean < hi and hi - lo < 0.05
    mean2, lo2, hi2 = fs.bootstrap_interval(spread)
    assert lo2 < mean2 < hi2 and hi2 - lo2 > 4 * (hi - lo)  # the seeds' spread counts
    assert all(np.isnan(v) for v in fs.bootstrap_interval([]))


def test_summary_table_and_figure(tmp_path):
    runs = [
        {
            "full_coverage": np.array([1.0, 0.0, 1.0]),
            "mean_coverage": np.array([1.0, 0.5, 1.0]),
            "progress_m": np.array([3.0, 2.0, 4.0]),
            "ground_speed": np.array([0.15, 0.16]),
            "scenarios": {"eval_stairs": np.array([1.0, 1.0])},
        }
    ] * 2
    summary = fs.summarise({"cylinders": runs, "learned": runs})
    assert summary["cylinders"]["full_coverage"]["mean"] == pytest.approx(2 / 3)
    assert summary["learned"]["scenario/eval_stairs"]["mean"] == 1.0
    report = {
        "summary": summary,
        "settings": {
            "seeds": [0, 1],
            "geometric_steps": 10,
            "planner_steps": 5,
            "starts": 3,
            "eval_seeds": [0],
            "episode_length": 400,
        },
    }
    text = fs.markdown(report)
    assert "| cylinders | 2 | 66.7 [" in text and "eval_stairs success (%)" in text
    fs.figure(report, tmp_path / "f.png")
    assert (tmp_path / "f.png").stat().st_size > 1000
    report["settings"]["seeds_done"] = [0]  # a study stopped after its first seed
    (tmp_path / "feasibility_study.json").write_text(json.dumps(report))
    fs.main(["--out", str(tmp_path), "--tables-only"])
    assert "1 training seeds (0;" in (tmp_path / "feasibility_study.md").read_text()
    assert (tmp_path / "feasibility_study.png").is_file()


def test_a_finished_policys_evaluation_is_reused_until_its_inputs_change(tmp_path):
    import argparse

    run = tmp_path / "run"
    run.mkdir()
    (run / "policy.ckpt").write_bytes(b"weights 1")
    args = argparse.Namespace(
        starts=3,
        eval_seeds=(0,),
        ground_starts=3,
        episode_length=60,
        scenarios=["eval_stairs"],
        scenario_starts=2,
    )
    calls = []

    def evaluate(run_dir, args):
        calls.append(args.starts)
        return {
            "full_coverage": np.array([1.0, 0.0, 1.0]),
            "progress_m": np.array([3.0, 2.5, 0.5]),
            "scenarios": {"eval_stairs": np.array([1.0, 0.0])},
        }

    first = fs.cached_evaluation(run, args, evaluate)
    again = fs.cached_evaluation(run, args, evaluate)
    assert calls == [3]  # read back, not evaluated again
    assert set(again) == set(first) and set(again["scenarios"]) == {"eval_stairs"}
    np.testing.assert_array_equal(again["progress_m"], first["progress_m"])
    np.testing.assert_array_equal(again["scenarios"]["eval_stairs"], [1.0, 0.0])
    args.starts = 4  # other settings
    fs.cached_evaluation(run, args, evaluate)
    (run / "policy.ckpt").write_bytes(b"weights 2")  # the run trained on
    fs.cached_evaluation(run, args, evaluate)
    (run / fs.EVALUATION_FILE).write_bytes(b"damaged")
    fs.cached_evaluation(run, args, evaluate)
    assert calls == [3, 4, 4, 4]
    fs.cached_evaluation(run, args, evaluate)
    assert calls == [3, 4, 4, 4]


def test_bad_arguments_name_the_option(tmp_path):
    with pytest.raises(UsageError, match="--methods"):
        fs.main(["--out", str(tmp_path), "--methods", "cylinders,boxes"])
    with pytest.raises(UsageError, match="--seeds"):
        fs.main(["--out", str(tmp_path), "--seeds", "a"])
    with pytest.raises(UsageError, match="--preset"):
        fs.main(["--out", str(tmp_path), "--preset", "huge"])


TINY = [
    "--seeds",
    "0",
    "--preset",
    "smoke",
    "--num-envs",
    "32",
    "--geometric-steps",
    "2048",
    "--planner-steps",
    "40",
    "--planner-envs",
    "4",
    "--refresh-every",
    "1",
    "--refresh-min-poses",
    "2",
    "--starts",
    "3",
    "--eval-seeds",
    "0",
    "--ground-starts",
    "3",
    "--episode-length",
    "60",
    "--workers",
    "0",
]


@pytest.mark.slow  # 63 s at load 3 on 2 cores (705 s at load 20): four trainings and evaluations compile
def test_study_runs_end_to_end_on_tiny_settings(tmp_path):
    report = fs.main(["--out", str(tmp_path)] + TINY)
    assert set(report["summary"]) == set(fs.METHODS)
    saved = json.loads((tmp_path / "feasibility_study.json").read_text())
    for method in fs.METHODS:
        for metric in fs.METRICS:
            entry = saved["summary"][method][metric]
            assert entry["lo"] <= entry["mean"] <= entry["hi"], (method, metric)
    assert (tmp_path / "feasibility_study.png").is_file() and (tmp_path / "feasibility_study.md").is_file()
    runs = tmp_path / "runs"
    assert (runs / "learned_planner" / "seed0" / "planner" / "condition_data.npz").is_file()
    for run in ("cylinders/seed0/geometric", "learned_planner/seed0/planner"):  # a resumed study reads them
        assert (runs / run / fs.EVALUATION_FILE).is_file()
    # a planner phase continues its method's own geometric run: no second geometric run
    assert not (runs / "cylinders_planner" / "seed0" / "geometric").exists()
    assert not (runs / "learned_planner" / "seed0" / "geometric").exists()
    planner = json.loads((runs / "cylinders_planner" / "seed0" / "planner" / "config.json").read_text())
    assert Path(planner["init_from"]) == runs / "cylinders" / "seed0" / "geometric"


def test_the_clearance_probes_judge_reaches_every_method():
    """`--clearance-condition cylinders` sets EnvConfig.clearance_condition of both phases; the
    default keeps the termination condition as the judge; another value is refused by argparse."""
    import argparse

    def args(judge):
        return argparse.Namespace(
            preset="quick",
            weights="checkpoints/feasibility/walking.npz",
            episode_length=400,
            clearance_condition=judge,
            geometric_steps=2048,
            num_envs=0,
            planner_steps=40,
            planner_envs=4,
            refresh_every=4,
            refresh_min_poses=2,
            refresh_sensitivity=None,
        )

    for judge in ("condition", "cylinders"):
        geo, plan = fs.method_configs("learned+planner", 0, args(judge))
        assert geo.env.condition == plan.env.condition == "learned"
        assert geo.env.clearance_condition == plan.env.clearance_condition == judge
        assert geo.env.rewards.clearance == 1.0  # `quick` has the clearance term
    with pytest.raises(SystemExit):
        fs.main(["--out", "unused", "--clearance-condition", "network"])
