"""The training curriculum: family terrains at a difficulty, curriculum arenas, the env's rows
(legged_gym's terrain levels) and the walkability model as the env's condition."""

import argparse
import dataclasses
import math
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import tomllib

from leas_jax.env import LeasEnv, heightfield_from_terrain, learned_feasibility, reachability
from leas_jax.env import condition as env_condition
from leas_jax.env.config import CurriculumConfig, EnvConfig
from leas_jax.env.field import with_curriculum
from leas_jax.errors import UsageError
from leas_jax.terrain import TerrainError, load_terrain, loads_terrain
from leas_jax.terrain.commands import register
from leas_jax.terrain.curriculum import CURRICULUM_FAMILIES, curriculum_terrain
from leas_jax.terrain.families import ALL_FAMILIES, FAMILIES, family_boxes, family_terrain
from leas_jax.training.config import GENERALIST_ENV, TrainConfig, preset

TERRAINS = Path(__file__).resolve().parents[1] / "terrains"


def _boxes(family, seed, difficulty):
    return tomllib.loads("\n".join(family_boxes(family, seed, difficulty)))["box"]


def _gap_width(seed, difficulty):
    left, right = _boxes("gaps", seed, difficulty)
    return (right["center"][0] - right["size"][0] / 2) - (left["center"][0] + left["size"][0] / 2)


def _slope_deg(seed, difficulty):
    ramp = _boxes("slopes", seed, difficulty)[1]
    return math.degrees(-ramp["rpy"][1])


def _beam_width(seed, difficulty):
    return min(box["size"][1] for box in _boxes("narrow", seed, difficulty))


def _beams_width(seed, difficulty):
    boxes = _boxes("beams", seed, difficulty)
    assert len(boxes) == 3  # the grounds and the beam, at ground level
    assert all(box["center"][2] + box["size"][2] / 2 == pytest.approx(0.0) for box in boxes)
    return min(box["size"][1] for box in boxes)


@pytest.mark.parametrize(
    "measure, harder",
    [(_gap_width, 1.0), (_slope_deg, 1.0), (_beam_width, -1.0), (_beams_width, -1.0)],
    ids=["gap", "slope", "beam", "beams"],
)
def test_a_family_grows_harder_with_its_difficulty(measure, harder):
    for seed in range(4):
        values = [measure(seed, d) for d in (0.0, 0.5, 1.0)]
        assert harder * values[0] < harder * values[1] < harder * values[2], values


def test_rubble_at_difficulty_zero_is_level_and_at_one_is_tilted():
    flat = _boxes("rubble", 1, 0.0)
    rough = _boxes("rubble", 1, 1.0)
    tilt = lambda boxes: max(max(abs(b["rpy"][0]), abs(b["rpy"][1])) for b in boxes)  # noqa: E731
    assert tilt(flat) <= math.radians(0.05 * 30.0) + 1e-4
    assert tilt(rough) > math.radians(20.0)


def test_family_draws_are_seeded_and_every_family_loads():
    for family in ALL_FAMILIES:
        for difficulty in (None, 0.0, 1.0):
            text = family_terrain(family, 5, difficulty=difficulty)
            assert text == family_terrain(family, 5, difficulty=difficulty)
            assert loads_terrain(text).boxes
    # the walkability model's families keep their uniform draws apart from the curriculum's
    assert family_terrain("gaps", 5) != family_terrain("gaps", 5, difficulty=0.5)
    assert set(FAMILIES) < set(ALL_FAMILIES)


@pytest.mark.parametrize("difficulty", [None, 0.0, 0.5, 1.0])
def test_stepping_stones_lie_one_gap_from_the_ground_on_either_side(difficulty):
    for seed in range(6):
        boxes = _boxes("stones", seed, difficulty)
        grounds = [b for b in boxes if b["size"][1] == pytest.approx(3.0)]
        stones = [b for b in boxes if b["size"][1] < 3.0]
        before, after = sorted(grounds, key=lambda b: b["center"][0])
        near = min(b["center"][0] - b["size"][0] / 2 for b in stones)
        far = max(b["center"][0] + b["size"][0] / 2 for b in stones)
        gap = near - (before["center"][0] + before["size"][0] / 2)
        assert (after["center"][0] - after["size"][0] / 2) - far == pytest.approx(gap, abs=1e-3)


