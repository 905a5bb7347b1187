"""Navigate: the lattice search (eval_bridge's beam, eval_hole's detour) and the closed loop
(replanning after an injected generator failure or a stalled rollout, unreachable goals,
determinism).

The closed-loop tests inject `plan_fn` (the pool's test hook): a generator stand-in that
stops every guide where it enters a blocked disk, so they run in seconds and fail where the
loop does, not where the real generator does (tests/test_navigate_cli.py runs the real one).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from navigate_helpers import plan_until

from leas_jax.contacts.validation.pool import ValidationPool
from leas_jax.navigate import result as reasons
from leas_jax.navigate.lattice import build_lattice, heading_index
from leas_jax.navigate.loop import NavigateConfig, Navigator, path_guide, stall_start
from leas_jax.navigate.search import search
from leas_jax.terrain import load_terrain, loads_terrain

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "checkpoints" / "leas_talos"
WALL = ROOT / "tests" / "data" / "slab_with_wall.toml"
BLOCK = np.array([3.0, 2.0])  # the stand-in generator fails where a guide comes this close...
BLOCK_RADIUS = 0.3  # ... m

# Two 3 x 4 m platforms 1 m apart over the void: nothing crosses.
VOID = """
name = "void_gap"
bounds = [[0.0, 0.0], [7.0, 4.0]]
void_height = -2.0
resolution = 0.02
[[box]]
center = [1.5, 2.0, -0.3]
size = [3.0, 4.0, 0.6]
[[box]]
center = [5.5, 2.0, -0.3]
size = [3.0, 4.0, 0.6]
"""

# A 6 x 4 m slab.
SLAB = """
name = "slab"
bounds = [[0.0, 0.0], [6.0, 4.0]]
void_height = -2.0
resolution = 0.02
[[box]]
center = [3.0, 2.0, -0.3]
size = [6.0, 4.0, 0.6]
"""


def blocked_plan(terrain, guide, timestep, config):
    """Covers a guide up to the pose before it enters the disk BLOCK_RADIUS around BLOCK."""
    inside = np.flatnonzero(np.hypot(*(guide[:, :2] - BLOCK).T) < BLOCK_RADIUS)
    return plan_until(guide, len(guide) - 1 if len(inside) == 0 else max(int(inside[0]) - 1, 0))


@pytest.fixture(scope="module")
def policy():
    from leas_jax.training import load_policy

    return load_policy(SHIPPED)


def _lattice(policy, terrain):
    from leas_jax.env import heightfield_from_terrain

    env = policy.config.env
    field = heightfield_from_terrain(terrain, env)
    return build_lattice(field, terrain.bounds, env.nominal_root_height, env.reachability)


def _over_void(terrain, xy) -> np.ndarray:
    return terrain.height_at(xy) <= terrain.void_height + 1e-3


def test_search_crosses_the_bridge_on_eval_bridge(policy):
    terrain = load_terrain(ROOT / "terrains" / "eval_bridge.toml")
    lattice = _lattice(policy, terrain)
    found = search(lattice, (2.0, 2.0, 0.0), terrain.scenario.target)
    assert found.reached and found.reason is None and found.end_distance <= 0.15 + 1e-9
    xy = found.path[:, :2]
    over = (xy[:, 0] > 4.05) & (xy[:, 0] < 6.95)  # the void under the beam spans x 4..7
    assert over.sum() > 40, "the path crosses the gap"
    assert np.all(np.abs(xy[over, 1] - 5.0) <= 0.1), "on the beam's valid strip (y 4.9..5.1)"
    assert not _over_void(terrain, xy).any()
    i, j = lattice.cell_of(xy).T
    assert lattice.node_valid[i, j, heading_index(found.path[:, 2])].all()


def test_search_goes_round_the_hole_on_eval_hole(policy):
    terrain = load_terrain(ROOT / "terrains" / "eval_hole.toml")
    lattice = _lattice(policy, terrain)
    found = search(lattice, (2.0, 4.0, 0.0), terrain.scenario.target)
    assert found.reached
    xy = found.path[:, :2]
    assert not _over_void(terrain, xy).any()
    # the straight line crosses the 3 m hole (x 4..6, y 2.5..5.5); the path passes beside it
    assert found.length > 6.5 + 0.5
    beside = (xy[:, 0] > 4.0) & (xy[:, 0] < 6.0)
    assert np.all((xy[beside, 1] < 2.5) | (xy[beside, 1] > 5.5))
    # waypoints every 0.5 m of the path, its end last
    gaps = np.hypot(*np.diff(found.waypoints, axis=0).T)
    assert np.all(gaps <= 0.5 + 1e-9 + lattice.resolution * 2.3)
    assert np.allclose(found.waypoints[-1], xy[-1])


def test_search_reports_a_goal_over_the_void_and_one_no_path_reaches(policy):
    void = _lattice(policy, loads_terrain(VOID))
    found = search(void, (1.5, 2.0, 0.0), (3.5, 2.0))  # in the gap
    assert not found.reached and found.reason == reasons.GOAL_INVALID
    assert found.path[-1, 0] <= 3.0 + 1e-9 and 0.4 < found.end_distance < 1.0  # the best: the edge
    found = search(void, (1.5, 2.0, 0.0), (5.5, 2.0))  # on the far platform
    assert not found.reached and found.reason == reasons.NO_PATH
    assert found.path[-1, 0] <= 3.0 + 1e-9 and found.end_distance >= 2.5 - 1e-9
    # on the 1.5 m wall's top (a valid root pose on a heightfield): nothing climbs there
    found = search(_lattice(policy, load_terrain(WALL)), (1.5, 3.0, 0.0), (4.5, 3.0))
    assert not found.reached and found.reason == reasons.NO_PATH
    assert 0.4 < found.end_distance < 1.2  # the best partial path ends at the wall


def _run(policy, terrain, queries, workers=0, **config):
    navigator = Navigator(policy, terrain, NavigateConfig(**config))
    checked = [navigator.query(*q) for q in queries]
    with ValidationPool(terrain, workers=workers, plan_fn=blocked_plan, return_plans=True) as pool:
        return navigator.run(checked, pool=pool)


def test_replans_around_an_injected_generator_failure(policy):
    (result,) = _run(policy, loads_terrain(SLAB), [((1.0, 2.0, 0.0), (5.0, 2.0))])
    assert result.success and result.reason == reasons.REACHED, result.message
    assert result.replans >= 1 and sum(a.kind == "policy" for a in result.attempts) == result.replans + 1
    first = result.attempts[0]
    assert first.last_valid_index < first.guide_length - 1
    assert np.hypot(*(np.array(first.failure) - BLOCK)) < BLOCK_RADIUS + 0.2
    assert np.min(np.hypot(*(result.guide[:, :2] - BLOCK).T)) >= BLOCK_RADIUS
    assert result.attempts[-1].begin > 0  # the last attempt grew a verified prefix
    assert set(result.seconds) >= {"lattice", "search", "rollout", "contact_planning"}


def test_stall_start_finds_where_a_guide_marks_time():
    """The first pose of a guide's tail that stays within the radius of it, when that tail is long
    enough; None for a guide that moves on to its end or stalls too briefly."""
    walk = np.stack([np.linspace(0.0, 1.0, 51), np.zeros(51), np.ones(51), np.zeros(51)], axis=1)
    jitter = 0.05 * np.sin(np.arange(1, 61))[:, None] * np.array([1.0, 1.0, 0.0, 0.0])
    stalled = np.concatenate([walk, walk[-1] + jitter])  # 60 poses within 0.071 m of pose 50
    # the earliest pose whose later ones all lie within 0.25 m of it: up to 0.25 m before pose 50
    assert stall_start(stalled, steps=50, radius=0.25) in range(37, 51)
    assert stall_start(stalled, steps=50, radius=0.05) is None  # the jitter leaves a 0.05 m disk
    assert stall_start(stalled[:80], steps=50, radius=0.25) is None  # 30 poses: too brief
    assert stall_start(walk, steps=5, radius=0.01) is None


def test_a_stalled_rollout_is_cut_and_searched_round(policy, monkeypatch):
    """A rollout that marks time at x = 3 for its last 10 s (LeaS before ground it does not take)
    is cut there, the generator (covering everything here) plans only the walked part, and the
    stall is penalised and searched round like a generator failure: the next rollout reaches."""
    real = Navigator._rollout
    calls = []

    def stalls_first(self, poses, speeds, waypoints):
        guides = real(self, poses, speeds, waypoints)
        if not calls:
            guide = guides[0]
            at = int(np.flatnonzero(guide[:, 0] >= 3.0)[0])
            guides = [np.concatenate([guide[: at + 1], np.repeat(guide[at : at + 1], 100, axis=0)])]
        calls.append(len(guides[0]))
        return guides

    monkeypatch.setattr(Navigator, "_rollout", stalls_first)
    lines = []
    navigator = Navigator(policy, loads_terrain(SLAB), NavigateConfig(), progress=lines.append)
    full = lambda terrain, guide, timestep, config: plan_until(guide, len(guide) - 1)  # noqa: E731
    with ValidationPool(navigator.terrain, workers=0, plan_fn=full, return_plans=True) as pool:
        (result,) = navigator.run([navigator.query((1.0, 2.0, 0.0), (5.0, 2.0))], pool=pool)
    assert result.success, result.message
    first = result.attempts[0]
    assert first.guide_length < calls[0] - 90  # the stalled poses were not planned
    assert first.failure is not None and np.hypot(first.failure[0] - 3.0, first.failure[1] - 2.0) < 0.3
    assert any("the policy stalls at" in line and "cut there" in line for line in lines)
    assert result.replans >= 1


def test_without_replans_the_injected_failure_ends_the_query(policy):
    (result,) = _run(
        policy, loads_terrain(SLAB), [((1.0, 2.0, 0.0), (5.0, 2.0))], max_replans=0, path_fallback=False
    )
    assert not result.success and result.reason == reasons.REPLAN_LIMIT
    assert result.replans == 0 and "after 0 replans" in result.message
    assert result.plan is not None and result.final_distance > 1.5
    # with the searched path tried once more (not counted as a replan): it meets the block too
    (result,) = _run(policy, loads_terrain(SLAB), [((1.0, 2.0, 0.0), (5.0, 2.0))], max_replans=0)
    assert not result.success and "after 0 replans" in result.message
    assert [a.kind for a in result.attempts] == ["policy", "path"]
    assert result.attempts[1].failure is not None and result.final_distance > 1.5


def test_path_guide_walks_the_searched_path_at_the_speed():
    """From the pose (its x, y, yaw first) through the path's later nodes, a pose every
    speed x timestep metres of arc, the path's end last; the yaw turns the short way across +-pi."""
    pose = np.array([0.0, 0.0, 1.0, 3.1])
    path = np.array([[0.01, 0.0, 3.1], [0.5, 0.0, -3.1], [1.0, 0.0, -3.0]])
    guide = path_guide(pose, path, speed=0.1, timestep=0.1)
    np.testing.assert_allclose(guide[0], pose[[0, 1, 3]])
    np.testing.assert_allclose(guide[-1, :2], path[-1, :2])
    steps = np.hypot(*np.diff(guide[:, :2], axis=0).T)
    np.testing.assert_allclose(steps[:-1], 0.01, atol=1e-12)
    assert 0.0 < steps[-1] <= 0.01 + 1e-12
    assert np.all(np.diff(guide[:, 2]) >= 0.0) and guide[-1, 2] == pytest.approx(2 * np.pi - 3.0)


