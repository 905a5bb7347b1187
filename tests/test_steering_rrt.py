"""RBKino+RRT finds a path around a wall; every pose of it passes the reachability condition."""

import numpy as np

from leas_jax.env import EnvConfig, heightfield_from_terrain
from leas_jax.steering.baselines import lift_checked, valid_poses
from leas_jax.steering.rrt import RRTConfig, plan_rrt
from leas_jax.terrain import loads_terrain

# Floor 6 x 4 m with a 1.5 m high wall across x = 3 from y = 0 to y = 2.6: the
# straight line from (1, 1) to (5, 1) hits it; the way round is above y ~ 2.9.
WALL = """name = "wall"
bounds = [[0.0, 0.0], [6.0, 4.0]]
void_height = -2.0
resolution = 0.05
[[box]]
center = [3.0, 2.0, -0.1]
size = [6.0, 4.0, 0.2]
[[box]]
center = [3.0, 1.3, 0.75]
size = [0.2, 2.6, 1.5]
"""


def _terrain_and_field(text: str):
    """A terrain from TOML text and its heightfield with the default EnvConfig."""
    terrain = loads_terrain(text)
    return terrain, heightfield_from_terrain(terrain, EnvConfig())


def test_rrt_goes_around_a_wall_with_every_pose_valid():
    terrain, field = _terrain_and_field(WALL)
    start = np.array([1.0, 1.0, 1.0, 0.0])
    direct, ok = lift_checked(field, np.linspace([1.0, 1.0, 0.0], [5.0, 1.0, 0.0], 50), 1.0)
    assert not ok.all()  # the straight line is blocked
    result = plan_rrt(
        field,
        start,
        [5.0, 1.0],
        0.05,
        terrain.bounds,
        rrt=RRTConfig(seed=0, max_iterations=1500, max_seconds=60.0),
    )
    assert result.success, (result.iterations, result.tree_sizes)
    guide = result.guide
    np.testing.assert_allclose(guide[0, [0, 1, 3]], [1.0, 1.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(guide[-1, :2], [5.0, 1.0], atol=1e-6)
    np.testing.assert_allclose(result.waypoints[-1], [5.0, 1.0])
    assert valid_poses(field, guide).all()
    assert lift_checked(field, guide[:, [0, 1, 3]], 1.0)[1].all()
    # the path crosses x = 3 above the wall's end
    crossing = guide[np.argmin(np.abs(guide[:, 0] - 3.0))]
    assert crossing[1] > 2.6
    # consecutive poses at most v_max * sqrt(2) * dt apart (per-axis bound)
    assert np.hypot(*np.diff(guide[:, :2], axis=0).T).max() <= 0.18 * np.sqrt(2) * 0.1 + 1e-9
    # seeded: the same seed gives the same path
    again = plan_rrt(
        field,
        start,
        [5.0, 1.0],
        0.05,
        terrain.bounds,
        rrt=RRTConfig(seed=0, max_iterations=1500, max_seconds=60.0),
    )
    np.testing.assert_array_equal(again.states, result.states)


# Two 2 x 3 m platforms joined by a 0.30 m beam over the void (x in [2, 4], y in [1.35, 1.65]).
BEAM = """name = "beam"
bounds = [[0.0, 0.0], [6.0, 3.0]]
void_height = -2.0
resolution = 0.02
[[box]]
center = [1.0, 1.5, -0.3]
size = [2.0, 3.0, 0.6]
[[box]]
center = [3.0, 1.5, -0.15]
size = [2.0, 0.3, 0.3]
[[box]]
center = [5.0, 1.5, -0.3]
size = [2.0, 3.0, 0.6]
"""


def test_bridge_test_samples_land_on_the_beam():
    """The bridge test's samples crowd into the narrow passage (a valid place between two invalid
    ones), where uniform valid samples rarely fall. A few land on the platforms' edges, where
    validity depends on the heading."""
    from leas_jax.steering.baselines import BaselineConfig
    from leas_jax.steering.rrt import _bridge_sample, _Problem, _sample

    terrain, field = _terrain_and_field(BEAM)
    env = EnvConfig()
    problem = _Problem(field, BaselineConfig.from_env(env), env.reachability)
    rrt = RRTConfig()
    rng = np.random.default_rng(0)
    lo, hi = np.array([0.3, 0.3]), np.array([5.7, 2.7])

    def on_beam(states):
        return (states[:, 0] > 2.0) & (states[:, 0] < 4.0) & (np.abs(states[:, 1] - 1.5) < 0.15)

    samples = [s for s in (_bridge_sample(rng, lo, hi, rrt, problem) for _ in range(200)) if s is not None]
    assert len(samples) >= 30
    samples = np.array(samples)
    assert on_beam(samples).mean() >= 0.75, samples[:, :2]
    assert np.all(np.hypot(samples[:, 2], samples[:, 3]) <= rrt.sample_speed + 1e-12)
    assert all(problem.valid_state(s) for s in samples)
    bounds = terrain.bounds
    uniform = np.array([_sample(rng, bounds, RRTConfig(bridge_fraction=0.0), problem) for _ in range(200)])
    assert on_beam(uniform).mean() <= 0.15


def test_rrt_crosses_a_narrow_beam_with_every_pose_valid():
    terrain, field = _terrain_and_field(BEAM)
    result = plan_rrt(
        field,
        np.array([1.0, 0.8, 1.0, 0.0]),
        [5.0, 2.2],
        0.05,
        terrain.bounds,
        rrt=RRTConfig(seed=0, max_iterations=3000, max_seconds=120.0),
    )
    assert result.success, (result.iterations, result.tree_sizes)
    assert valid_poses(field, result.guide).all()
    over_void = result.guide[(result.guide[:, 0] > 2.0) & (result.guide[:, 0] < 4.0)]
    assert len(over_void) and np.all(np.abs(over_void[:, 1] - 1.5) < 0.15)
