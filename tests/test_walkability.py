"""The walkability model: terrain families, the plausible set and the model's verdicts (shapes,
jit), a known rule learned from synthetic labels, the label cache's invalidation, rates, and the
`leas feasibility walkability` command's errors, and the warning where a model was labelled by
another generator."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
import warnings

import jax
import numpy as np
import pytest

from leas_jax.env.config import ReachabilityConfig
from leas_jax.feasibility import walkability as wk
from leas_jax.terrain import loads_terrain
from leas_jax.terrain.families import FAMILIES, family_terrain

CONFIG = wk.WalkabilityConfig()


@pytest.mark.parametrize("family", FAMILIES)
def test_every_family_draws_a_seeded_terrain_with_its_feature(family):
    first, again, other = (family_terrain(family, s) for s in (0, 0, 1))
    assert first == again and first != other
    terrain = loads_terrain(first)
    heights = terrain.raster()
    res = terrain.resolution
    before = heights[int(0.5 / res) : int(1.5 / res)]  # flat ground at z = 0 before the feature
    assert np.allclose(before, 0.0, atol=1e-6)
    feature = heights[int(2.1 / res) : int(4.3 / res)]
    assert np.ptp(feature) > 0.03, "the feature is not flat ground"


def test_an_unknown_family_names_the_known_ones():
    with pytest.raises(ValueError, match="unknown terrain family 'lava'.*rubble, blocks"):
        family_terrain("lava", 0)


def test_the_plausible_condition_drops_the_lookahead_and_the_sole_flatness():
    reach = ReachabilityConfig()
    relaxed = wk.relaxed_reachability(reach)
    assert relaxed.leg_forward == 0.0 and relaxed.foothold_spread is None
    assert relaxed.trunk_bottom == reach.trunk_bottom and relaxed.hand_radius == reach.hand_radius
    assert wk.relaxed_reachability(reach, 0.12).foothold_spread == 0.12


def _field(text):
    terrain = loads_terrain(text)
    return terrain, wk._field(terrain)


def test_judge_gives_root_heights_and_a_model_only_splits_the_plausible_set():
    from leas_jax.env import learned_feasibility as lf

    terrain, field = _field(family_terrain("rubble", 0))
    rng = np.random.default_rng(0)
    planar = np.column_stack(
        [rng.uniform(0.5, 5.5, 300), rng.uniform(0.5, 2.5, 300), rng.uniform(-3, 3, 300)]
    )
    ground = wk.crack_filled_ground(field, CONFIG.crack_width)
    reach = ReachabilityConfig()
    plausible = wk.relaxed_reachability(reach)
    z, sure, maybe = wk.judge_poses(field, ground, planar, 1.0, reach, plausible, None, chunk=128)
    assert z.shape == sure.shape == maybe.shape == (300,)
    assert np.all(maybe[sure]), "a confident pose is plausible"
    flat = planar[:, 0] < 1.8
    assert np.allclose(z[flat], 1.0, atol=1e-5) and maybe[flat].all()
    assert (maybe & ~sure)[~flat].any(), "the tiles hold doubtful poses"
    model = lf.init_params(jax.random.PRNGKey(0), reach=reach)
    for threshold, expect in ((-np.inf, maybe), (np.inf, np.zeros(300, bool))):
        model["threshold"] = jax.numpy.asarray(threshold, jax.numpy.float32)
        _, judged, again = wk.judge_poses(field, ground, planar, 1.0, reach, plausible, model, chunk=128)
        assert np.array_equal(judged, expect) and np.array_equal(again, maybe)


def test_a_known_rule_is_learned_from_synthetic_labels():
    """Walkable iff the ground 0.25-0.6 m ahead rises 5 cm above the ground under the root: a rule
    on the patch features alone, which the fit must recover on terrains it did not see."""
    from leas_jax.env import learned_feasibility as lf
    from leas_jax.feasibility.fit import FitConfig, features_of, fit, predict

    reach = ReachabilityConfig()
    params = lf.init_params(jax.random.PRNGKey(0), reach=reach)
    grid = np.asarray(params["grid"])
    ahead = (grid[:, 0] > 0.25) & (grid[:, 0] < 0.6) & (np.abs(grid[:, 1]) < 0.2)

    def labelled(family, seed):
        terrain, field = _field(family_terrain(family, seed))
        poses, _ = wk.plausible_poses(field, terrain.bounds, 400, seed, CONFIG)
        x = features_of(params, field, poses, reach)
        return x, x[:, : len(grid)][:, ahead].max(axis=1) > -CONFIG.nominal_root_height + 0.05

    parts = [labelled(f, s) for f in ("stairs", "blocks", "clutter") for s in (0, 1)]
    x, y = (np.concatenate(a) for a in zip(*parts))
    assert 0.1 < y.mean() < 0.9
    model, _ = fit(x, y, FitConfig(steps=400, mirror=False, target_sensitivity=0.95))
    tx, ty = labelled("stairs", 7)
    accuracy = (predict(model, tx) == ty).mean()
    assert accuracy > 0.9, accuracy


def test_rates_count_and_bound_both_classes():
    r = wk.rates(np.array([1, 1, 0, 0, 1], bool), np.array([1, 1, 1, 0, 0], bool))
    assert (r["walkable"], r["not_walkable"]) == (3, 2)
    assert r["sensitivity"] == pytest.approx(2 / 3) and r["specificity"] == pytest.approx(0.5)
    low, high = r["sensitivity_ci"]
    assert low < 2 / 3 < high


def test_walking_labels_are_cached_and_rebuilt_when_the_generator_changes(tmp_path, monkeypatch):
    from leas_jax.contacts.planner.config import GeneratorConfig

    terrain = loads_terrain(family_terrain("gaps", 0))
    poses = np.array([[1.0, 1.5, 1.0, 0.0], [1.0, 1.0, 1.0, 0.3], [5.0, 1.5, 1.0, 3.1]])
    first = wk.walking_labels(terrain, poses, tmp_path, workers=0)
    assert first.all(), "flat ground is walkable"

    def refuse(chunk):
        raise AssertionError("the cache holds these labels")

    monkeypatch.setattr(wk, "_walk", refuse)
    assert np.array_equal(wk.walking_labels(terrain, poses, tmp_path, workers=0), first)
    monkeypatch.setattr(wk, "_walk", lambda chunk: np.zeros(len(chunk), bool))
    other = dataclasses.replace(GeneratorConfig(), lookahead=0.6)
    assert not wk.walking_labels(terrain, poses, tmp_path, workers=0, generator_config=other).any()
    moved = loads_terrain(family_terrain("gaps", 1))  # another terrain text: another key
    assert not wk.walking_labels(moved, poses, tmp_path, workers=0).any()


def test_a_model_labelled_by_another_generator_warns_when_loaded(tmp_path):
    """The build records the generator's key; loading a model whose key is not the current
    generator's warns, naming the file; one with the current key, or with none (built before the
    key was recorded), loads silently."""
    from leas_jax.contacts.planner.config import GeneratorConfig
    from leas_jax.env import learned_feasibility as lf
    from leas_jax.feasibility.walking_truth import StaleConditionWarning, generator_key

    reach = ReachabilityConfig()
    params = lf.init_params(jax.random.PRNGKey(0), hidden=(8, 4), reach=reach)
    assert generator_key() != generator_key(dataclasses.replace(GeneratorConfig(), lookahead=0.6))
    stale = lf.save_params(tmp_path / "stale.npz", params, generator_key="0" * 64)
    with pytest.warns(StaleConditionWarning, match="stale.npz: the walkability model was fitted"):
        wk.load_walkability(stale, reach)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        wk.load_walkability(
            lf.save_params(tmp_path / "now.npz", params, generator_key=generator_key()), reach
        )
        wk.load_walkability(lf.save_params(tmp_path / "unkeyed.npz", params), reach)


@pytest.mark.parametrize(
    "args, message",
    [
        (["--out", "w.txt"], "--out: expected a .npz file"),
        (["--held-out", "lava"], "--held-out: unknown families lava"),
        (["--scenes", "no/such/*.toml"], "--scenes: 'no/such/\\*.toml' matches no file"),
        (["--poses-per-terrain", "0"], "--poses-per-terrain"),
        (["--root-height-jitter", "-0.1"], "--root-height-jitter: expected a finite number >= 0"),
        (["--terrains-per-family", "9990"], "--terrains-per-family, --jittered-terrains-per-family: at most"),
    ],
)
def test_walkability_command_errors_are_one_line(args, message, tmp_path):
    import re

    run = subprocess.run(
        [sys.executable, "-m", "leas_jax.cli", "feasibility", "walkability", *args],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert run.returncode == 2
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and re.search(message, lines[0]), run.stderr


def test_test_terrains_and_scenes_keep_their_own_draws(tmp_path, monkeypatch):
    """`test_poses_per_terrain` sets the draws of the test terrains and scenes, the held-out
    families have terrains and draws of their own, the fit keeps `poses_per_terrain`, and a test
    pose is the same pose whatever the fit's draws: a build with many small fitting terrains is
    judged on the same poses as one with a few large ones. A build with `footing` writes a model
    that reads the footing shares at its places, one without it a model that does not."""
    from leas_jax.env import learned_feasibility as lf

    drawn = []

    def labels(terrain, poses, cache, workers, generator_config=None):
        drawn.append((terrain.name, len(poses), poses[:3].copy()))
        return poses[:, 0] < 3.5  # a known rule, so that both classes are there to fit

    monkeypatch.setattr(wk, "walking_labels", labels)
    scene = loads_terrain(family_terrain("slopes", 7), source="<scene>")
    config = dataclasses.replace(
        CONFIG,
        train_families=("gaps", "slopes"),
        held_out_families=("blocks",),
        terrains_per_family=3,
        jittered_terrains_per_family=1,
        test_terrains_per_family=1,
        poses_per_terrain=20,
        test_poses_per_terrain=60,
        held_out_terrains_per_family=2,
        held_out_poses_per_terrain=40,
        footing=False,
    )
    wk.build(tmp_path / "w.npz", config, scenes=(scene,), cache=tmp_path, workers=0, say=lambda _: None)
    counts = [n for _, n, _ in drawn]
    # the fit (3 + 1 jittered terrains of gaps and slopes), the tests (one terrain of each, nominal
    # and jittered), blocks on two terrains, the scene
    assert len(counts) == 8 + 4 + 2 + 1
    fit_draws, test_draws, held_draws, scene_draws = counts[:8], counts[8:12], counts[12:14], counts[14:]
    assert max(fit_draws) <= 20 < max(held_draws) <= 40 < min(test_draws + scene_draws) <= 60
    first_test = drawn[8][2]
    drawn.clear()
    wk.build(
        tmp_path / "v.npz",
        dataclasses.replace(config, terrains_per_family=1, poses_per_terrain=60, footing=True),
        scenes=(scene,),
        cache=tmp_path,
        workers=0,
        say=lambda _: None,
    )
    assert np.array_equal(drawn[4][2], first_test), "a test terrain's poses do not depend on the fit's"
    plain, footing = lf.load_params(tmp_path / "w.npz")[0], lf.load_params(tmp_path / "v.npz")[0]
    assert "footing" not in plain
    np.testing.assert_array_equal(np.asarray(footing["footing"]), lf.footing_points(ReachabilityConfig()))
    assert footing["w0"].shape[0] == plain["w0"].shape[0] + 2 * len(lf.footing_points(ReachabilityConfig()))


def test_no_fitting_terrain_is_a_test_terrain():
    """The fit's seeds (nominal and jittered), the tests' and the held-out families' are apart for
    any size up to the bound, and a size past it is refused."""
    for terrains in (1, 120, wk.TEST_SEEDS - 40):
        seeds = wk.build_seeds(dataclasses.replace(CONFIG, terrains_per_family=terrains))
        training = [seeds.fit, seeds.jittered_fit, seeds.test, seeds.jittered_test]
        every = [s for r in training for s in r]
        assert len(every) == len(set(every)) == sum(len(r) for r in training)
        assert len(seeds.fit) == terrains and len(seeds.held_out) == CONFIG.held_out_terrains_per_family
    with pytest.raises(ValueError, match="at most 10000 fitting terrains"):
        wk.build_seeds(dataclasses.replace(CONFIG, terrains_per_family=wk.TEST_SEEDS))


def test_jittered_poses_are_the_lattices_poses_moved_up_or_down():
    """Jittered root heights keep the lattice's (x, y, yaw) draws, move z by at most the jitter,
    and every pose kept is plausible at its own height; without jitter the draws are unchanged."""
    terrain, field = _field(family_terrain("stairs", 3))
    nominal, nominal_cylinders = wk.plausible_poses(field, terrain.bounds, 300, 5, CONFIG)
    again, _ = wk.plausible_poses(field, terrain.bounds, 300, 5, CONFIG, height_jitter=0.0)
    assert np.array_equal(again, nominal)
    jittered, cylinders = wk.plausible_poses(field, terrain.bounds, 300, 5, CONFIG, height_jitter=0.1)
    index = {tuple(p[[0, 1, 3]]): p[2] for p in nominal}
    moved = np.array([p[2] - index[tuple(p[[0, 1, 3]])] for p in jittered])  # KeyError: a new draw
    assert np.abs(moved).max() <= 0.1 + 1e-6 and np.abs(moved).max() > 0.05
    assert 0.5 * len(nominal) < len(jittered) <= len(nominal)
    from leas_jax.env import reachability

    def valid(reach):
        return np.asarray(
            reachability.valid_poses(field, jax.numpy.asarray(jittered, jax.numpy.float32), reach)
        )

    assert valid(wk.relaxed_reachability(ReachabilityConfig())).all()
    assert np.array_equal(cylinders, valid(ReachabilityConfig()))
    assert nominal_cylinders.any() and cylinders.any() and not cylinders.all()


def test_the_default_build_is_the_shipped_models_recipe():
    """`leas feasibility walkability` with no size options rebuilds the shipped model: its recorded
    settings are the config's defaults."""
    import json
    from pathlib import Path

    from leas_jax.env import learned_feasibility as lf

    folder = Path(__file__).parents[1] / "checkpoints/walkability"
    shipped = json.loads((folder / "walkability.json").read_text())
    defaults = json.loads(json.dumps(dataclasses.asdict(wk.WalkabilityConfig())))
    assert shipped["config"] == defaults
    # and its weights read what the recipe says: the footing shares at their places
    weights = lf.load_params(folder / "walkability.npz")[0]
    assert ("footing" in weights) == defaults["footing"]
