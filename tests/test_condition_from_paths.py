"""studies/condition_from_paths.py: per-path agreement of a condition with the generator."""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "studies"))

import condition_from_paths as cfp  # noqa: E402


def test_sure_end_is_the_whole_covered_guide_or_a_horizon_before_the_failure():
    assert cfp.sure_end(9, 10, horizon=3) == 9
    assert cfp.sure_end(6, 10, horizon=3) == 3
    assert cfp.sure_end(2, 10, horizon=3) == -1
    assert cfp.sure_end(-1, 10, horizon=3) == -4


def test_path_outcomes_count_ended_covered_and_stopped_failed_guides():
    none, at = np.zeros(10, bool), lambda k: np.eye(10, dtype=bool)[k]
    rejected = [none, at(4), at(5), at(8), none, at(0)]
    last_valid = [9, 9, 6, 6, 6, -1]  # two covered guides, then four the generator stops at 7, 7, 7, 0
    outcome = cfp.path_outcomes(rejected, last_valid, horizon=3)
    assert outcome == {
        "covered": 2,
        "covered_ended": 1,  # the second, at pose 4
        "failed": 4,
        "failed_stopped": 2,  # pose 5 <= 7 and pose 0 <= 0; pose 8 is past the failure, none never
        "sure_prefix_ended": 1,  # only the covered guide rejected at 4 (prefixes end at pose 3)
    }


def test_path_threshold_lets_the_target_share_of_prefixes_pass():
    minima = np.array([-3.0, -1.0, 0.5, 2.0])
    assert cfp.path_threshold(minima, 1.0) == -3.0  # every prefix passes
    assert cfp.path_threshold(minima, 0.75) == -1.0  # three of four
    assert cfp.path_threshold(minima, 0.5) == 0.5
    assert (minima >= cfp.path_threshold(minima, 0.5)).mean() >= 0.5


def test_prefix_minima_read_only_the_surely_feasible_prefix():
    logits = [
        np.array([3.0, 2.0, 1.0, -5.0]),
        np.array([0.5, -1.0, 2.0, 2.0]),
        np.array([-9.0, 1.0, 1.0, 1.0]),
    ]
    last_valid = [3, 3, 0]  # covered, covered, stopped after its first pose (no sure prefix at horizon 1)
    assert cfp.prefix_minima(logits, last_valid, horizon=1).tolist() == [-5.0, -1.0]
    # a guide failing after pose 2: its sure prefix is poses 0-1
    assert cfp.prefix_minima([logits[0]], [2], horizon=1).tolist() == [2.0]
