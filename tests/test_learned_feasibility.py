"""The learned feasibility condition: shapes, jit and vmap, determinism, a known rule learned
from synthetic data, the weights file, its selection as the env's termination condition."""

import dataclasses
import json
import re
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from leas_jax.env import EnvConfig, LeasEnv, condition, heightfield_from_terrain, reachability
from leas_jax.env import learned_feasibility as lf
from leas_jax.feasibility.fit import (
    FitConfig,
    balanced_weights,
    features_of,
    fit,
    mirrored,
    predict,
    threshold_for,
)
from leas_jax.feasibility.walking_truth import WALK_TIMESTEP, walking_guide
from leas_jax.terrain import load_terrain
from leas_jax.training.config import TRAINING_ENV

WALL = load_terrain(Path(__file__).parent / "data" / "slab_with_wall.toml")  # ground 0, wall x 4.3-4.7, y 1-5
FIELD = heightfield_from_terrain(WALL, TRAINING_ENV)
SMALL = FitConfig(hidden=(16, 8), steps=400, learning_rate=1e-2)


def _poses(n, seed=0):
    """Poses over the slab, near the wall half of the time, z 0.6-1.3 m, any yaw."""
    rng = np.random.default_rng(seed)
    x = np.where(rng.random(n) < 0.5, rng.uniform(0.8, 5.2, n), rng.uniform(3.6, 5.2, n))
    return np.column_stack(
        [x, rng.uniform(0.8, 5.2, n), rng.uniform(0.6, 1.3, n), rng.uniform(-np.pi, np.pi, n)]
    )


def test_grid_and_feature_shapes():
    grid = lf.patch_grid()
    assert grid.shape == (14 * 17, 2)  # x -0.40..0.64, y -0.64..0.64 at 0.08 m
    reach = TRAINING_ENV.reachability  # two legs, no foothold or hands: M = 1 + 2 * 2
    assert lf.margin_count(reach) == 5 and lf.margin_count(EnvConfig().reachability) == 15
    params = lf.init_params(jax.random.PRNGKey(0), reach=reach)
    assert params["w0"].shape == (len(grid) + 1 + 5, 64)
    x = np.asarray(lf.features(params, FIELD, jnp.array([2.0, 3.0, 1.0, 0.3]), reach))
    assert x.shape == (len(grid) + 1 + 5,)
    # flat ground 1.0 m under the root: every relative height -1.0, 1.0 m above the local ground
    np.testing.assert_allclose(x[: len(grid)], -1.0, atol=1e-5)
    assert x[len(grid)] == pytest.approx(1.0, abs=1e-5)
    # margins: trunk 1.0 - 0.825 m, legs reach 1.175 - 1.0 below and 1.0 - 0.55 above the ground
    np.testing.assert_allclose(x[len(grid) + 1 :], [0.175, 0.175, 0.175, 0.45, 0.45], atol=1e-5)
    assert lf.logit(params, FIELD, jnp.zeros(4), reach).shape == ()
    assert lf.valid(params, FIELD, jnp.zeros(4), reach).dtype == jnp.bool_


def test_the_local_ground_is_the_highest_terrain_near_the_root(tmp_path):
    """The height-above-ground feature reads the grid points within GROUND_RADIUS of the root
    (`ground_index`, derived from the grid, not stored in the weights file); with none it is
    the clip's top."""
    reach = TRAINING_ENV.reachability
    params = lf.init_params(jax.random.PRNGKey(0), reach=reach)
    grid, ground = np.asarray(params["grid"]), np.asarray(params["ground_index"])
    assert len(ground) == 13 and np.all(np.sum(grid[ground] ** 2, axis=-1) <= lf.GROUND_RADIUS**2)
    above = len(grid)  # the feature's index
    # the wall (x 4.3-4.7, 1.5 m high) 0.5 m ahead: in the patch, not the ground
    assert lf.features(params, FIELD, jnp.array([3.8, 3.0, 1.0, 0.0]), reach)[above] == pytest.approx(1.0)
    # the root 0.05 m past the wall's edge, 2.2 m up: the wall's top is the ground
    assert lf.features(params, FIELD, jnp.array([4.35, 3.0, 2.2, 0.0]), reach)[above] == pytest.approx(0.7)
    path = lf.save_params(tmp_path / "w.npz", params)
    with np.load(path) as stored:
        assert "ground_index" not in stored.files
    np.testing.assert_array_equal(np.asarray(lf.load_params(path)[0]["ground_index"]), ground)
    ahead_only = lf.init_params(jax.random.PRNGKey(0), grid=lf.patch_grid(x_range=(0.4, 0.64)), reach=reach)
    assert ahead_only["ground_index"].shape == (0,)
    x = lf.features(ahead_only, FIELD, jnp.array([2.0, 3.0, 1.0, 0.0]), reach)
    assert x[len(ahead_only["grid"])] == pytest.approx(lf.HEIGHT_CLIP[1])


