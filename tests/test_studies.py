"""The study scripts (studies/): what they compute from their inputs, on small cases.

guide_failures.py names why the generator stopped and pairs two reports of the same episodes;
table2_baselines.py samples RBKino as HPP's generator samples it.
"""

import json
import sys
from pathlib import Path

import pytest

from leas_jax.env import EnvConfig, heightfield_from_terrain
from leas_jax.terrain import load_terrain

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "studies"), str(ROOT / "benchmarks")]

import common  # noqa: E402
import guide_failures  # noqa: E402
import table2_baselines as table2  # noqa: E402


def test_guide_failures_report_names_why_the_generator_stopped():
    assert guide_failures.main_reason({"leg IK": 2, "terrain collision: arm": 5}) == "terrain collision: arm"
    assert guide_failures.main_reason({}) == "none"
    failure = {"start": 0, "cell": "wall", "speed": 0.1, "yaw_rate": 0.0, "reason": "terrain collision: arm"}
    failure["reasons"] = {"terrain collision: arm": 5}
    report = {
        "policy": "p", "terrain": "t", "spawns": "condition", "upper_bodies": ["half_sitting"],
        "starts": 2, "seed": 0, "full_coverage": 0.5, "full_coverage_95ci": [0.1, 0.9],
        "mean_coverage": 0.7, "failed_at_first_pose": 0, "mean_progress_m": 1.0, "valid_fraction": 1.0,
        "failures": [failure], "failures_by_cell": {"wall": 1}, "cells_visited": {"wall": 10},
        "failures_by_reason": {"terrain collision: arm": 1}, "failures_with_an_arm_collision": 1,
        "what_if": {},
    }  # fmt: skip
    text = guide_failures.markdown(report)
    assert "upper bodies half_sitting" in text
    assert "| terrain collision: arm | 1 |" in text
    assert "met the terrain or the legs at the failure: 1 / 1" in text


def test_guide_failures_sets_generator_fields_from_the_command_line():
    import argparse

    parser = argparse.ArgumentParser()
    settings = common.generator_settings(["retry_settings=()", "max_candidates = 12"], parser)
    assert settings == {"retry_settings": (), "max_candidates": 12}
    from leas_jax.contacts.planner.config import TransitionConfig

    checked = common.generator_settings(["transitions={}", "max_candidates=12"], parser)["transitions"]
    assert checked == TransitionConfig()
    assert common.generator_settings(["transitions={'min_knee': 0.2}"], parser)["transitions"].min_knee == 0.2
    for bad in ("no_such_field=1", "max_candidates", "lookahead=fast", "transitions={'knee': 1}"):
        with pytest.raises(SystemExit):
            common.generator_settings([bad], parser)
    report = {"policy": "p", "terrain": "t", "spawns": "condition", "upper_bodies": ["half_sitting"]}
    report |= {"generator_settings": {"max_candidates": "12"}, "starts": 1, "seed": 0}
    report |= {"full_coverage": 1.0, "full_coverage_95ci": [0.2, 1.0], "mean_coverage": 1.0}
    report |= {"failed_at_first_pose": 0, "mean_progress_m": 1.0, "valid_fraction": 1.0}
    report |= {"failures_by_cell": {}, "cells_visited": {}, "failures_by_reason": {}}
    report |= {"failures_with_an_arm_collision": 0, "failures": [], "what_if": {}}
    assert "half_sitting, max_candidates=12, 1 starts" in guide_failures.markdown(report)