def test_where_the_policy_wavers_the_searched_path_is_walked(policy, monkeypatch):
    """A stand-in generator that stops a guide where it strays 0.1 m from the line y = 2 (a beam)
    and a policy that drifts off it: the searched path along y = 2 is walked next from the
    verified pose before the failure, unpenalised, and reaches; LeaS alone never would."""
    real = Navigator._rollout

    def wavers(self, poses, speeds, waypoints):  # drifts off y = 2 past x = 2
        guides = real(self, poses, speeds, waypoints)
        return [
            g + np.c_[0 * g[:, :1], 0.3 * np.clip(g[:, :1] - 2.0, 0.0, None), 0 * g[:, 2:]] for g in guides
        ]

    def beam(terrain, guide, timestep, config):
        off = np.flatnonzero(np.abs(guide[:, 1] - 2.0) > 0.1)
        return plan_until(guide, len(guide) - 1 if len(off) == 0 else max(int(off[0]) - 1, 0))

    monkeypatch.setattr(Navigator, "_rollout", wavers)
    answers = {}
    for fallback in (False, True):
        navigator = Navigator(
            policy, loads_terrain(SLAB), NavigateConfig(max_replans=1, path_fallback=fallback)
        )
        with ValidationPool(navigator.terrain, workers=0, plan_fn=beam, return_plans=True) as pool:
            (answers[fallback],) = navigator.run([navigator.query((1.0, 2.0, 0.0), (5.0, 2.0))], pool=pool)
    assert not answers[False].success and answers[False].reason == reasons.REPLAN_LIMIT
    result = answers[True]
    assert result.success, result.message
    assert [a.kind for a in result.attempts] == ["policy", "path"]
    assert result.attempts[1].begin > 0 and np.abs(result.guide[:, 1] - 2.0).max() <= 0.1