def test_patch_turns_with_the_yaw():
    """The wall 0.5 m ahead of the root (x 4.3) shows at root-frame x 0.48-0.56 when facing +x,
    and behind-free when the root faces -x."""
    reach = TRAINING_ENV.reachability
    params = lf.init_params(jax.random.PRNGKey(0), reach=reach)
    grid = np.asarray(params["grid"])
    ahead = (np.abs(grid[:, 0] - 0.56) < 1e-4) & (np.abs(grid[:, 1]) < 1e-4)
    facing = np.asarray(lf.features(params, FIELD, jnp.array([3.8, 3.0, 1.0, 0.0]), reach))
    away = np.asarray(lf.features(params, FIELD, jnp.array([3.8, 3.0, 1.0, np.pi]), reach))
    assert facing[: len(grid)][ahead][0] == pytest.approx(0.4)  # the wall top 1.5 m, clipped at +0.4
    assert away[: len(grid)][ahead][0] == pytest.approx(-1.0, abs=1e-5)


def test_mirror_index_is_an_involution():
    grid = lf.patch_grid()
    index = lf.mirror_index(grid)
    np.testing.assert_array_equal(index[index], np.arange(len(grid)))
    np.testing.assert_allclose(grid[index], grid * np.array([1.0, -1.0]), atol=1e-6)
    # the features of a pose beside the wall and of its mirror image across the wall's axis (y 3)
    field = heightfield_from_terrain(WALL, EnvConfig())  # every term: four legs, foothold, hands
    reach = EnvConfig().reachability
    params = lf.init_params(jax.random.PRNGKey(0), reach=reach)
    full = lf.feature_mirror_index(grid, reach)
    np.testing.assert_array_equal(full[full], np.arange(len(full)))
    left = np.asarray(lf.features(params, field, jnp.array([3.9, 1.3, 1.0, 0.4]), reach))
    right = np.asarray(lf.features(params, field, jnp.array([3.9, 4.7, 1.0, -0.4]), reach))
    np.testing.assert_allclose(left[full], right, atol=0.03)
    with pytest.raises(ValueError, match="symmetric"):
        lf.mirror_index(lf.patch_grid(y_range=(-0.64, 0.56)))


def test_jit_and_vmap_agree_with_single_calls():
    reach = TRAINING_ENV.reachability
    params = lf.init_params(jax.random.PRNGKey(1), reach=reach)
    poses = jnp.asarray(_poses(16), jnp.float32)
    batched = jax.jit(jax.vmap(lambda p: lf.logit(params, FIELD, p, reach)))(poses)
    single = np.array([float(lf.logit(params, FIELD, p, reach)) for p in poses])
    np.testing.assert_allclose(np.asarray(batched), single, rtol=1e-5, atol=1e-5)


def test_threshold_keeps_the_target_share_of_feasible_poses():
    logits = np.arange(100, dtype=float)
    y = np.ones(100, bool)
    t = threshold_for(logits, y, 0.95)
    assert (logits >= t).mean() == pytest.approx(0.95)
    with pytest.raises(ValueError, match="no feasible"):
        threshold_for(logits, np.zeros(100, bool), 0.95)
    w = balanced_weights(np.array([True, False, False, False]))
    assert w[0] == pytest.approx(3 * w[1]) and w.sum() == pytest.approx(4.0)


