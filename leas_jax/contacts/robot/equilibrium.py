"""Static equilibrium of a stance: hpp-centroidal-dynamics robustness LP and our own LP.

Host-only, not jittable. docs/design.md §6 check 4: the stance is in static equilibrium with
robustness >= 0 by the linear program of hpp-centroidal-dynamics over the sole
corners (mu = 0.5). `sole_corners` gives those contact points; `HppEquilibrium` wraps
the library; `static_equilibrium_lp` is an independent formulation with SciPy's
`linprog` used to cross-check it (tests/test_contacts_equilibrium.py).
qpOASES solves the library's LPs, CLP those qpOASES fails on (`HppEquilibrium`).

The library's Python module does not find its shared libraries by itself (they live
in the cmeel prefix, which is not on the loader path), so `_import_hpp_centroidal_dynamics`
loads them with RTLD_GLOBAL before importing it.
"""

from __future__ import annotations

import ctypes
import functools
import os
import site
import sysconfig

import numpy as np

from leas_jax.contacts.robot.model import FRICTION, SOLE_LENGTH, SOLE_WIDTH

GRAVITY = 9.81  # m/s^2, hpp-centroidal-dynamics' value (Equilibrium uses g = -9.81 e_z)
# Friction-cone generators per contact point: hpp-centroidal-dynamics' usual choice
# (its tests and the RB-PRM Talos scripts use 4), an inscribed pyramid of the cone.
GENERATORS_PER_CONTACT = 4
# Shared libraries of hpp-centroidal-dynamics and its dependencies, in load order.
_HPP_LIBRARIES = (
    "libeigenpy.so",
    "libcdd.so.0",
    "libCoinUtils.so.3",
    "libClp.so.1",
    "libqpOASES.so.3.2",
    "libhpp-centroidal-dynamics.so",
)


def _cmeel_lib_dir() -> str:
    """The `cmeel.prefix/lib` folder holding hpp-centroidal-dynamics' shared libraries.

    Raises:
        ImportError: no site-packages folder has it.
    """
    candidates = [sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]]
    candidates += site.getsitepackages() if hasattr(site, "getsitepackages") else []
    candidates.append(site.getusersitepackages())
    seen = []
    for base in candidates:
        path = os.path.join(base, "cmeel.prefix", "lib")
        seen.append(path)
        if os.path.isfile(os.path.join(path, "libhpp-centroidal-dynamics.so")):
            return path
    raise ImportError(
        "hpp-centroidal-dynamics shared library not found; looked for "
        "libhpp-centroidal-dynamics.so in: "
        + ", ".join(dict.fromkeys(seen))
        + " (install the pinned `hpp-centroidal-dynamics` wheel: make venv)"
    )


@functools.lru_cache(maxsize=1)
def _import_hpp_centroidal_dynamics():
    """Import `hpp_centroidal_dynamics` after loading its shared libraries globally."""
    import eigenpy  # noqa: F401  (registers the Eigen <-> NumPy converters first)

    lib_dir = _cmeel_lib_dir()
    for name in _HPP_LIBRARIES:
        path = os.path.join(lib_dir, name)
        if not os.path.exists(path):
            raise ImportError(f"hpp-centroidal-dynamics dependency {name} missing from {lib_dir}")
        ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
    import hpp_centroidal_dynamics

    return hpp_centroidal_dynamics