def test_unreachable_goals_end_with_the_partial_plan_and_the_reason(policy):
    gap, far = _run(
        policy, loads_terrain(VOID), [((1.5, 2.0, 0.0), (3.5, 2.0)), ((1.5, 2.0, 0.0), (5.5, 2.0))]
    )
    assert not gap.success and gap.reason == reasons.GOAL_INVALID
    assert "cannot be reached" in gap.message and "over the void" in gap.message
    assert gap.plan is not None and 0.3 < gap.final_distance < 1.2 and gap.guide[:, 0].max() < 3.0
    assert not far.success and far.reason == reasons.NO_PATH
    assert "no lattice path" in far.message and f"{far.final_distance:.2f} m" in far.message
    assert far.plan is not None and far.guide[:, 0].max() < 3.0
    (wall,) = _run(policy, load_terrain(WALL), [((1.5, 3.0, 0.0), (4.5, 3.0))])
    assert not wall.success and wall.reason == reasons.NO_PATH
    assert wall.plan is not None and 0.3 < wall.final_distance < 1.5


def test_a_start_in_collision_is_rejected_naming_it(policy):
    from leas_jax.errors import UsageError

    navigator = Navigator(policy, load_terrain(WALL))
    with pytest.raises(
        UsageError, match=r"--start: the start \(4\.15, 3\.00, 0\.00\) is in collision.*trunk_free"
    ):
        navigator.query((4.15, 3.0, 0.0), (1.0, 1.0))
    with pytest.raises(UsageError, match=r"--goal: \(9\.00, 1\.00\) lies off the terrain"):
        navigator.query((1.0, 1.0, 0.0), (9.0, 1.0))