def test_learns_the_cylinders_from_synthetic_labels_and_is_deterministic():
    """A known rule: the training presets' cylinders on the slab and its wall. Learned from
    2 400 poses, it must agree with the rule on 800 held-out ones (>= 90 %, the cylinders are a
    sharp function of the patch); the same data and seed give the same weights."""
    rule = jax.jit(jax.vmap(lambda p: reachability.valid(FIELD, p, TRAINING_ENV.reachability)))
    poses = _poses(3200, seed=3)
    labels = np.asarray(rule(jnp.asarray(poses, jnp.float32)))
    assert 0.2 < labels.mean() < 0.8  # both classes present
    reach = TRAINING_ENV.reachability
    x = features_of(lf.init_params(jax.random.PRNGKey(0), reach=reach), FIELD, poses, reach)
    params, info = fit(x[:2400], labels[:2400], SMALL, reach=reach)
    agreement = (predict(params, x[2400:]) == labels[2400:]).mean()
    assert agreement >= 0.90, agreement
    again, _ = fit(x[:2400], labels[:2400], SMALL, reach=reach)
    for k in lf.LAYER_KEYS:
        np.testing.assert_array_equal(np.asarray(params[k]), np.asarray(again[k]))
    assert info["poses"] == 2400 and info["aside"] == 360
    # the mirrored features of the mirrored terrain: a flat slab is its own mirror image
    flat = x[np.abs(poses[:, 0] - 2.0) < 0.5][:5]
    np.testing.assert_allclose(mirrored(flat, np.asarray(params["grid"]), reach), flat, atol=1e-5)


def test_weights_round_trip_and_bad_files(tmp_path):
    params = lf.init_params(jax.random.PRNGKey(2), hidden=(8, 4))
    path = lf.save_params(tmp_path / "w.npz", params, data_key="abc")
    loaded, meta = lf.load_params(path)
    assert meta == {"data_key": "abc"}
    for k, v in params.items():
        np.testing.assert_array_equal(np.asarray(loaded[k]), np.asarray(v))
    np.savez(tmp_path / "bad.npz", grid=np.zeros((2, 2)))
    with pytest.raises(ValueError, match="bad.npz.*missing"):
        lf.load_params(tmp_path / "bad.npz")
    with pytest.raises(ValueError, match="nope.npz"):
        lf.load_params(tmp_path / "nope.npz")


def test_env_selects_the_learned_condition(tmp_path):
    """condition "learned": the field carries the weights, the env terminates where the network
    says so (a network whose threshold rejects everything ends every episode at its first step)."""
    params = lf.init_params(jax.random.PRNGKey(0), hidden=(8, 4), reach=TRAINING_ENV.reachability)
    accept = lf.save_params(tmp_path / "accept.npz", {**params, "threshold": jnp.asarray(-1e9)})
    reject = lf.save_params(tmp_path / "reject.npz", {**params, "threshold": jnp.asarray(1e9)})
    done = {}
    for name, path in (("accept", accept), ("reject", reject)):
        config = dataclasses.replace(TRAINING_ENV, condition="learned", learned_weights=str(path))
        field = heightfield_from_terrain(WALL, config)
        assert set(field.condition) >= {"grid", "w0", "threshold"}
        env = LeasEnv(field, config)
        state = jax.jit(env.reset)(jax.random.PRNGKey(0))
        done[name] = float(jax.jit(env.step)(state, jnp.zeros(4)).done)
    assert done == {"accept": 0.0, "reject": 1.0}
    assert heightfield_from_terrain(WALL, TRAINING_ENV).condition == {}
    with pytest.raises(ValueError, match="condition must be"):
        heightfield_from_terrain(WALL, dataclasses.replace(TRAINING_ENV, condition="boxes"))
    with pytest.raises(ValueError, match="no learned condition"):
        condition.valid(FIELD, jnp.zeros(4), dataclasses.replace(EnvConfig(), condition="learned"))
    fitted = lf.save_params(
        tmp_path / "fitted.npz", params, reachability=json.dumps(dataclasses.asdict(EnvConfig().reachability))
    )
    with pytest.raises(ValueError, match="fitted.npz.*another ReachabilityConfig"):
        heightfield_from_terrain(
            WALL, dataclasses.replace(TRAINING_ENV, condition="learned", learned_weights=str(fitted))
        )


