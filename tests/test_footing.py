"""Footing: the share of ground around a footstep place where a sole stands in static
equilibrium (`field.footing_rasters`), and the walkability model's features that read it."""

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from leas_jax.contacts.robot.equilibrium import GENERATORS_PER_CONTACT, friction_generators
from leas_jax.contacts.robot.model import FRICTION
from leas_jax.env import EnvConfig, LeasEnv, heightfield_from_terrain
from leas_jax.env import learned_feasibility as lf
from leas_jax.env.field import FOOTING_SLOPE, footing_rasters
from leas_jax.feasibility.fit import FitConfig, fit, mirrored
from leas_jax.terrain import loads_terrain
from leas_jax.training.config import TRAINING_ENV

RES = 0.02
X, Y = np.meshgrid(np.arange(200) * RES, np.arange(150) * RES, indexing="ij")  # 4 x 3 m
CENTRE = (100, 75)


def _plane(degrees: float, direction_degrees: float = 0.0) -> np.ndarray:
    a = math.radians(direction_degrees)
    return math.tan(math.radians(degrees)) * (math.cos(a) * X + math.sin(a) * Y)


def test_the_slope_limit_is_the_generators_friction_pyramid():
    """Along world x (and y) the generator's pyramid holds a tangential load up to this share of
    the normal one: the half-width of the pyramid's section at unit normal load."""
    edges = friction_generators(np.array([[0.0, 0.0, 1.0]]), FRICTION, GENERATORS_PER_CONTACT)[0]
    section = edges[:, :2] / edges[:, 2:]  # [4, 2] the pyramid's corners at unit normal load
    assert FOOTING_SLOPE == pytest.approx(np.abs(section[:, 0]).max(), rel=1e-9)
    assert FOOTING_SLOPE == pytest.approx(np.abs(section[:, 1]).max(), rel=1e-9)


@pytest.mark.parametrize(
    ("degrees", "direction", "footing"),
    [
        (0.0, 0.0, 1.0),
        (15.0, 0.0, 1.0),
        (19.0, 0.0, 1.0),
        (20.0, 0.0, 0.0),
        (20.0, 90.0, 0.0),
        (25.0, 45.0, 1.0),
    ],
)
def test_planes_within_the_limit_are_footing(degrees, direction, footing):
    """Along x or y the limit is 19.5 deg; the pyramid reaches farther along the diagonals
    (a 25 deg plane falling along x + y holds a sole)."""
    shares = footing_rasters(_plane(degrees, direction), -2.0, RES)
    assert shares.shape == (2, *X.shape) and shares.dtype == np.float32
    assert shares[0][CENTRE] == pytest.approx(footing, abs=1e-6)
    assert shares[1][CENTRE] == pytest.approx(1.0)


def test_steps_edges_and_the_void_are_not_footing():
    """A 0.10 m step is no footing within the sole square of its edge, and the void is neither
    footing nor solid: shares fall towards a step and over a hole, and are zero beyond the grid."""
    step = np.where(X >= 2.0, 0.10, 0.0)
    shares = footing_rasters(step, -2.0, RES)
    assert shares[0][CENTRE] < 0.5 and shares[0][60, 75] == pytest.approx(1.0)
    assert shares[1][CENTRE] == pytest.approx(1.0)  # still solid
    hole = np.where(X >= 2.0, -2.0, 0.0)  # the void from x = 2 m
    shares = footing_rasters(hole, -2.0, RES)
    assert 0.3 < shares[1][CENTRE] < 0.7 and shares[0][CENTRE] < shares[1][CENTRE]
    assert shares[0][150, 75] == 0.0 and shares[1][150, 75] == 0.0
    assert shares[1][0, 75] < 1.0  # the grid's border: nothing beyond it