def test_same_answers_in_process_and_with_1_and_2_workers(policy):
    terrain = loads_terrain(SLAB)
    queries = [((1.0, 2.0, 0.0), (5.0, 2.0)), ((1.0, 1.0, 0.5), (5.0, 3.0)), ((5.0, 3.0, 3.0), (1.0, 2.0))]
    inline = _run(policy, terrain, queries)  # each run builds its own Navigator and pool
    one = _run(policy, terrain, queries, workers=1)
    two = _run(policy, terrain, queries, workers=2)
    for a, b, c in zip(inline, one, two):
        for other in (b, c):
            assert other.reason == a.reason and other.replans == a.replans
            np.testing.assert_array_equal(other.guide, a.guide)
            np.testing.assert_array_equal(other.plan.q, a.plan.q)
            np.testing.assert_array_equal(other.waypoints, a.waypoints)


def test_any_policy_checkpoint_navigates(run_dir):
    """A quick policy (a few PPO steps) walks badly, but the loop answers with a reason."""
    from leas_jax.training import load_policy

    (result,) = _run(
        load_policy(run_dir), loads_terrain(SLAB), [((1.0, 1.0, 0.0), (5.0, 1.0))], max_replans=1
    )
    assert result.reason in (reasons.REACHED, reasons.REPLAN_LIMIT)
    assert result.replans <= 1 and result.plan is not None
