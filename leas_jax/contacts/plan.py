"""Contact plan: the contact generator's output and its file format (docs/design.md §6, contract).

Host-only (NumPy), not jittable.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from leas_jax.contacts.robot.model import NQ
from leas_jax.errors import LeasError

# Keys of a plan file, docs/design.md §6: "exactly those keys plus terrain and guide".
PLAN_KEYS = ("q", "feet", "guide_index", "last_valid_index", "coverage", "terrain", "guide")

# Longest guide the command line plans or shows: 20 000 poses are 2 000 s at the paper's 0.1 s
# step (over half an hour of walking, far past any scenario's route). A million-pose guide took
# 340 s and 857 MB to plan and `leas show` 2 GB on it; at this bound both stay within seconds
# and tens of MB.
MAX_GUIDE_POSES = 20_000


class PlanError(LeasError):
    """A plan file or plan arrays do not follow the docs/design.md §6 format."""


@dataclass(frozen=True, eq=False)
class ContactPlan:
    """A sequence of K quasi-static key postures along a guide path.

    Attributes:
        q: [K, 39] Pinocchio configurations of Talos (root xyz + quaternion xyzw,
            then the 32 joints; upper body at half-sitting), world frame.
        feet: [K, 2, 7] world placements (xyz + quaternion xyzw) of the left and right
            sole frames; a row of NaN for a foot in the air.
        guide_index: [K] int, guide index each posture belongs to.
        last_valid_index: guide index of the last valid posture (-1: none).
        coverage: arc-length fraction of the guide covered up to `last_valid_index`, in [0, 1].
        terrain: the terrain file text (TOML).
        guide: [T, 4] guide path (x, y, z, yaw), world frame, root = base_link.
        timestep: s between guide poses; kept in memory only (the file holds exactly
            the docs/design.md §6 keys), None for a plan read from a file.
    """

    q: np.ndarray
    feet: np.ndarray
    guide_index: np.ndarray
    last_valid_index: int
    coverage: float
    terrain: str
    guide: np.ndarray
    timestep: float | None = None

    def __post_init__(self):
        q = np.asarray(self.q, dtype=np.float64).reshape(-1, NQ)
        feet = np.asarray(self.feet, dtype=np.float64).reshape(-1, 2, 7)
        guide_index = np.asarray(self.guide_index, dtype=np.int64).reshape(-1)
        guide = np.asarray(self.guide, dtype=np.float64).reshape(-1, 4)
        if not (len(q) == len(feet) == len(guide_index)):
            raise PlanError(
                f"plan arrays disagree on the posture count: q {len(q)}, feet {len(feet)}, "
                f"guide_index {len(guide_index)}"
            )
        for name, value in (("q", q), ("feet", feet), ("guide_index", guide_index), ("guide", guide)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        object.__setattr__(self, "last_valid_index", int(self.last_valid_index))
        object.__setattr__(self, "coverage", float(self.coverage))
        object.__setattr__(self, "terrain", str(self.terrain))

    def __len__(self) -> int:
        return len(self.q)

    def save(self, path) -> None:
        """Write the plan as .npz with exactly the keys of PLAN_KEYS, atomically.

        The file is written to a temporary file in the same folder, then renamed over
        `path`, so readers never see a partial file.
        """
        import io

        from leas_jax.files import atomic_write_bytes

        buffer = io.BytesIO()
        np.savez(
            buffer,
            q=self.q,
            feet=self.feet,
            guide_index=self.guide_index,
            last_valid_index=np.int64(self.last_valid_index),
            coverage=np.float64(self.coverage),
            terrain=np.str_(self.terrain),
            guide=self.guide,
        )
        atomic_write_bytes(os.fspath(path), buffer.getvalue())

    @classmethod
    def load(cls, path) -> ContactPlan:
        """Read a plan written by `save`.

        Raises:
            PlanError: a key is missing or an array has the wrong shape (message names the file).
        """
        with np.load(path, allow_pickle=False) as data:
            missing = [key for key in PLAN_KEYS if key not in data.files]
            if missing:
                raise PlanError(
                    f"{path}: missing key '{missing[0]}' (plan files have {', '.join(PLAN_KEYS)})"
                )
            try:
                return cls(
                    q=data["q"],
                    feet=data["feet"],
                    guide_index=data["guide_index"],
                    last_valid_index=int(data["last_valid_index"]),
                    coverage=float(data["coverage"]),
                    terrain=str(data["terrain"]),
                    guide=data["guide"],
                )
            except ValueError as exc:
                raise PlanError(f"{path}: malformed plan arrays ({exc})") from None


def arc_length(guide: np.ndarray) -> np.ndarray:
    """Cumulative arc length of a guide path.

    Args:
        guide: [T, 4] (x, y, z, yaw).

    Returns:
        [T] length of the root's (x, y, z) polyline from pose 0 to each pose, m.
    """
    guide = np.asarray(guide, dtype=np.float64).reshape(-1, 4)
    if len(guide) == 0:
        return np.zeros(0)
    seg = np.linalg.norm(np.diff(guide[:, :3], axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(seg)])


def coverage_of(guide: np.ndarray, last_valid_index: int) -> float:
    """Arc-length fraction of the guide covered up to `last_valid_index` (docs/design.md §6).

    A guide that does not move (pure rotation or standing) has no length; its
    coverage is then the index fraction last_valid_index / (T - 1).

    Args:
        guide: [T, 4] guide path.
        last_valid_index: guide index of the last valid posture, -1 for none.

    Returns:
        coverage in [0, 1].
    """
    guide = np.asarray(guide, dtype=np.float64).reshape(-1, 4)
    if last_valid_index < 0 or len(guide) == 0:
        return 0.0
    if last_valid_index >= len(guide) - 1:
        return 1.0
    length = arc_length(guide)
    if length[-1] <= 1e-9:
        return float(last_valid_index) / float(len(guide) - 1)
    return float(np.clip(length[last_valid_index] / length[-1], 0.0, 1.0))