def test_a_difficulty_outside_the_unit_interval_is_refused():
    with pytest.raises(ValueError, match="difficulty"):
        family_boxes("rubble", 0, 1.5)


def test_a_curriculum_arena_lays_rows_of_difficulty_and_columns_of_families():
    terrain = loads_terrain(curriculum_terrain(3, levels=3, families=("flat", "gaps"), ceilings={}))
    assert terrain.curriculum.levels == 3 and terrain.curriculum.families == ("flat", "gaps")
    np.testing.assert_allclose(terrain.bounds, [[0, 0], [18, 6]])
    heights = terrain.raster()
    xs, ys = terrain.grid_axes()
    # the gaps column (y in 3..6): its void widens row after row along x
    void = heights < terrain.void_height + 1e-6
    widths = []
    for level in range(3):
        rows = (xs >= level * 6) & (xs < level * 6 + 6)
        widths.append(void[np.ix_(rows, (ys > 4.0) & (ys < 5.0))].all(axis=1).sum())
    assert widths[0] < widths[1] < widths[2]
    # the flat column is solid everywhere
    assert not void[:, (ys > 0.5) & (ys < 2.5)].any()


def test_a_familys_ceiling_scales_its_rows_difficulty():
    full = loads_terrain(curriculum_terrain(3, levels=3, families=("flat", "gaps"), ceilings={}))
    text = curriculum_terrain(3, levels=3, families=("flat", "gaps"), ceilings={"gaps": 0.5})
    capped = loads_terrain(text)
    assert text.startswith(
        "# Generated by `leas terrain curriculum --seed 3 --levels 3 --families flat,gaps --ceiling gaps=0.5`"
    )

    def widths(terrain):
        void = terrain.raster() < terrain.void_height + 1e-6
        xs, ys = terrain.grid_axes()
        rows = [(xs >= level * 6) & (xs < level * 6 + 6) for level in range(3)]
        return [void[np.ix_(r, (ys > 4.0) & (ys < 5.0))].all(axis=1).sum() for r in rows]

    full_widths, capped_widths = widths(full), widths(capped)
    assert capped_widths[0] == full_widths[0]  # row 0 is difficulty 0 either way
    assert capped_widths[0] < capped_widths[2] < full_widths[2]
    # the top row of the capped arena is the middle row's difficulty of the full one (same draws
    # but for the tile seed: the width within the difficulty jitter's spread)
    assert abs(capped_widths[2] - full_widths[1]) <= 0.1 * 0.75 / 0.02 + 1


@pytest.mark.parametrize("ceilings", [{"lava": 0.5}, {"gaps": 1.5}, {"gaps": -0.1}])
def test_a_bad_ceiling_is_refused(ceilings):
    with pytest.raises(ValueError, match="ceilings"):
        curriculum_terrain(0, levels=2, families=("gaps",), ceilings=ceilings)


def test_the_passability_sweep_lets_level_ground_through_and_finds_the_ceiling():
    import sys

    sys.path.insert(0, str(TERRAINS.parent / "studies"))
    import curriculum_passability

    assert curriculum_passability.ceiling([0.0, 0.5, 1.0], [1.0, 0.4, 0.9], 0.5) == 0.0
    assert curriculum_passability.ceiling([0.0, 0.5, 1.0], [1.0, 0.6, 0.4], 0.5) == 0.5
    config = preset("quick").env  # the reachability cylinders: a 0.8 m gap fails, level ground passes
    shares = curriculum_passability.passability(config, levels=2, seed=0, lines=2)
    assert set(shares) == set(curriculum_passability.CROSSING)
    assert shares["gaps"] == [1.0, 0.0]
    assert shares["stairs"][0] == 1.0


def test_the_committed_curriculum_arena_is_the_generated_one():
    committed = (TERRAINS / "curriculum_arena.toml").read_text()
    assert committed == curriculum_terrain(0)
    # its stairs column tops out at the stairs' ceiling: 0.11 m risers (+- the jitter), not 0.30
    terrain = loads_terrain(committed)
    heights, (xs, ys) = terrain.raster(), terrain.grid_axes()
    column = CURRICULUM_FAMILIES.index("stairs")
    top_row = np.ix_(xs >= 7 * 6.0, (ys > column * 3.0 + 0.5) & (ys < column * 3.0 + 2.5))
    steps = heights[top_row].max()
    assert 2 * 0.09 < steps < 4 * 0.13
    assert loads_terrain(committed).curriculum.families == CURRICULUM_FAMILIES