def test_shipped_weights_agree_with_the_generator_on_held_out_poses():
    """Parity: the committed weights (`leas feasibility condition`) against the contact
    generator's walking truth on 24 arena poses none of their data holds (seed 99). On 4 000
    fresh poses they reach 92.1 % sensitivity and 95.1 % specificity (~94 % agreement);
    below 70 % on 24 poses would have probability < 1e-3 at that rate."""
    from leas_jax.contacts.planner.generator import ContactGenerator
    from leas_jax.feasibility.poses import ARENA, sample_poses

    arena = load_terrain(ARENA)
    config = dataclasses.replace(EnvConfig(), condition="learned")  # the shipped weights, calibrated margins
    field = heightfield_from_terrain(arena, config)
    poses = sample_poses(arena, 24, seed=99)
    ours = np.asarray(
        jax.jit(jax.vmap(lambda p: condition.valid(field, p, config)))(jnp.asarray(poses, jnp.float32))
    )
    generator = ContactGenerator(arena)
    truth = np.array([generator.plan(walking_guide(p), WALK_TIMESTEP).coverage >= 1.0 for p in poses])
    assert truth.any() and not truth.all()
    assert (ours == truth).mean() >= 0.70, (ours, truth)


def test_train_command_selects_the_learned_condition():
    """`leas train --reachability learned`: the learned condition on the calibrated cylinders'
    margins; in planner mode refreshed on the generator's verdicts (DAgger), not in geometric mode."""
    from leas_jax.cli import build_parser
    from leas_jax.training.commands import config_from_args
    from leas_jax.training.config import LEARNED_REFRESH_EVERY

    parser = build_parser()
    geometric = config_from_args(
        parser.parse_args(["train", "--out", "r", "--preset", "smoke", "--reachability", "learned"])
    )
    planner = config_from_args(
        parser.parse_args(
            ["train", "--out", "r", "--mode", "planner", "--preset", "smoke", "--reachability", "learned"]
        )
    )
    for config in (geometric, planner):
        assert config.env.condition == "learned" and config.env.reachability == EnvConfig().reachability
        assert config.env.learned_weights == "checkpoints/feasibility/walking.npz"
    assert geometric.condition_refresh_every == 0 and planner.condition_refresh_every == LEARNED_REFRESH_EVERY
    default = config_from_args(parser.parse_args(["train", "--out", "r", "--preset", "smoke"]))
    assert default.env.condition == "cylinders"


def test_train_command_sets_or_freezes_the_dagger_refits():
    """`--condition-refresh-every N` sets the planner phase's refit period (0: the condition stays
    as loaded); outside `--mode planner --reachability learned`, or below 0, it is refused."""
    from leas_jax.cli import build_parser
    from leas_jax.errors import UsageError
    from leas_jax.training.commands import config_from_args

    parser = build_parser()
    planner = ["train", "--out", "r", "--mode", "planner", "--preset", "smoke", "--reachability", "learned"]
    for period in (0, 7):
        config = config_from_args(parser.parse_args([*planner, "--condition-refresh-every", str(period)]))
        assert config.condition_refresh_every == period and config.env.condition == "learned"
    for misplaced in (
        ["train", "--out", "r", "--preset", "smoke", "--reachability", "learned"],
        ["train", "--out", "r", "--mode", "planner", "--preset", "smoke"],
    ):
        with pytest.raises(UsageError, match="--condition-refresh-every"):
            config_from_args(parser.parse_args([*misplaced, "--condition-refresh-every", "0"]))
    with pytest.raises(SystemExit):
        parser.parse_args([*planner, "--condition-refresh-every", "-1"])


