"""Per-leg sample database: reachable flat-sole positions in the root frame (RB-PRM).

Host-only (Pinocchio, coal, SciPy), not jittable. As in RB-PRM (Tonneau et al., "An
efficient acyclic contact planner for multiped robots", T-RO 2018), each limb gets an
offline set of joint configurations, indexed by the end-effector position in the
root frame, from which contact candidates are drawn online.

Sampling: hip yaw, hip roll, hip pitch and knee are drawn uniformly within their
limits (seeded), and the ankle is set so that the sole is exactly flat in the root
frame. With R_sole = Rz(q1) Rx(q2) Ry(q3 + q4 + q5) Rx(q6) (ik.py eq. (1)), R_sole e_z
= e_z holds iff q5 = -(q3 + q4) and q6 = -q2; drawing all six joints and keeping the
near-flat ones would discard ~99.5 % of the draws for a 3 deg tolerance. Samples with
the ankle outside its limits, or with the leg (thigh, shin, ankle, foot meshes)
colliding with the rest of the body at half-sitting (SRDF-disabled pairs excluded),
are dropped. Positions are indexed with a cKDTree.

The database is cached on disk in `$LEAS_CACHE_DIR` (default `~/.cache/leas_jax`) under
a name keyed by a hash of the URDF/SRDF files, the settings and the format version;
it is rebuilt when they change and written atomically (temporary file + rename).
"""

from __future__ import annotations

import functools
import hashlib
import os
import tempfile
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from leas_jax.contacts.robot.ik import leg_fk
from leas_jax.contacts.robot.model import LEG_PREFIXES, TalosModel, load_talos

_FORMAT_VERSION = 1


@dataclass(frozen=True)
class DatabaseConfig:
    """Settings of the per-leg sample database (part of the cache key)."""

    samples: int = 20000  # raw draws per leg; ~10^4 kept samples give a few mm spacing in the sole plane
    seed: int = 0  # numpy default_rng seed
    collision_links: tuple[int, ...] = (
        3,
        4,
        5,
        6,
    )  # leg links checked against the body (hip links 1-2 sit inside the pelvis)


@dataclass(frozen=True)
class LegDatabase:
    """Flat-sole samples of one leg.

    Attributes:
        side: 0 left, 1 right.
        q: [N, 6] leg joints, rad (hip yaw ... ankle roll).
        positions: [N, 3] sole positions in the root (base_link) frame, m.
        yaw: [N] sole yaw relative to the root (= hip yaw q1), rad.
        tree: scipy.spatial.cKDTree over `positions`.
        tree_xy: scipy.spatial.cKDTree over `positions[:, :2]` (vertical-cylinder queries;
            the root frame is yaw-only, so its z axis is vertical).
    """

    side: int
    q: np.ndarray
    positions: np.ndarray
    yaw: np.ndarray
    tree: object
    tree_xy: object

    def near(self, point, radius: float) -> np.ndarray:
        """Indices of the samples within `radius` (m) of `point` [3] (root frame)."""
        return np.asarray(
            self.tree.query_ball_point(np.asarray(point, dtype=np.float64), radius), dtype=np.int64
        )

    def near_column(self, point, radius: float, half_height: float) -> np.ndarray:
        """Indices (sorted) of the samples in the vertical cylinder of `radius` and +-`half_height`
        around `point` [3] (root frame).

        Scans the samples' (x, y) columns rather than querying `tree_xy`: turning the
        KD-tree's Python list of ~600 indices into an array cost more than the query itself.
        """
        point = np.asarray(point, dtype=np.float64)
        return self.near_column_z(self.near_disk(point, radius), point[2], half_height)

    def near_disk(self, point, radius: float) -> np.ndarray:
        """Indices (sorted) of the samples whose (x, y) lies within `radius` of point[:2]
        (root frame): the first half of `near_column`, shared by columns at several heights."""
        # A scan of all ~10^4 samples (contiguous columns) costs a third of a grid query
        # with its gather and sort, and gives the indices sorted.
        point = np.asarray(point, dtype=np.float64)
        dx, dy = self._x - point[0], self._y - point[1]
        return np.flatnonzero(dx * dx + dy * dy <= radius * radius)

    def near_column_z(self, idx: np.ndarray, z: float, half_height: float) -> np.ndarray:
        """The samples of `idx` (from `near_disk`) within +-`half_height` of height z: with
        `near_disk`, the same indices as `near_column` (same tests, same order)."""
        return idx[np.abs(self._z[idx] - z) <= half_height]

    @property
    def _x(self) -> np.ndarray:
        return self._columns()[0]

    @property
    def _y(self) -> np.ndarray:
        return self._columns()[1]

    @property
    def _z(self) -> np.ndarray:
        return self._columns()[2]

    def _columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Contiguous x, y, z columns of `positions` (gathers from them are cheaper)."""
        columns = self.__dict__.get("_xyz")
        if columns is None:
            columns = tuple(np.ascontiguousarray(self.positions[:, k]) for k in range(3))
            object.__setattr__(self, "_xyz", columns)
        return columns

    @property
    def bounds(self) -> np.ndarray:
        """[2, 3] min and max sole position over the samples, root frame, m."""
        return np.stack([self.positions.min(axis=0), self.positions.max(axis=0)])


def cache_dir() -> Path:
    """Folder of the on-disk caches: `$LEAS_CACHE_DIR`, else `~/.cache/leas_jax`."""
    env = os.environ.get("LEAS_CACHE_DIR")
    return Path(env) if env else Path.home() / ".cache" / "leas_jax"


def cache_key(talos: TalosModel, side: int, config: DatabaseConfig) -> str:
    """Hex digest naming one leg's database: model files, settings, side, format version."""
    digest = hashlib.sha256()
    digest.update(talos.file_digest.encode())
    digest.update(repr(sorted(asdict(config).items())).encode())
    digest.update(f"side={side};version={_FORMAT_VERSION}".encode())
    return digest.hexdigest()


