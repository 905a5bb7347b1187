"""Static equilibrium: hpp-centroidal-dynamics LP vs our SciPy LP, and hand-computed cases."""

from pathlib import Path

import numpy as np
import pytest

from leas_jax.contacts.robot import equilibrium as E
from leas_jax.contacts.robot.model import quat_xyzw_from_matrix, rotz

MASS = 90.27  # kg, Talos (computeTotalMass of the example-robot-data model)
# Sole placements [42, 2, 7] (NaN rows in the air) and CoMs [42, 3] of the postures of
# `leas navigate --checkpoint checkpoints/leas_talos --terrain
# terrains/hpp/demos/talos_stairs15.toml --start=-1.9,1.9,-90 --degrees --goal=-1.9,0.9`.
# qpOASES solves the double-support stances 6 and 7 hot-started from another double
# support but not from a cold start (a new object, or after the single-support 5).
STAIRS15 = Path(__file__).parent / "data" / "talos_stairs15_stances.npz"


def _foot(x, y, z, rot=None):
    rot = np.eye(3) if rot is None else rot
    return np.concatenate([[x, y, z], quat_xyzw_from_matrix(rot)])


def _pitch(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


STANCES = {
    # both feet flat, 0.17 m apart
    "double": np.array([_foot(0, 0.085, 0), _foot(0, -0.085, 0)]),
    # one foot (the other in the air: NaN row)
    "single": np.array([_foot(0.1, 0.085, 0), np.full(7, np.nan)]),
    # stairs: feet on treads 0.15 m apart in height
    "stairs": np.array([_foot(0, 0.085, 0), _foot(0.3, -0.085, 0.15)]),
    # a foot on a 0.3 rad slope, the other turned
    "slope": np.array([_foot(0, 0.085, 0, _pitch(0.3)), _foot(0.2, -0.085, 0.1, rotz(0.4))]),
}
COMS = [
    [0.0, 0.0, 0.87],
    [0.1, 0.05, 0.9],
    [0.15, -0.05, 1.0],
    [0.3, 0.0, 0.9],
    [-0.1, 0.1, 1.0],
    [0.12, 0.1, 0.85],
    [0.0, 0.2, 0.87],
]


@pytest.fixture(scope="module")
def hpp():
    return E.HppEquilibrium(MASS)


@pytest.mark.parametrize("name", sorted(STANCES))
def test_parity_with_hpp_centroidal_dynamics(hpp, name):
    """Same robustness (same LP definition) within 1e-5 relative, and so the same sign."""
    points, normals = E.sole_corners(STANCES[name])
    signs = set()
    for com in COMS:
        ours = E.static_equilibrium_lp(points, normals, np.array(com), MASS)
        theirs = hpp.feet_robustness(STANCES[name], np.array(com))
        assert ours == pytest.approx(theirs, rel=1e-5, abs=1e-5), (name, com)
        signs.add(theirs >= 0)
    assert signs == {True, False}  # each stance has CoMs inside and outside


def test_plan_stances_match_scipy_in_any_order():
    """Each stance of a plan has SciPy's robustness, on one object in plan order (single
    and double support alternating) and on a fresh object per stance."""
    data = np.load(STAIRS15)
    reused = E.HppEquilibrium(MASS)
    for k, (feet, com) in enumerate(zip(data["feet"], data["com"])):
        points, normals = E.sole_corners(feet)
        expected = E.static_equilibrium_lp(points, normals, com, MASS)
        assert reused.feet_robustness(feet, com) == pytest.approx(expected, rel=1e-5), k
        assert E.HppEquilibrium(MASS).feet_robustness(feet, com) == pytest.approx(expected, rel=1e-5), k


def test_hand_computed_double_support():
    """Two flat 0.20 x 0.13 soles centred at y = +-0.085: the support polygon spans
    y in [-0.15, 0.15], x in [-0.1, 0.1]. A CoM at y = 0.14 is 1 cm inside (balanced),
    at y = 0.16 1 cm outside (not); by symmetry their robustness is opposite."""
    points, normals = E.sole_corners(STANCES["double"])
    inside = E.static_equilibrium_lp(points, normals, np.array([0.0, 0.14, 0.87]), MASS)
    outside = E.static_equilibrium_lp(points, normals, np.array([0.0, 0.16, 0.87]), MASS)
    assert inside > 0 > outside
    assert inside == pytest.approx(-outside, rel=1e-6)
    # Flat-ground shortcut: distances to the polygon edges, 0.15 - 0.14 = 0.01 m.
    assert E.flat_support_margin(points, normals, np.array([0.0, 0.14, 0.87])) == pytest.approx(0.01)
    assert E.flat_support_margin(points, normals, np.array([0.0, 0.16, 0.87])) == pytest.approx(-0.01)
    # Not defined (-inf) as soon as a normal is tilted.
    slope_points, slope_normals = E.sole_corners(STANCES["slope"])
    assert E.flat_support_margin(slope_points, slope_normals, np.zeros(3)) == -np.inf


def test_robustness_scale_hand_computed():
    """4 unit edges (n + mu t)/sqrt(1 + mu^2): f0 = 4 n / sqrt(1 + mu^2), |f0 x g0| =
    4 mu / (1 + mu^2) = 4 * 0.5 / 1.25 = 1.6."""
    assert E.robustness_scale(0.5, 4) == pytest.approx(1.6)


def test_sole_corners():
    points, normals = E.sole_corners(STANCES["single"])
    assert points.shape == (4, 3) and normals.shape == (4, 3)
    np.testing.assert_allclose(np.sort(points[:, 0]), [0.0, 0.0, 0.2, 0.2])
    np.testing.assert_allclose(np.sort(points[:, 1]), [0.02, 0.02, 0.15, 0.15])
    np.testing.assert_allclose(normals, np.tile([0, 0, 1.0], (4, 1)))


def test_no_contact_is_not_balanced(hpp):
    assert hpp.feet_robustness(np.full((2, 7), np.nan), np.zeros(3)) == -np.inf
    with pytest.raises(RuntimeError, match="set_contacts"):
        E.HppEquilibrium(MASS).robustness(np.zeros(3))


def test_missing_library_message(monkeypatch):
    monkeypatch.setattr(
        E.sysconfig, "get_paths", lambda: {"purelib": "/nonexistent", "platlib": "/nonexistent"}
    )
    monkeypatch.setattr(E.site, "getsitepackages", lambda: [])
    monkeypatch.setattr(E.site, "getusersitepackages", lambda: "/nonexistent-user")
    with pytest.raises(ImportError, match="libhpp-centroidal-dynamics.so"):
        E._cmeel_lib_dir()


def test_an_accelerating_com_keeps_the_clp_retry_and_rest_is_zero_acceleration():
    """The stairs15 stances that qpOASES fails cold are solved with a CoM acceleration too (the
    motion checks' call), and a zero acceleration gives the robustness at rest."""
    data = np.load(STAIRS15)
    solver = E.HppEquilibrium(MASS)
    for feet, com in zip(data["feet"], data["com"]):
        points, normals = E.sole_corners(feet)
        solver.set_contacts(points, normals)
        at_rest = solver.robustness(com)
        assert np.isfinite(at_rest)
        assert solver.robustness(com, np.zeros(3)) == pytest.approx(at_rest, rel=1e-6)
        assert solver.robustness(com, np.array([30.0, 30.0, 0.0])) < at_rest  # pushed sideways: less margin