def test_guide_failures_compare_pairs_the_same_episodes(tmp_path):
    from leas_jax.errors import UsageError

    assert guide_failures.sign_test(0, 0) == 1.0
    assert guide_failures.sign_test(14, 0) == pytest.approx(2 * 0.5**14)
    assert guide_failures.sign_test(3, 3) == 1.0
    same = {"policy": "p", "starts": 4, "seed": 0, "spawns": "condition", "terrain": "t"}
    before = {**same, "full_coverage": 0.25, "failures": [{"start": k} for k in (0, 1, 2)]}
    after = {**same, "full_coverage": 0.5, "failures": [{"start": k} for k in (2, 3)]}
    for name, report in (("b.json", before), ("a.json", after)):
        (tmp_path / name).write_text(json.dumps(report))
    result = guide_failures.main(
        ["--compare", str(tmp_path / "b.json"), str(tmp_path / "a.json"), "--out", str(tmp_path)]
    )
    assert result["fixed"] == [0, 1] and result["broken"] == [3]
    assert json.loads((tmp_path / "paired.json").read_text())["p_sign_test"] == pytest.approx(1.0)
    (tmp_path / "o.json").write_text(json.dumps({**after, "seed": 1}))
    with pytest.raises(UsageError, match="seed"):
        guide_failures.main(
            ["--compare", str(tmp_path / "b.json"), str(tmp_path / "o.json"), "--out", str(tmp_path)]
        )
    with pytest.raises(UsageError, match="missing.json"):
        guide_failures.main(
            ["--compare", str(tmp_path / "missing.json"), str(tmp_path / "a.json"), "--out", str(tmp_path)]
        )
    # The same weights under another path (a run folder and the checkpoint copied from it) pair.
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "policy.ckpt").write_bytes(b"weights")
    (tmp_path / "copy.ckpt").write_bytes(b"weights")
    (tmp_path / "other.ckpt").write_bytes(b"other weights")
    digests = {
        name: guide_failures.policy_digest(tmp_path / name) for name in ("run", "copy.ckpt", "other.ckpt")
    }
    assert digests["run"] == digests["copy.ckpt"] != digests["other.ckpt"]
    (tmp_path / "b.json").write_text(json.dumps({**before, "policy": "run", "policy_sha256": digests["run"]}))
    (tmp_path / "a.json").write_text(
        json.dumps({**after, "policy": "copy.ckpt", "policy_sha256": digests["copy.ckpt"]})
    )
    (tmp_path / "o.json").write_text(
        json.dumps({**after, "policy": "other.ckpt", "policy_sha256": digests["other.ckpt"]})
    )
    paths = [str(tmp_path / "b.json"), str(tmp_path / "a.json"), "--out", str(tmp_path)]
    assert guide_failures.main(["--compare", *paths])["fixed"] == [0, 1]
    with pytest.raises(UsageError, match="policy"):
        guide_failures.main(
            ["--compare", str(tmp_path / "b.json"), str(tmp_path / "o.json"), "--out", str(tmp_path)]
        )


def test_table2_rbkino_sampled_as_hpp_follows_a_start_turned_away():
    """RBKino from a start turned 60-120 degrees from the target at 0.01 m/s turns its root
    30-75 degrees between two poses 0.1 s apart: the generator stops at its first pose.
    Sampled every 0.01 s, as HPP's contact generator samples the path, and judged at the
    same 0.5 s planning interval, it is followed to the goal."""
    from leas_jax.contacts import GeneratorConfig
    from leas_jax.eval.scenarios import cells_for
    from leas_jax.steering.baselines import BaselineConfig
    from leas_jax.terrain.generate import scenario_file

    assert GeneratorConfig().planning_stride(0.01) == 50 and GeneratorConfig().planning_stride(0.1) == 5
    terrain = load_terrain(scenario_file("ground"))
    env = EnvConfig()
    base = BaselineConfig.from_env(env)
    field = heightfield_from_terrain(terrain, env)
    cells = cells_for("ground", terrain.scenario)
    turned = next(k for k, c in enumerate(cells) if c.yaw_deg == (60.0, 120.0) and c.speed[0] == 0.01)
    jobs = [(v, "rbkino", table2.VARIANTS[v][1], [turned]) for v in ("rbkino", "rbkino_dt001")]
    coarse, fine = table2.build(jobs, terrain, field, cells, 1, base, env)
    assert len(fine.guide) > 9 * len(coarse.guide) and (coarse.timestep, fine.timestep) == (0.1, 0.01)
    table2.judge(terrain, [coarse, fine], base.timestep, 0, None)
    assert coarse.outcome.last_valid_index == 0
    assert fine.outcome.coverage == 1.0 and fine.outcome.success


def test_generator_rough_scenes_builds_its_limit_terrains_and_guides():
    import generator_rough_scenes as grs
    import numpy as np

    from leas_jax.terrain import loads_terrain

    gap = loads_terrain(grs._limit_terrain("gap", 0.4))
    assert gap.height_at(np.array([[3.2, 1.0]]))[0] == pytest.approx(gap.void_height)
    assert gap.height_at(np.array([[3.5, 1.0]]))[0] == pytest.approx(0.0, abs=1e-6)
    down = loads_terrain(grs._limit_terrain("down", 0.25))
    assert down.height_at(np.array([[2.0, 1.0], [4.0, 1.0]])) == pytest.approx([0.25, 0.0], abs=1e-6)
    field = heightfield_from_terrain(down, EnvConfig(condition="cylinders"))
    guide = grs.straight_guide(field, (1.5, 1.0), (4.5, 1.0), 0.18, 1.0)
    assert np.allclose(np.diff(guide[:, 0]), 3.0 / (len(guide) - 1)) and np.allclose(guide[:, 3], 0.0)
    assert guide[0, 2] == pytest.approx(1.25, abs=1e-3) and guide[-1, 2] == pytest.approx(1.0, abs=1e-3)
    rows = [{"kind": "gap", "size": 0.4, "covered": True}, {"kind": "gap", "size": 0.5, "covered": False}]
    assert "| gap across | 0.40 | 0.50 |" in grs.limits_table(rows)