@pytest.mark.parametrize(
    "table, key",
    [
        ("[curriculum]\nlevels = 0\ntile = [6, 3]\nfamilies = ['flat']", "curriculum.levels"),
        ("[curriculum]\nlevels = 2\ntile = [6, 3]\nfamilies = 'flat'", "curriculum.families"),
        ("[curriculum]\nlevels = 9\ntile = [6, 3]\nfamilies = ['flat']", "curriculum"),
        ("[curriculum]\nlevels = 1\ntile = [6, -3]\nfamilies = ['flat']", "curriculum.tile"),
        ("[curriculum]\nlevels = 1\ntile = [6, 3]\nfamilies = ['flat']\nrows = 2", "curriculum.rows"),
    ],
)
def test_a_bad_curriculum_table_names_its_key(table, key):
    text = family_terrain("flat", 0) + "\n" + table + "\n"
    with pytest.raises(TerrainError, match=key.replace(".", r"\.")):
        loads_terrain(text)


@pytest.fixture(scope="module")
def arena():
    """A small 3-row curriculum arena, its config (cylinders) and field."""
    terrain = loads_terrain(curriculum_terrain(0, levels=3, families=("flat", "rubble")))
    config = dataclasses.replace(preset("quick").env, curriculum=CurriculumConfig(initial_max_level=0))
    return terrain, config, heightfield_from_terrain(terrain, config, require_spawn=True)


def test_the_field_sorts_spawns_by_row_and_indexes_the_rows(arena):
    terrain, _, field = arena
    start = np.asarray(field.curriculum["level_start"])
    count = np.asarray(field.curriculum["level_count"])
    xy = np.asarray(field.spawn_xy)
    assert count.sum() == len(xy) and (count > 0).all()
    for level in range(3):
        rows = xy[start[level] : start[level] + count[level], 0]
        assert rows.min() >= level * 6.0 and rows.max() < (level + 1) * 6.0


def test_a_row_without_spawn_points_is_refused(arena):
    terrain, _, field = arena
    only_first_row = field.replace(spawn_xy=field.spawn_xy[:10], spawn_yaw=field.spawn_yaw[:10])
    with pytest.raises(TerrainError, match="curriculum rows 1, 2"):
        with_curriculum(only_first_row, terrain.curriculum, "arena.toml")


def _ended(env, level, walked):
    """A root that ended its episode `walked` m from its start on row `level`."""
    root = env.random_root(jax.random.PRNGKey(level), jnp.asarray(level, jnp.int32))
    return root.replace(pos=root.pos.at[0].add(walked))


def test_envs_move_up_after_a_long_walk_and_down_after_a_short_one(arena):
    _, config, field = arena
    env = LeasEnv(field, config)
    next_row = jax.jit(lambda root: env.next_root(root).level)
    assert int(next_row(_ended(env, 0, 3.5))) == 1
    assert int(next_row(_ended(env, 1, 2.0))) == 1  # between the two distances: stays
    assert int(next_row(_ended(env, 1, 0.5))) == 0
    assert int(next_row(_ended(env, 0, 0.2))) == 0  # never below the first row
    past_top = [int(next_row(_ended(env, 2, 4.0).replace(rng=jax.random.PRNGKey(k)))) for k in range(40)]
    assert set(past_top) == {0, 1, 2}  # past the top: a random row


def test_resets_start_on_their_row(arena):
    _, config, field = arena
    env = LeasEnv(field, config)
    draw = jax.jit(jax.vmap(env.random_root))
    keys = jax.random.split(jax.random.PRNGKey(0), 256)
    for level in range(3):
        roots = draw(keys, jnp.full(256, level, jnp.int32))
        x = np.asarray(roots.pos[:, 0])
        assert (np.asarray(roots.level) == level).all()
        assert (x >= level * 6.0 - 0.1).all() and (x < (level + 1) * 6.0 + 0.1).all()
        np.testing.assert_allclose(np.asarray(roots.start), np.asarray(roots.pos[:, :2]))
    first = jax.jit(jax.vmap(lambda k: env.random_root(k)))(keys)  # initial_max_level 0
    assert (np.asarray(first.level) == 0).all()