def test_train_command_takes_other_condition_weights(tmp_path):
    """`--condition-weights FILE` selects the learned condition's weights; a missing file or the
    option without `--reachability learned` is refused naming the option."""
    from leas_jax.cli import build_parser
    from leas_jax.errors import UsageError
    from leas_jax.training.commands import config_from_args

    weights = tmp_path / "other.npz"
    weights.write_bytes(b"")
    parser = build_parser()
    base = ["train", "--out", "r", "--preset", "smoke"]
    chosen = config_from_args(
        parser.parse_args([*base, "--reachability", "learned", "--condition-weights", str(weights)])
    )
    assert chosen.env.condition == "learned" and chosen.env.learned_weights == str(weights)
    with pytest.raises(UsageError, match="--condition-weights: no such file"):
        config_from_args(
            parser.parse_args(
                [*base, "--reachability", "learned", "--condition-weights", str(tmp_path / "missing.npz")]
            )
        )
    with pytest.raises(UsageError, match="--condition-weights is for --reachability learned"):
        config_from_args(parser.parse_args([*base, "--condition-weights", str(weights)]))


def test_feasibility_condition_command_runs_end_to_end(tmp_path, capsys, monkeypatch):
    """`leas feasibility condition` on tiny settings: labels (cached under --cache, reused by a
    second build), fit, weights with their data key, and the report with the machine, load and
    commit; bad options are refused in one line with exit code 2."""
    from leas_jax.cli import main
    from leas_jax.feasibility import walkability

    weights = tmp_path / "w.npz"
    report = tmp_path / "report"
    params = lf.init_params(jax.random.PRNGKey(0), reach=EnvConfig().reachability)
    reject = lf.save_params(tmp_path / "reject.npz", {**params, "threshold": jnp.asarray(1e9)})
    tiny = ["feasibility", "condition", "--train-poses", "24", "--test-poses", "12"]
    tiny += ["--policy-train-poses", "0", "--policy-poses", "0", "--workers", "0", "--steps", "20"]
    tiny += ["--cost-envs", "0"]
    tiny += ["--weights", str(weights), "--cache", str(tmp_path / "cache")]
    assert main([*tiny, "--compare-weights", str(reject), "--out", str(report)]) == 0
    labels = sorted(
        p.relative_to(tmp_path / "cache" / "condition") for p in (tmp_path / "cache").rglob("*.npz")
    )
    assert [p.parts[0] for p in labels] == ["fresh12_seed11", "fresh24_seed13"]
    saved = json.loads((report / "feasibility_condition.json").read_text())
    assert saved["command"] == "leas feasibility condition"
    assert {"machine", "git", "load_average_before", "load_average_after"} <= set(saved)
    learned = saved["validation"]["fresh"]["learned"]
    assert learned["tp"] + learned["fn"] + learned["fp"] + learned["tn"] == 12
    # other weights validated on the same poses: these call every pose infeasible
    rejecting = saved["validation"]["fresh"][f"learned ({reject})"]
    assert rejecting["tp"] == rejecting["fp"] == 0 and rejecting["fn"] == learned["tp"] + learned["fn"]
    params, metadata = lf.load_params(weights)
    assert metadata["data_key"] == saved["data_key"] and metadata["terrain"] == "terrains/training_arena.toml"
    assert "| fresh |" in (report / "feasibility_condition.md").read_text()

    def refuse(chunk):
        raise AssertionError("the cache holds these labels")

    monkeypatch.setattr(walkability, "_walk", refuse)
    assert main(tiny) == 0  # the same labels, from the cache; the report beside the weights
    again = json.loads((tmp_path / "feasibility_condition.json").read_text())
    assert again["data"]["feasible_fraction"] == saved["data"]["feasible_fraction"]
    capsys.readouterr()
    for bad, message in (
        (
            ["--compare-weights", str(tmp_path / "missing.npz")],
            "--compare-weights .*missing.npz: no such file",
        ),
        (["--test-seed", "13"], "seeds must differ"),
        (["--weights", str(tmp_path / "w.txt")], "--weights: expected a .npz file"),
        (["--train-poses", "0"], "--train-poses"),
    ):
        try:
            code = main([*tiny, *bad])
        except SystemExit as exit_:  # argparse's own errors
            code = exit_.code
        err = capsys.readouterr().err.strip()
        assert code == 2, bad
        assert len(err.splitlines()) == 1 and re.search(message, err), err