def sample_flat_sole(talos: TalosModel, side: int, count: int, seed: int) -> np.ndarray:
    """Seeded flat-sole leg configurations within the joint limits (no collision check).

    Args:
        talos: the model.
        side: 0 left, 1 right.
        count: number of draws (fewer are returned: ankle-limit rejections).
        seed: numpy default_rng seed.

    Returns:
        [M, 6] leg joints, rad, M <= count.
    """
    leg = talos.legs[side]
    rng = np.random.default_rng([seed, side])
    q = np.empty((count, 6))
    q[:, :4] = rng.uniform(leg.lower[:4], leg.upper[:4], size=(count, 4))
    q[:, 4] = -(q[:, 2] + q[:, 3])  # flat sole: ankle pitch cancels hip pitch + knee
    q[:, 5] = -q[:, 1]  # flat sole: ankle roll cancels hip roll
    keep = np.all((q >= leg.lower) & (q <= leg.upper), axis=1)
    return q[keep]


def _body_collision_model(talos: TalosModel, side: int, links: tuple[int, ...]):
    """Geometry model with the pairs (leg link of `links`, non-leg body geometry), SRDF-filtered."""
    import example_robot_data
    import pinocchio as pin

    geom_model = example_robot_data.load("talos").collision_model
    prefix = LEG_PREFIXES[side]
    leg_names = {f"{prefix}_{k}_link_0" for k in links}
    names = [g.name for g in geom_model.geometryObjects]
    geom_model.addAllCollisionPairs()
    pin.removeCollisionPairs(talos.model, geom_model, talos.srdf_path)
    kept = []
    for pair in geom_model.collisionPairs:
        a, b = names[pair.first], names[pair.second]
        if (a in leg_names and not b.startswith("leg_")) or (b in leg_names and not a.startswith("leg_")):
            kept.append((pair.first, pair.second))
    geom_model.removeAllCollisionPairs()
    for first, second in kept:
        geom_model.addCollisionPair(pin.CollisionPair(first, second))
    return geom_model


def build_leg_database(talos: TalosModel, side: int, config: DatabaseConfig = DatabaseConfig()) -> np.ndarray:
    """Draw, filter and return one leg's samples (seconds; use `leg_database` for the cache).

    Host-only, not jittable.

    Returns:
        [N, 6] collision-free flat-sole leg joints, rad.
    """
    import pinocchio as pin

    q_leg = sample_flat_sole(talos, side, config.samples, config.seed)
    geom_model = _body_collision_model(talos, side, config.collision_links)
    geom_data = pin.GeometryData(geom_model)
    data = talos.model.createData()
    q = talos.q_ref.copy()
    index = talos.legs[side].q_index
    free = np.ones(len(q_leg), dtype=bool)
    for k, joints in enumerate(q_leg):
        q[index] = joints
        free[k] = not pin.computeCollisions(talos.model, data, geom_model, geom_data, q, True)
    return q_leg[free]


def _from_joints(talos: TalosModel, side: int, q_leg: np.ndarray) -> LegDatabase:
    from scipy.spatial import cKDTree

    rot, pos = leg_fk(talos.legs[side], q_leg)
    for array in (q_leg, pos):
        array.setflags(write=False)
    yaw = np.arctan2(rot[:, 1, 0], rot[:, 0, 0])
    yaw.setflags(write=False)
    return LegDatabase(
        side=side, q=q_leg, positions=pos, yaw=yaw, tree=cKDTree(pos), tree_xy=cKDTree(pos[:, :2])
    )


def _load_or_build(talos: TalosModel, side: int, config: DatabaseConfig) -> np.ndarray:
    path = cache_dir() / f"talos_leg{side}_{cache_key(talos, side, config)[:20]}.npz"
    if path.is_file():
        try:
            with np.load(path) as data:
                q_leg = np.array(data["q"], dtype=np.float64)
            if q_leg.ndim == 2 and q_leg.shape[1] == 6 and len(q_leg) > 0:
                return q_leg
        except (OSError, ValueError, KeyError):
            pass  # unreadable or truncated cache file: rebuild it below
    q_leg = build_leg_database(talos, side, config)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(handle, "wb") as stream:
            np.savez(stream, q=q_leg)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return q_leg


@functools.lru_cache(maxsize=4)
def leg_database(side: int, config: DatabaseConfig = DatabaseConfig()) -> LegDatabase:
    """One leg's sample database, from the disk cache or built (and cached) once per process.

    Host-only, not jittable.

    Args:
        side: 0 left, 1 right.
        config: database settings.
    """
    talos = load_talos()
    return _from_joints(talos, side, _load_or_build(talos, side, config))