def sole_corners(feet: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Contact points and normals of the feet in contact: the sole rectangle's corners.

    Args:
        feet: [F, 7] sole placements (xyz + quaternion xyzw), world frame; rows with
            NaN (feet in the air) are skipped.

    Returns:
        (points [4 C, 3], normals [4 C, 3]) world frame, for the C feet in contact;
        the normal of each corner is its sole's z axis.
    """
    from leas_jax.contacts.robot.model import matrix_from_quat_xyzw

    feet = np.asarray(feet, dtype=np.float64).reshape(-1, 7)
    feet = feet[~np.any(np.isnan(feet), axis=1)]
    if len(feet) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    rot = matrix_from_quat_xyzw(feet[:, 3:])
    half = np.array(
        [[sx * SOLE_LENGTH / 2, sy * SOLE_WIDTH / 2, 0.0] for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    )
    points = feet[:, None, :3] + np.einsum("fij,cj->fci", rot, half)
    normals = np.broadcast_to(rot[:, None, :, 2], points.shape)
    return points.reshape(-1, 3), np.ascontiguousarray(normals.reshape(-1, 3))


class HppEquilibrium:
    """Robustness of static equilibrium with hpp-centroidal-dynamics (LP algorithm).

    Host-only, not jittable; holds solver objects, one per process/thread.

    The LP (hpp-centroidal-dynamics `EQUILIBRIUM_ALGORITHM_LP`) finds generator
    coefficients b of the linearised friction cones with G b = D c + d (Newton-Euler
    of a static body of mass m at CoM c) maximising b0 <= min(b); the robustness is
    b0 >= 0 when the CoM is in equilibrium, negative when not.

    qpOASES solves it by default. hpp-centroidal-dynamics hot-starts qpOASES from the
    previous LP of the same size and starts it cold on a new object, after a change in
    the number of contact points (it then makes a new qpOASES problem) or after a
    failure; from a cold start qpOASES fails on some stances that have an optimum
    ("Initialisation failed", status LP_STATUS_ERROR), so its answer would depend on the
    stances checked before. Every LP qpOASES leaves without an optimum is solved again
    by CLP's simplex (a second Equilibrium, made at the first such LP): the robustness
    then depends on the stance alone, and CLP runs only where qpOASES fails.

    Args:
        mass: kg.
        mu: friction coefficient.
        use_clp: solve every LP with CLP alone.
    """

    def __init__(self, mass: float, mu: float = FRICTION, use_clp: bool = False):
        self._hpp = _import_hpp_centroidal_dynamics()
        self.mass = float(mass)
        self.mu = float(mu)
        self.use_clp = use_clp
        self._eq = self._new_equilibrium(use_clp)
        self._contacts = None  # (points [N, 3], normals [N, 3]) set on self._eq
        self._contacts_key = None
        self._clp = None  # CLP Equilibrium for the LPs qpOASES fails on
        self._clp_key = None  # key of the contact set on self._clp

    def _new_equilibrium(self, clp: bool):
        """A hpp-centroidal-dynamics Equilibrium of this mass solving its LPs with CLP or qpOASES."""
        solvers = self._hpp.SolverLP
        solver = solvers.SOLVER_LP_CLP if clp else solvers.SOLVER_LP_QPOASES
        return self._hpp.Equilibrium("talos", self.mass, GENERATORS_PER_CONTACT, solver)

    def _load_contacts(self, equilibrium, points: np.ndarray, normals: np.ndarray) -> None:
        """Give `equilibrium` the contact set (points, normals) for the LP algorithm."""
        algorithm = self._hpp.EquilibriumAlgorithm.EQUILIBRIUM_ALGORITHM_LP
        if not equilibrium.setNewContacts(points, normals, self.mu, algorithm):
            raise RuntimeError("hpp-centroidal-dynamics rejected the contact set")

    def set_contacts(self, points: np.ndarray, normals: np.ndarray) -> None:
        """Set contact points [N, 3] and unit normals [N, 3], world frame."""
        points = np.ascontiguousarray(points, dtype=np.float64)
        normals = np.ascontiguousarray(normals, dtype=np.float64)
        key = (points.tobytes(), normals.tobytes())
        if key == self._contacts_key:
            return
        self._load_contacts(self._eq, points, normals)
        self._contacts = (points, normals)
        self._contacts_key = key

    def _clp_equilibrium(self):
        """The CLP Equilibrium holding the current contact set (made and loaded on demand)."""
        if self._clp is None:
            self._clp = self._new_equilibrium(clp=True)
        if self._clp_key != self._contacts_key:
            self._load_contacts(self._clp, *self._contacts)
            self._clp_key = self._contacts_key
        return self._clp

    def robustness(self, com: np.ndarray, acceleration: np.ndarray | None = None) -> float:
        """Robustness of the current contact set for a CoM [3] (world), at rest or accelerating
        [3] (m/s^2, world); -inf if the LP has no optimum.

        Raises:
            RuntimeError: no contact set yet (`set_contacts`).
        """
        if self._contacts is None:
            raise RuntimeError("no contact set: call set_contacts first")
        args = (np.asarray(com, dtype=np.float64),)
        if acceleration is not None:
            args += (np.asarray(acceleration, dtype=np.float64),)
        optimal = self._hpp.LP_status.LP_STATUS_OPTIMAL
        status, value = self._eq.computeEquilibriumRobustness(*args)
        if status != optimal and not self.use_clp:
            status, value = self._clp_equilibrium().computeEquilibriumRobustness(*args)
        return float(value) if status == optimal else -np.inf

    def feet_robustness(self, feet: np.ndarray, com: np.ndarray) -> float:
        """Robustness of a stance: feet [F, 7] (NaN rows in the air), CoM [3], world."""
        points, normals = sole_corners(feet)
        if len(points) == 0:
            return -np.inf
        self.set_contacts(points, normals)
        return self.robustness(com)


def convex_hull_2d(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of a few 2-D points (Andrew's monotone chain).

    Args:
        points: [N, 2].

    Returns:
        [H, 2] hull vertices, counter-clockwise, no repeated point.
    """
    pts = sorted(set(map(tuple, np.asarray(points, dtype=np.float64).tolist())))
    if len(pts) <= 2:
        return np.array(pts).reshape(-1, 2)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def flat_support_margin(points: np.ndarray, normals: np.ndarray, com: np.ndarray) -> float:
    """Distance of the CoM's vertical projection inside the support polygon, if all normals are vertical.

    With every contact normal along +z, vertical contact forces alone balance gravity
    iff the CoM projects inside the convex hull of the contact points, and each
    hpp-centroidal-dynamics pyramid (4 edges symmetric about the normal) yields any
    vertical force with equal generator coefficients; so a CoM strictly inside the
    hull has robustness > 0. Used by the generator to skip the LP in clear cases.

    Args:
        points: [N, 3] contact points; normals: [N, 3] unit normals; com: [3], world.

    Returns:
        Signed distance (m, > 0 inside) of com[:2] to the hull boundary, or -inf if a
        normal is not vertical or the hull is degenerate.
    """
    if len(points) < 3 or normals[:, 2].min() < 1.0 - 1e-12:
        return -np.inf
    hull = convex_hull_2d(points[:, :2])
    if len(hull) < 3:
        return -np.inf
    edges = hull[np.arange(1, len(hull) + 1) % len(hull)] - hull  # np.roll(hull, -1, axis=0), cheaper
    rel = com[:2] - hull
    dist = (edges[:, 0] * rel[:, 1] - edges[:, 1] * rel[:, 0]) / np.hypot(edges[:, 0], edges[:, 1])
    return float(dist.min())


def friction_generators(
    normals: np.ndarray, mu: float = FRICTION, count: int = GENERATORS_PER_CONTACT
) -> np.ndarray:
    """Edges of the friction pyramids inscribed in the cones at each contact.

    Same pyramid as hpp-centroidal-dynamics (`Equilibrium::computeGenerators`), so
    that robustness values can be compared: tangents t1 = n x e_y (n x e_x when n is
    along e_y), t2 = n x t1, edges n + mu (sin a t1 + cos a t2), a = pi/4 + 2 pi k / count.

    Args:
        normals: [N, 3] unit contact normals.
        mu: friction coefficient.
        count: edges per cone.

    Returns:
        [N, count, 3] unit edge directions.
    """
    normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    t1 = np.cross(normals, np.array([0.0, 1.0, 0.0]))
    along_y = np.linalg.norm(t1, axis=1) < 1e-5
    t1[along_y] = np.cross(normals[along_y], np.array([1.0, 0.0, 0.0]))
    t2 = np.cross(normals, t1)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 /= np.linalg.norm(t2, axis=1, keepdims=True)
    angles = np.pi / 4 + 2.0 * np.pi * np.arange(count) / count
    edges = normals[:, None, :] + mu * (
        np.sin(angles)[None, :, None] * t1[:, None, :] + np.cos(angles)[None, :, None] * t2[:, None, :]
    )
    return edges / np.linalg.norm(edges, axis=2, keepdims=True)


def robustness_scale(mu: float = FRICTION, count: int = GENERATORS_PER_CONTACT) -> float:
    """Factor from the LP's b0 to hpp-centroidal-dynamics' robustness e_max.

    hpp-centroidal-dynamics reports e_max = b0 |f0 x g0| with f0 the sum of one
    cone's unit edges and g0 one edge (the distance from f0 to the cone boundary
    when b0 = 1); it depends only on mu and the edge count.
    """
    edges = friction_generators(np.array([[0.0, 0.0, 1.0]]), mu, count)[0]
    return float(np.linalg.norm(np.cross(edges.sum(axis=0), edges[0])))


def static_equilibrium_lp(
    points: np.ndarray,
    normals: np.ndarray,
    com: np.ndarray,
    mass: float,
    mu: float = FRICTION,
    count: int = GENERATORS_PER_CONTACT,
) -> float:
    """Independent robustness LP with SciPy (slow; for cross-checks and tests).

    Static equilibrium of a body of mass m at CoM c under gravity g = -9.81 e_z with
    contact forces f_i = sum_k b_ik e_ik (e_ik the pyramid edges, b_ik >= 0):

        (1) sum_i f_i            = -m g            (force balance)
        (2) sum_i p_i x f_i      = -c x m g        (moment balance about the origin)

    and b0* = max b0 subject to (1), (2), b_ik >= b0 (b0 free); with b_ik = b0 + s_ik,
    s_ik >= 0 this is a standard-form LP. The robustness is b0* times
    `robustness_scale`: the definition of hpp-centroidal-dynamics' LP algorithm, so
    the values match up to solver tolerance; the sign (equilibrium or not) is what
    docs/design.md §6 check 4 uses.

    Args:
        points: [N, 3] contact points, world frame.
        normals: [N, 3] unit normals.
        com: [3] centre of mass, world frame.
        mass: kg.
        mu: friction coefficient.
        count: edges per cone.

    Returns:
        Robustness b0 (>= 0 iff static equilibrium with the pyramid cones); -inf if
        the LP is infeasible, +inf if unbounded.
    """
    from scipy.optimize import linprog

    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    edges = friction_generators(normals, mu, count).reshape(-1, 3)  # [M, 3]
    lever = np.repeat(points, count, axis=0)
    wrench = np.vstack([edges.T, np.cross(lever, edges).T])  # [6, M]
    weight = np.array([0.0, 0.0, mass * GRAVITY])
    target = np.concatenate([weight, np.cross(np.asarray(com, dtype=np.float64), weight)])
    # Variables x = (s [M], b0): wrench (s + b0) = target; maximise b0.
    m = wrench.shape[1]
    a_eq = np.hstack([wrench, wrench.sum(axis=1, keepdims=True)])
    cost = np.zeros(m + 1)
    cost[-1] = -1.0
    bounds = [(0.0, None)] * m + [(None, None)]
    result = linprog(cost, A_eq=a_eq, b_eq=target, bounds=bounds, method="highs")
    if result.status == 2:
        return -np.inf
    if result.status == 3:
        return np.inf
    if result.status != 0:
        raise RuntimeError(f"linprog failed: {result.message}")
    return float(result.x[-1]) * robustness_scale(mu, count)