def test_a_field_without_curriculum_keeps_row_zero():
    terrain = load_terrain(TERRAINS / "training_arena.toml")
    config = preset("quick").env
    field = heightfield_from_terrain(terrain, config)
    env = LeasEnv(field, config)
    root = env.random_root(jax.random.PRNGKey(1))
    moved = root.replace(pos=root.pos.at[0].add(5.0))
    nxt = env.next_root(moved)
    assert field.curriculum == {} and int(nxt.level) == 0
    same = env.random_root(root.rng)
    np.testing.assert_array_equal(np.asarray(nxt.pos), np.asarray(same.pos))


def test_the_walkability_condition_is_the_plausible_cylinders_and_the_network():
    terrain = loads_terrain(family_terrain("rubble", 2))
    config = GENERALIST_ENV
    field = heightfield_from_terrain(terrain, config)
    rng = np.random.default_rng(0)
    n = 400
    poses = np.stack(
        [rng.uniform(0.3, 5.7, n), rng.uniform(0.3, 2.7, n), rng.uniform(0.7, 1.3, n), rng.uniform(-3, 3, n)],
        axis=1,
    ).astype(np.float32)
    verdict = jax.jit(jax.vmap(lambda p: env_condition.valid(field, p, config)))(poses)
    network = jax.vmap(lambda p: learned_feasibility.valid(field.condition, field, p, config.reachability))(
        poses
    )
    plausible = jax.vmap(
        lambda p: reachability.valid(field, p, reachability.relaxed_reachability(config.reachability))
    )(poses)
    np.testing.assert_array_equal(np.asarray(verdict), np.asarray(network & plausible))
    assert 0 < int(verdict.sum()) < n and int((np.asarray(network) & ~np.asarray(plausible)).sum()) > 0


def test_the_condition_threshold_moves_the_networks_boundary_and_none_keeps_the_stored_one():
    """`EnvConfig.condition_threshold` replaces the threshold stored with the weights: a lower
    logit accepts a superset of the poses, and the generalist preset sets one."""
    from leas_jax.env.learned_weights import condition_params, load_params

    stored = float(load_params(TERRAINS.parent / GENERALIST_ENV.learned_weights)[0]["threshold"])
    own = dataclasses.replace(GENERALIST_ENV, condition_threshold=None)
    assert float(condition_params(own)["threshold"]) == pytest.approx(stored)
    assert GENERALIST_ENV.condition_threshold is not None and GENERALIST_ENV.condition_threshold < stored
    terrain = loads_terrain(family_terrain("stairs", 4))
    rng = np.random.default_rng(1)
    poses = np.stack(
        [
            rng.uniform(0.3, 5.7, 400),
            rng.uniform(0.3, 2.7, 400),
            rng.uniform(0.8, 1.4, 400),
            rng.uniform(-3, 3, 400),
        ],
        axis=1,
    ).astype(np.float32)

    def accepted(config):
        field = heightfield_from_terrain(terrain, config)
        return np.asarray(jax.vmap(lambda p: env_condition.valid(field, p, config))(poses))

    strict, lenient = accepted(own), accepted(GENERALIST_ENV)
    assert np.all(lenient[strict]) and lenient.sum() > strict.sum()


def test_the_generalist_preset_trains_on_the_curriculum_with_the_walkability_model():
    config = preset("generalist")
    assert config.env.condition == "walkability"
    assert config.env.rewards == preset("quick").env.rewards  # the reward terms are quick's
    assert load_terrain(config.terrain_path()).curriculum is not None
    assert TrainConfig.from_dict(config.to_dict()) == config
    planner = preset("generalist", mode="planner")  # `leas run --preset generalist`'s fine-tuning
    assert (
        planner.terrain == config.terrain and planner.env == config.env and planner.pretrain == "generalist"
    )
    legacy = config.to_dict()
    del legacy["env"]["curriculum"]  # a run saved before the curriculum existed
    assert TrainConfig.from_dict(legacy).env.curriculum == CurriculumConfig()
    with pytest.raises(ValueError, match="condition"):
        env_condition.valid(
            heightfield_from_terrain(load_terrain(TERRAINS / "eval_ground.toml")),
            jnp.zeros(4),
            dataclasses.replace(EnvConfig(), condition="walkability"),
        )