def _blocks(tilt_degrees: float) -> str:
    """Flat ground, then 0.4 x 0.2 m blocks pitched alternately by the tilt (x 2.0-3.6 m)."""
    boxes = ["[[box]]\ncenter = [1.0, 1.5, -0.1]\nsize = [2.0, 3.0, 0.2]\n"]
    for k, x in enumerate(np.arange(2.2, 3.6, 0.4)):
        for m, y in enumerate(np.arange(0.1, 3.0, 0.2)):
            pitch = math.radians(tilt_degrees) * (1 if (k + m // 2) % 2 == 0 else -1)
            boxes.append(
                f"[[box]]\ncenter = [{x:.3f}, {y:.3f}, 0.1]\nsize = [0.4, 0.2, 0.2]\nrpy = [0, {pitch:.5f}, 0]\n"
            )
    head = 'name = "blocks"\nbounds = [[0.0, 0.0], [4.0, 3.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
    return head + "\n".join(boxes)


def test_the_model_reads_footing_at_the_guides_footstep_places():
    """With footing places, the features end with the footing shares then the solid shares at
    each place (left leg's line, then the right's); the mirror index maps them onto the mirror
    image's; on blocks beyond the friction limit the shares ahead are low where flat ground
    behind keeps them whole."""
    reach = EnvConfig().reachability
    places = lf.footing_points(reach)
    assert places.shape == (6, 2)
    np.testing.assert_allclose(places[:3, 0], lf.FOOTING_X)
    np.testing.assert_allclose(places[3:], places[:3] * np.array([1.0, -1.0]))
    params = lf.init_params(jax.random.PRNGKey(0), reach=reach, footing=places)
    plain = lf.init_params(jax.random.PRNGKey(0), reach=reach)
    extra = params["mean"].shape[0] - plain["mean"].shape[0]
    assert extra == 12 and params["w0"].shape[0] == lf.feature_count(params["grid"], reach, places)
    steep = heightfield_from_terrain(loads_terrain(_blocks(24.0)), EnvConfig())
    gentle = heightfield_from_terrain(loads_terrain(_blocks(12.0)), EnvConfig())
    pose = jnp.array([1.80, 1.3, 1.1, 0.0])  # on the flat ground, its guide onto the blocks
    on_steep = np.asarray(lf.features(params, steep, pose, reach))[-12:]
    on_gentle = np.asarray(lf.features(params, gentle, pose, reach))[-12:]
    np.testing.assert_allclose(
        np.asarray(lf.features(plain, steep, pose, reach)),
        np.asarray(lf.features(params, steep, pose, reach))[:-12],
    )
    footing, solid = on_steep[:6], on_steep[6:]
    np.testing.assert_allclose(solid, 1.0, atol=1e-6)
    assert footing[0] > 0.5 and footing[3] > 0.5  # the flat ground
    assert np.all(footing[[1, 2, 4, 5]] < 0.1)  # the steep blocks ahead
    assert on_gentle[2] > 0.5 and on_gentle[5] > 0.5
    index = lf.feature_mirror_index(np.asarray(params["grid"]), reach, places)
    np.testing.assert_array_equal(index[index], np.arange(len(index)))
    x = np.asarray(lf.features(params, steep, pose, reach))[None]
    swapped = mirrored(x, np.asarray(params["grid"]), reach, places)[0, -12:]
    np.testing.assert_array_equal(
        swapped, np.concatenate([on_steep[3:6], on_steep[:3], on_steep[9:], on_steep[6:9]])
    )


def test_footing_weights_round_trip_and_drive_the_env(tmp_path):
    """Weights with footing places keep them through the file, and the env's `walkability`
    condition runs on them: a model whose threshold refuses every pose ends the first step, one
    whose threshold accepts every pose does not."""
    reach = TRAINING_ENV.reachability
    places = lf.footing_points(reach)
    params = lf.init_params(jax.random.PRNGKey(1), hidden=(8, 4), reach=reach, footing=places)
    path = lf.save_params(tmp_path / "w.npz", params)
    loaded, _ = lf.load_params(path)
    np.testing.assert_array_equal(np.asarray(loaded["footing"]), places)
    flat = loads_terrain(
        'name = "flat"\nbounds = [[0.0, 0.0], [6.0, 6.0]]\nvoid_height = -2.0\nresolution = 0.02\n'
        "[[box]]\ncenter = [3.0, 3.0, -0.1]\nsize = [6.0, 6.0, 0.2]\n"
    )
    for threshold, done in ((1e9, 1.0), (-1e9, 0.0)):
        weights = lf.save_params(
            tmp_path / f"t{threshold:g}.npz", {**params, "threshold": jnp.asarray(threshold)}
        )
        config = dataclasses.replace(TRAINING_ENV, condition="walkability", learned_weights=str(weights))
        field = heightfield_from_terrain(flat, config)
        env = LeasEnv(field, config)
        state = jax.jit(env.reset)(jax.random.PRNGKey(0))
        assert float(jax.jit(env.step)(state, jnp.zeros(4)).done) == done


def test_a_fit_with_footing_learns_a_footing_rule():
    """Synthetic labels that depend on the footing share ahead alone (blocks steeper than the
    limit or not, flat ground behind): the fit with footing places learns them."""
    reach = EnvConfig().reachability
    places = lf.footing_points(reach)
    template = lf.init_params(jax.random.PRNGKey(0), reach=reach, footing=places)
    rng = np.random.default_rng(0)
    xs, ys = [], []
    for tilt in (8.0, 12.0, 16.0, 22.0, 24.0, 27.0):
        field = heightfield_from_terrain(loads_terrain(_blocks(tilt)), EnvConfig())
        poses = np.column_stack(
            [
                rng.uniform(2.3, 3.3, 80),
                rng.uniform(0.5, 2.5, 80),
                np.full(80, 1.2),
                rng.uniform(-0.3, 0.3, 80),
            ]
        )
        xs.append(
            np.asarray(
                jax.vmap(lambda p, f=field: lf.features(template, f, p, reach))(
                    jnp.asarray(poses, jnp.float32)
                )
            )
        )
        ys.append(np.full(80, tilt < 19.5))
    x, y = np.concatenate(xs), np.concatenate(ys)
    params, _ = fit(
        x, y, FitConfig(hidden=(16, 8), steps=300, learning_rate=1e-2), reach=reach, footing=places
    )
    assert "footing" in params
    verdicts = np.asarray(lf.logit_of_features(params, jnp.asarray(x)) >= params["threshold"])
    assert (verdicts == y).mean() >= 0.95