def test_clearance_probes_are_judged_by_the_selected_condition(tmp_path):
    """EnvConfig.clearance_condition: "condition" judges the clearance term's six probes with the
    termination condition (a network that rejects everything: all six fail), "cylinders" with
    the env's cylinders whatever the condition (the same shortfall as `reachability`'s: 0 for
    some poses, a fraction for others); another value is refused naming the field."""
    from leas_jax.errors import UsageError
    from leas_jax.training.config import preset

    reach = TRAINING_ENV.reachability
    params = lf.init_params(jax.random.PRNGKey(0), hidden=(8, 4), reach=reach)
    reject = lf.save_params(tmp_path / "reject.npz", {**params, "threshold": jnp.asarray(1e9)})
    learned = dataclasses.replace(TRAINING_ENV, condition="learned", learned_weights=str(reject))
    field = heightfield_from_terrain(WALL, learned)
    poses = jnp.asarray(_poses(64, seed=3), jnp.float32)

    def shortfall(config):
        return np.asarray(
            jax.jit(jax.vmap(lambda p: condition.clearance_shortfall(field, p, 0.1, config)))(poses)
        )

    np.testing.assert_array_equal(shortfall(learned), 1.0)
    cylinders = shortfall(dataclasses.replace(learned, clearance_condition="cylinders"))
    expected = np.asarray(jax.vmap(lambda p: reachability.clearance_shortfall(field, p, 0.1, reach))(poses))
    np.testing.assert_array_equal(cylinders, expected)
    assert (cylinders == 0.0).any() and ((cylinders > 0.0) & (cylinders < 1.0)).any()
    with pytest.raises(ValueError, match="clearance_condition must be one of condition, cylinders"):
        condition.clearance_shortfall(
            field, poses[0], 0.1, dataclasses.replace(learned, clearance_condition="x")
        )
    with pytest.raises(UsageError, match="env.clearance_condition"):
        preset("smoke", env=dataclasses.replace(TRAINING_ENV, clearance_condition="network"))


def test_train_command_sets_the_clearance_probes_judge():
    """`--clearance-condition` sets EnvConfig.clearance_condition of a learned-condition preset
    with the clearance term (both modes: `leas run` passes it to both phases); without it the
    network judges; it is refused with the cylinders, a preset without the term, or another value."""
    from leas_jax.cli import build_parser
    from leas_jax.errors import UsageError
    from leas_jax.training.commands import config_from_args

    parser = build_parser()
    learned = ["train", "--out", "r", "--preset", "quick", "--reachability", "learned"]
    assert config_from_args(parser.parse_args(learned)).env.clearance_condition == "condition"
    for mode in ("geometric", "planner"):
        config = config_from_args(
            parser.parse_args([*learned, "--mode", mode, "--clearance-condition", "cylinders"])
        )
        assert config.env.condition == "learned" and config.env.clearance_condition == "cylinders"
    with pytest.raises(UsageError, match="--clearance-condition is for --reachability learned"):
        config_from_args(parser.parse_args(["train", "--out", "r", "--clearance-condition", "cylinders"]))
    with pytest.raises(UsageError, match="preset 'paper' has no clearance term"):
        config_from_args(
            parser.parse_args(
                [
                    "train",
                    "--out",
                    "r",
                    "--preset",
                    "paper",
                    "--reachability",
                    "learned",
                    "--clearance-condition",
                    "cylinders",
                ]
            )
        )
    with pytest.raises(SystemExit):
        parser.parse_args([*learned, "--clearance-condition", "network"])