def run(*argv):
    parser = argparse.ArgumentParser(prog="leas")
    register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["terrain", *argv])
    args.func(args)


def test_the_curriculum_command_writes_a_seeded_arena(tmp_path):
    out = tmp_path / "arena.toml"
    run("curriculum", "--seed", "4", "--levels", "2", "--families", "flat,holes", "--out", str(out))
    assert out.read_text() == curriculum_terrain(4, 2, ("flat", "holes"))


def test_the_curriculum_command_caps_a_family(tmp_path):
    out = tmp_path / "capped.toml"
    run(
        "curriculum",
        "--seed",
        "4",
        "--levels",
        "2",
        "--families",
        "flat,gaps",
        "--ceiling",
        "gaps=0.25",
        "--out",
        str(out),
    )
    assert out.read_text() == curriculum_terrain(4, 2, ("flat", "gaps"), ceilings={"gaps": 0.25})


@pytest.mark.parametrize(
    "argv, message",
    [
        (("--seed", "-1"), "--seed -1"),
        (("--levels", "0"), "--levels 0"),
        (("--families", "flat,lava"), "unknown lava"),
        (("--ceiling", "gaps=1.5"), "--ceiling gaps=1.5"),
        (("--ceiling", "gaps"), "--ceiling gaps:"),
        (("--families", "flat", "--ceiling", "gaps=0.5"), "--ceiling gaps=0.5"),
    ],
)
def test_curriculum_command_errors_name_the_argument(argv, message):
    with pytest.raises(UsageError, match=message):
        run("curriculum", *argv)


def test_the_generalist_study_tabulates_pooled_coverage_with_intervals():
    import sys

    sys.path.insert(0, str(TERRAINS.parent / "studies"))
    import generalist

    row = {"guides": 32, "fully_covered": 30, "mean_progress_m": 3.0}
    results = {
        "policies": {"a": "run_a"},
        "arenas": {
            "a": {"random_10x10_V5": {"0": row, "1": {**row, "fully_covered": 28, "mean_progress_m": 2.0}}}
        },
        "scenarios": {"a": {"terrains/eval_stairs.toml": {"n": 20, "success": 19, "mean_coverage": 0.99}}},
    }
    text = generalist.markdown(results)
    assert "| random_10x10_V5 | 90.6 [81.0, 95.6] (n 64) | 2.50 |" in text
    assert "| eval_stairs | 95.0 [76.4, 99.1] (99) |" in text


def test_the_tiles_study_crosses_each_tile_from_its_flat_ground(tmp_path):
    import sys

    sys.path.insert(0, str(TERRAINS.parent / "studies"))
    import curriculum_tiles

    from leas_jax.training.policy import load_policy

    starts = curriculum_tiles.tile_starts(1, 2, (6.0, 3.0), (0.0, 0.0), 50, seed=0)
    assert np.allclose(starts[:, 0], 6.5) and (np.abs(starts[:, 1] - 7.5) <= 0.9).all()
    assert (np.abs(starts[:, 2]) <= 0.3).all()
    np.testing.assert_array_equal(
        starts, curriculum_tiles.tile_starts(1, 2, (6.0, 3.0), (0.0, 0.0), 50, seed=0)
    )
    # a 2-row arena of flat ground and gaps: the shipped policy crosses the flat tiles
    terrain = loads_terrain(curriculum_terrain(0, levels=2, families=("flat", "gaps"), ceilings={}))
    table = curriculum_tiles.cross_tiles(
        load_policy(TERRAINS.parent / "checkpoints/leas_talos"), terrain, starts_per_tile=3, seed=0, steps=400
    )
    assert [cell["row"] for cell in table["flat"]] == [0, 1]
    assert all(cell["reached"] == 3 for cell in table["flat"])
    gap = table["gaps"][1]  # a 0.80 m gap over the void: no policy crosses it under its condition
    assert gap["reached"] == 0 and gap["reached"] + gap["invalid"] + gap["short"] == 3
    results = {
        "terrain": "t",
        "starts": 3,
        "seed": 0,
        "steps": 400,
        "runs": {"p": "run"},
        "policies": {"p": table},
    }
    assert "| flat | 100 [44, 100] (0) | 100 [44, 100] (0) |" in curriculum_tiles.markdown(results)
