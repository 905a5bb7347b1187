"""The learned condition's data: the labels' cache key and its invalidation, resuming a build,
weights fitted on another generator named stale."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from leas_jax.contacts.planner.generator import GeneratorConfig
from leas_jax.feasibility.label_cache import cached_labels, load_partial
from leas_jax.feasibility.walking_truth import dataset_key

TERRAIN = (Path(__file__).parent / "data" / "slab_with_wall.toml").read_text()


def test_key_changes_with_the_generator_config_the_terrain_and_the_sources(tmp_path):
    base = dataset_key(TERRAIN, GeneratorConfig())
    assert dataset_key(TERRAIN, GeneratorConfig()) == base
    assert dataset_key(TERRAIN, dataclasses.replace(GeneratorConfig(), step_trigger=0.08)) != base
    assert dataset_key(TERRAIN + "\n# edited\n", GeneratorConfig()) != base
    sources = tmp_path / "contacts" / "planner"
    sources.mkdir(parents=True)
    (sources / "generator.py").write_text("x = 1\n")
    first = dataset_key(TERRAIN, GeneratorConfig(), tmp_path / "contacts")
    (sources / "generator.py").write_text("x = 2\n")  # a sub-package's source counts too
    assert dataset_key(TERRAIN, GeneratorConfig(), tmp_path / "contacts") != first


class Labeller:
    """Labels a pose feasible when its x > 0; counts the poses it labelled; fails after `fail_after` chunks."""

    def __init__(self, fail_after=None):
        self.poses, self.fail_after, self.chunks = 0, fail_after, 0

    def __call__(self, chunks):
        for chunk in chunks:
            if self.fail_after is not None and self.chunks >= self.fail_after:
                raise KeyboardInterrupt
            self.chunks += 1
            self.poses += len(chunk)
            yield chunk[:, 0] > 0


def test_cache_reused_rebuilt_when_the_key_changes_and_resumed(tmp_path):
    poses = np.random.default_rng(0).normal(size=(25, 4))
    path = tmp_path / "labels.npz"
    key = dataset_key(TERRAIN, GeneratorConfig())
    first = Labeller()
    labels = cached_labels(poses, key, path, first, chunk=10)
    np.testing.assert_array_equal(labels, poses[:, 0] > 0)
    assert first.poses == 25
    again = Labeller()
    np.testing.assert_array_equal(cached_labels(poses, key, path, again, chunk=10), labels)
    assert again.poses == 0  # from the cache
    other_key = dataset_key(TERRAIN, dataclasses.replace(GeneratorConfig(), max_candidates=8))
    rebuilt = Labeller()
    cached_labels(poses, other_key, path, rebuilt, chunk=10)
    assert rebuilt.poses == 25  # the generator config changed: every label recomputed
    other_poses = Labeller()
    cached_labels(poses + 1.0, other_key, path, other_poses, chunk=10)
    assert other_poses.poses == 25
    # an interrupted build keeps its finished chunks and resumes after them
    resumed_path = tmp_path / "resumed.npz"
    with pytest.raises(KeyboardInterrupt):
        cached_labels(poses, key, resumed_path, Labeller(fail_after=2), chunk=10)
    assert len(load_partial(resumed_path, poses, key)) == 20
    rest = Labeller()
    np.testing.assert_array_equal(cached_labels(poses, key, resumed_path, rest, chunk=10), labels)
    assert rest.poses == 5


def test_weights_fitted_on_another_generator_are_named_stale():
    """`walking_truth.stale_weights`: weights whose labels' key is the current generator's pass;
    another generator's key gives one message naming the file and the relabelling command;
    weights that carry no key (the planner phase's refits) cannot be judged."""
    from leas_jax.feasibility.walking_truth import RELABEL_COMMAND, stale_weights

    arena = "terrains/training_arena.toml"
    current = dataset_key((Path(__file__).resolve().parents[1] / arena).read_text(), GeneratorConfig())
    assert stale_weights(Path("w.npz"), {"data_key": current, "terrain": arena}) is None
    other = dataclasses.replace(GeneratorConfig(), step_trigger=0.08)
    message = stale_weights(Path("w.npz"), {"data_key": current, "terrain": arena}, other)
    assert message.startswith("w.npz: ") and RELABEL_COMMAND in message and current[:12] in message
    assert stale_weights(Path("w.npz"), {"refreshes": "3"}) is None


def test_the_generator_digest_reads_the_generator_and_terrain_loading_not_the_viewer(tmp_path):
    """Editing the viewer or a terrain generator leaves the labels' key; the generator's code does not."""
    from leas_jax.feasibility.spawns import GENERATOR_SOURCES, generator_code_digest

    names = {p.name for p in GENERATOR_SOURCES}
    assert {"planner", "robot", "model.py", "loader.py"} <= names
    assert not names & {"contacts", "terrain", "viewer.py", "curriculum.py", "families.py"}
    (tmp_path / "pkg").mkdir()
    source = tmp_path / "pkg" / "model.py"
    source.write_text("x = 1\n")
    before = generator_code_digest((source,))
    (tmp_path / "pkg" / "viewer.py").write_text("y = 2\n")  # beside it, not a source
    assert generator_code_digest((source,)) == before
    source.write_text("x = 2\n")
    assert generator_code_digest((source,)) != before
