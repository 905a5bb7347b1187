"""Navigate's global layer on rough ground: doubtful nodes offered at a cost and judged by the
generator on demand, the step model, cracks, and A* against plain Dijkstra.

The closed-loop tests inject `plan_fn` (the pool's test hook): stand-ins for the generator that
either walk every guide or stop where a guide enters the rough strip, so they check what the
loop does with the verdicts, in seconds.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from navigate_helpers import plan_until

from leas_jax.contacts.validation.pool import ValidationPool
from leas_jax.navigate import result as reasons
from leas_jax.navigate.lattice import LatticeConfig, build_lattice, heading_index
from leas_jax.navigate.loop import NavigateConfig, Navigator
from leas_jax.navigate.search import SearchConfig, goal_nodes, graph, search, start_node
from leas_jax.terrain import load_terrain, loads_terrain

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "checkpoints" / "leas_talos"
ROUGH_X = (3.0, 4.2)  # m: the rough strip of ROUGH_STRIP spans these x


def _tiles(width_y: float, y0: float) -> str:
    """Boxes of a strip of 0.3 m tiles across x in ROUGH_X, pitched +-20 deg in turn."""
    out = []
    for k, x in enumerate(np.arange(ROUGH_X[0] + 0.15, ROUGH_X[1], 0.3)):
        pitch = 0.35 if k % 2 == 0 else -0.35
        out.append(
            f"[[box]]\ncenter = [{x:.2f}, {y0 + width_y / 2:.2f}, -0.05]\n"
            f"size = [0.3, {width_y:.2f}, 0.1]\nrpy = [0.0, {pitch}, 0.0]\n"
        )
    return "\n".join(out)


def _terrain(name: str, boxes: list[tuple[float, float, float, float]], extra: str = "") -> str:
    """An 8 x 3 m terrain of full-width boxes (x centre, z centre, x size, z size), then `extra`."""
    text = f'name = "{name}"\nbounds = [[0.0, 0.0], [8.0, 3.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
    for x, z, size_x, size_z in boxes:
        text += f"[[box]]\ncenter = [{x}, 1.5, {z}]\nsize = [{size_x}, 3.0, {size_z}]\n"
    return text + extra


def _slab(name: str, tiles: str, extra: str = "") -> str:
    """An 8 x 3 m slab with its top at 0, a gap for the tiles in ROUGH_X over the full width."""
    return _terrain(name, [(1.5, -0.1, 3.0, 0.2), (6.1, -0.1, 3.8, 0.2)], f"{tiles}\n{extra}\n")


# The tiles cover the whole width: every way to the goal crosses doubtful ground.
ROUGH_STRIP = _slab("rough_strip", _tiles(3.0, 0.0))
# The tiles cover y 0..2.2; a flat lane (y 2.2..3) goes round them.
ROUGH_WITH_LANE = _slab(
    "rough_with_lane",
    _tiles(2.2, 0.0),
    "[[box]]\ncenter = [3.6, 2.6, -0.1]\nsize = [1.2, 0.8, 0.2]\n",
)


def _steps(height: float) -> str:
    """Flat ground with a step of `height` m up at x = 2 across the whole width."""
    return _terrain("steps", [(4.0, -0.1, 8.0, 0.2), (5.0, height / 2, 6.0, height)])


# a 0.06 m crack at x 3.0..3.06, a 0.47 m gap at x 4.03..4.5
CRACKS = _terrain("cracks", [(1.5, -0.1, 3.0, 0.2), (3.53, -0.1, 1.0, 0.2), (6.0, -0.1, 3.0, 0.2)])


@pytest.fixture(scope="module")
def policy():
    from leas_jax.training import load_policy

    return load_policy(SHIPPED)


def _lattice(policy, terrain, **config):
    from leas_jax.env import heightfield_from_terrain

    env = policy.config.env
    field = heightfield_from_terrain(terrain, env)
    return build_lattice(
        field, terrain.bounds, env.nominal_root_height, env.reachability, LatticeConfig(**config)
    )


def _valid_at(lattice, xy, heading: float = 0.0) -> bool:
    i, j = lattice.cell_of(np.asarray(xy))
    return bool(lattice.node_valid[i, j, heading_index(heading)])


def test_rough_tiles_are_doubtful_not_invalid_and_only_offered_when_asked(policy):
    terrain = loads_terrain(ROUGH_STRIP)
    lattice = _lattice(policy, terrain)
    i0, i1 = lattice.cell_of(np.array([[ROUGH_X[0] + 0.1, 0.5], [ROUGH_X[1] - 0.1, 2.5]]))
    strip = lattice.node_valid[i0[0] : i1[0], i0[1] : i1[1], 0]
    doubt = lattice.doubtful[i0[0] : i1[0], i0[1] : i1[1], 0]
    assert strip.mean() > 0.5 and doubt[strip].mean() > 0.5, "the tiles: valid, mostly doubtful"
    (a, b), (c, d) = lattice.cell_of(np.array([[0.5, 0.5], [2.4, 2.5]]))
    assert not lattice.doubtful[a:c, b:d].any(), "the flat slab's inside is confident"
    found = search(lattice, (1.0, 1.5, 0.0), (6.0, 1.5))
    assert found.reached
    confident_only = _lattice(policy, terrain, offer_doubtful=False)
    assert not confident_only.doubtful.any()
    assert not search(confident_only, (1.0, 1.5, 0.0), (6.0, 1.5)).reached


def _doubtful_nodes(lattice, path) -> int:
    """How many nodes of a search path [P, 3] (x, y, yaw) are doubtful."""
    i, j = lattice.cell_of(path[:, :2]).T
    return int(lattice.doubtful[i, j, heading_index(path[:, 2])].sum())


def test_a_confident_detour_is_preferred_to_doubtful_ground(policy):
    lattice = _lattice(policy, loads_terrain(ROUGH_WITH_LANE))
    cheap = search(lattice, (1.0, 1.0, 0.0), (6.0, 1.0), SearchConfig(doubt_penalty=0.0))
    dear = search(lattice, (1.0, 1.0, 0.0), (6.0, 1.0))
    assert cheap.reached and dear.reached
    assert _doubtful_nodes(lattice, cheap.path) > 5, "without the doubt's cost: across the tiles"
    assert _doubtful_nodes(lattice, dear.path) == 0, "with it: round them by the flat lane"
    assert dear.length > cheap.length + 0.5


@pytest.mark.parametrize("height, crosses", [(0.15, True), (0.40, False)])
def test_the_step_model_bounds_a_riser(policy, height, crosses):
    terrain = loads_terrain(_steps(height))
    lattice = _lattice(policy, terrain)
    assert _valid_at(lattice, (1.0, 1.5)) and _valid_at(lattice, (6.0, 1.5)), "both treads"
    found = search(lattice, (1.0, 1.5, 0.0), (6.0, 1.5))
    assert found.reached == crosses
    if not crosses:
        assert found.reason == reasons.NO_PATH and found.path[:, 0].max() < 2.2


def test_a_crack_counts_as_ground_a_gap_and_a_platform_edge_do_not(policy):
    lattice = _lattice(policy, loads_terrain(CRACKS))
    assert _valid_at(lattice, (3.03, 1.5)), "over the 0.06 m crack"
    assert not _valid_at(lattice, (4.25, 1.5)), "over the 0.47 m gap"
    assert not _valid_at(lattice, (4.08, 1.5)) and not _valid_at(lattice, (4.45, 1.5)), "past its edges"
    assert search(lattice, (1.0, 1.5, 0.0), (3.8, 1.5)).reached
    assert not search(lattice, (1.0, 1.5, 0.0), (6.0, 1.5)).reached


def test_astar_finds_dijkstras_cost_and_path_length(policy):
    from scipy.sparse import csgraph

    terrain = load_terrain(ROOT / "terrains" / "eval_hole.toml")
    lattice = _lattice(policy, terrain)
    config = SearchConfig()
    adjacency = graph(lattice, None, config)
    for start, goal in [((2.0, 4.0, 0.0), terrain.scenario.target), ((1.0, 1.0, 1.0), (8.0, 7.0))]:
        found = search(lattice, start, goal, config, adjacency=adjacency)
        source = start_node(lattice, start, config)
        dist = csgraph.dijkstra(adjacency, indices=source)
        best = dist[goal_nodes(lattice, goal, config)].min()
        assert found.reached and found.cost == pytest.approx(best, rel=1e-9, abs=1e-9)


def walks_everything(terrain, guide, timestep, config):
    """A generator that covers every guide."""
    return plan_until(guide, len(guide) - 1)


def refuses_the_tiles(terrain, guide, timestep, config):
    """A generator that stops before the first guide pose on the rough strip."""
    inside = np.flatnonzero((guide[:, 0] > ROUGH_X[0]) & (guide[:, 0] < ROUGH_X[1]))
    return plan_until(guide, len(guide) - 1 if len(inside) == 0 else max(int(inside[0]) - 1, 0))


def _navigate(policy, plan_fn, **config):
    terrain = loads_terrain(ROUGH_STRIP)
    navigator = Navigator(policy, terrain, NavigateConfig(**config))
    query = navigator.query((1.0, 1.5, 0.0), (6.0, 1.5))
    with ValidationPool(terrain, workers=0, plan_fn=plan_fn, return_plans=True) as pool:
        (result,) = navigator.run([query], pool=pool)
    return result


def test_doubtful_ground_is_walked_when_the_generator_walks_it(policy):
    result = _navigate(policy, walks_everything)
    assert result.success and result.reason == reasons.REACHED, result.message
    assert result.replans == 0 and result.guide[:, 0].max() > ROUGH_X[1]


def test_doubtful_ground_is_refused_when_the_generator_does_not(policy):
    result = _navigate(policy, refuses_the_tiles, max_replans=2)
    assert not result.success and result.reason == reasons.REPLAN_LIMIT, result.message
    assert result.replans == 2 and all(a.failure is not None for a in result.attempts)
    assert result.plan.q[:, 0].max() <= ROUGH_X[0], "no verified posture on the tiles"
    assert "after 2 replans" in result.message


def _saved_model(tmp_path, threshold: float, reach=None) -> str:
    import dataclasses
    import json

    import jax

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.env.config import ReachabilityConfig

    reach = ReachabilityConfig() if reach is None else reach
    params = lf.init_params(jax.random.PRNGKey(0), reach=ReachabilityConfig())
    params["threshold"] = jax.numpy.asarray(threshold, jax.numpy.float32)
    path = tmp_path / f"walkability_{threshold}.npz"
    lf.save_params(path, params, reachability=json.dumps(dataclasses.asdict(reach)))
    return str(path)


def test_a_walkability_model_decides_which_plausible_nodes_are_confident(policy, tmp_path):
    terrain = loads_terrain(ROUGH_STRIP)
    plain = _lattice(policy, terrain)
    accept = _lattice(policy, terrain, walkability=_saved_model(tmp_path, -np.inf))
    refuse = _lattice(policy, terrain, walkability=_saved_model(tmp_path, np.inf))
    for lattice in (accept, refuse):
        assert np.array_equal(lattice.node_valid, plain.node_valid), "the plausible set is the model's input"
    assert not accept.doubtful.any()
    assert np.array_equal(refuse.doubtful, refuse.node_valid)


def test_a_walkability_model_of_other_cylinders_is_refused_naming_the_file(policy, tmp_path):
    import dataclasses

    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.errors import UsageError

    other = _saved_model(tmp_path, 0.0, dataclasses.replace(ReachabilityConfig(), trunk_radius=0.4))
    with pytest.raises(UsageError, match="walkability_0.0.npz: the walkability model reads the margins"):
        _lattice(policy, loads_terrain(ROUGH_STRIP), walkability=other)
    with pytest.raises(UsageError, match="missing.npz"):
        _lattice(policy, loads_terrain(ROUGH_STRIP), walkability=str(tmp_path / "missing.npz"))


def test_evaluate_hands_the_walkability_model_to_navigate(tmp_path):
    import subprocess
    import sys

    terrain = tmp_path / "strip.toml"
    scenario = (
        "\n[scenario]\ntarget = [6.0, 1.5]\nstart_region = [[0.8, 1.3], [1.2, 1.7]]\nstart_yaw_deg = [-10.0, 10.0]\n"
        "start_speed = [0.0, 0.0]\nn_starts = 1\nseed = 0\n"
    )
    terrain.write_text(ROUGH_STRIP + scenario)
    run = subprocess.run(
        [sys.executable, "-m", "leas_jax.cli", "evaluate", "--terrain", str(terrain), "--methods", "navigate"]
        + ["--checkpoint", str(SHIPPED), "--workers", "0", "--no-progress", "--out", str(tmp_path / "eval")]
        + ["--navigate-walkability", str(tmp_path / "missing.npz")],
        capture_output=True,
        text=True,
    )
    lines = [line for line in run.stderr.splitlines() if line.strip() and "warp" not in line]
    assert run.returncode == 2 and len(lines) == 1 and "missing.npz" in lines[0], run.stderr
