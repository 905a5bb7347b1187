"""Evaluation scenarios of the paper (§IV-B to §IV-D) and their seeded start draws.

A scenario is a terrain file with a `[scenario]` table (docs/design.md §4). It is run
as one or more *cells*: a yaw range and a speed range for the starts. The
ground scenario is the paper's Table II, nine cells (three yaw ranges x three
initial speeds); every other scenario is one cell, its own table's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from leas_jax.errors import UsageError

METHODS = ("rblin", "rbkino", "rbkino_rrt", "leas", "leas_rrt", "navigate")
LEAS_METHODS = ("leas", "leas_rrt", "navigate")
RRT_METHODS = ("rbkino_rrt", "leas_rrt")

# Methods the paper runs on each scenario (§IV-B, §IV-C, §IV-D).
DEFAULT_METHODS = {
    "ground": ("rblin", "rbkino", "leas"),  # Table II
    "hole": ("rblin", "rbkino", "leas", "rbkino_rrt", "leas_rrt"),  # Figs. 6a, 7, 8
    "bridge": ("rblin", "rbkino", "leas", "rbkino_rrt", "leas_rrt"),  # Figs. 6b, 7
    "stairs": ("rblin", "rbkino", "leas"),  # Fig. 6c
    "stairs_side": ("rblin", "rbkino", "leas"),  # Fig. 6d
    "circuit": ("leas",),  # Fig. 9
}

# Table II: yaw ranges (deg, relative to the direction to the target) x initial speeds (m/s).
TABLE_II_YAWS = ((-30.0, 30.0), (60.0, 120.0), (150.0, 210.0))
TABLE_II_SPEEDS = (0.01, 0.04, 0.07)

# Mean contact-plan coverage (%) from Chemin et al., "Learning to steer a
# locomotion contact planner", Table II (60 trajectories per cell), keyed by
# (yaw range, speed) then method.
PAPER_TABLE_II = {
    ((-30.0, 30.0), 0.01): {"rblin": 99.8, "rbkino": 99.7, "leas": 99.8},
    ((-30.0, 30.0), 0.04): {"rblin": 99.8, "rbkino": 99.7, "leas": 99.8},
    ((-30.0, 30.0), 0.07): {"rblin": 99.8, "rbkino": 99.7, "leas": 99.8},
    ((60.0, 120.0), 0.01): {"rblin": 99.8, "rbkino": 99.7, "leas": 99.8},
    ((60.0, 120.0), 0.04): {"rblin": 97.3, "rbkino": 99.7, "leas": 99.8},
    ((60.0, 120.0), 0.07): {"rblin": 99.8, "rbkino": 99.7, "leas": 99.8},
    ((150.0, 210.0), 0.01): {"rblin": 22.3, "rbkino": 76.5, "leas": 98.4},
    ((150.0, 210.0), 0.04): {"rblin": 28.9, "rbkino": 77.6, "leas": 93.1},
    ((150.0, 210.0), 0.07): {"rblin": 34.0, "rbkino": 85.5, "leas": 98.2},
}

# A drawn start that fails the reachability condition is drawn again, at most
# this many times (then the run stops with an error naming the scenario).
_START_ATTEMPTS = 100


@dataclass(frozen=True)
class Cell:
    """One group of starts: yaw offsets (deg, relative to the first target) and speeds (m/s) drawn uniformly."""

    name: str
    yaw_deg: tuple[float, float]
    speed: tuple[float, float]

    @property
    def table_key(self):
        """Key into PAPER_TABLE_II (None for cells that are not Table II's)."""
        key = (tuple(self.yaw_deg), self.speed[0])
        return key if self.speed[0] == self.speed[1] and key in PAPER_TABLE_II else None


@dataclass(frozen=True)
class Starts:
    """Starts of one cell.

    Attributes:
        poses: [N, 4] (x, y, z, yaw) world, z at the nominal height above the terrain.
        speeds: [N] initial speeds along the heading (m/s).
        yaw_offsets_deg: [N] yaw minus the direction to the first target (deg).
    """

    poses: np.ndarray
    speeds: np.ndarray
    yaw_offsets_deg: np.ndarray


def cells_for(name: str, scenario) -> list[Cell]:
    """Cells of a scenario: Table II's nine for `ground`, else the scenario table's one.

    Args:
        name: scenario name (or a terrain name for --terrain files).
        scenario: the terrain's `Scenario`.
    """
    if name == "ground":
        return [
            Cell(f"yaw {lo:g}..{hi:g} deg, v {v:g} m/s", (lo, hi), (v, v))
            for lo, hi in TABLE_II_YAWS
            for v in TABLE_II_SPEEDS
        ]
    yaw = tuple(float(a) for a in scenario.start_yaw_deg)
    speed = tuple(float(a) for a in scenario.start_speed)
    return [Cell(f"yaw {yaw[0]:g}..{yaw[1]:g} deg, v {speed[0]:g}..{speed[1]:g} m/s", yaw, speed)]


def route(scenario) -> np.ndarray:
    """[W + 1, 2] points a path must visit in order: the waypoints, then the target."""
    points = [] if scenario.waypoints is None else list(np.asarray(scenario.waypoints, np.float64))
    return np.array(points + [np.asarray(scenario.target, np.float64)])


def draw_starts(
    scenario, cell: Cell, n: int, seed: int, field, nominal_root_height: float, reachability=None
) -> Starts:
    """Seeded starts of one cell: uniform in the start region, yaw offset and speed ranges.

    Starts failing the reachability condition (or standing over the void) are
    drawn again, so that every method starts from a valid pose. A target where
    the robot cannot stand is an error (`check_target`).

    Args:
        scenario: the terrain's `Scenario` (start_region, target, waypoints).
        cell: yaw and speed ranges.
        n: number of starts.
        seed: RNG seed (the scenario's seed plus the cell index, so cells differ).
        field: the heightfield.
        nominal_root_height: m above the terrain.
        reachability: `ReachabilityConfig` of the field (default the env's).

    Returns:
        `Starts`.

    Raises:
        UsageError: a target the robot cannot stand at, or no valid start in the region.
    """
    from leas_jax.env.config import ReachabilityConfig
    from leas_jax.steering.baselines import lift_checked

    reach = reachability or ReachabilityConfig()
    check_target(scenario, field, nominal_root_height, reach)
    rng = np.random.default_rng(seed)
    region = np.asarray(scenario.start_region, np.float64)
    aim = route(scenario)[0]
    poses, speeds, offsets = [], [], []
    for k in range(n):
        for _ in range(_START_ATTEMPTS):
            xy = rng.uniform(region[0], region[1])
            offset = rng.uniform(*cell.yaw_deg)
            speed = rng.uniform(*cell.speed)
            yaw = math.atan2(aim[1] - xy[1], aim[0] - xy[0]) + math.radians(offset)
            pose, ok = lift_checked(field, np.array([[xy[0], xy[1], yaw]]), nominal_root_height, reach)
            if ok[0]:
                break
        else:
            raise UsageError(
                f"scenario start_region {region.tolist()}: no valid start after "
                f"{_START_ATTEMPTS} draws (start {k})"
            )
        poses.append(pose[0])
        speeds.append(speed)
        offsets.append(offset)
    return Starts(np.array(poses).reshape(-1, 4), np.array(speeds), np.array(offsets))


# Yaws tried at the target: it is valid ground when the root fits there at one of them.
_TARGET_YAWS = 16


def check_target(scenario, field, nominal_root_height: float, reachability) -> None:
    """UsageError unless the root fits at the scenario's target at some yaw (reachability condition,
    solid ground under it): a target inside a wall, a pillar or over the void cannot be reached.

    Args:
        scenario: the terrain's `Scenario`.
        field: its heightfield; nominal_root_height: m; reachability: `ReachabilityConfig`.
    """
    from leas_jax.steering.baselines import lift_checked

    x, y = (float(v) for v in scenario.target)
    yaws = np.linspace(-math.pi, math.pi, _TARGET_YAWS, endpoint=False)
    planar = np.stack([np.full(_TARGET_YAWS, x), np.full(_TARGET_YAWS, y), yaws], axis=1)
    _, ok = lift_checked(field, planar, nominal_root_height, reachability)
    if not np.any(ok):
        raise UsageError(
            f"scenario.target ({x:g}, {y:g}): the robot cannot stand there at any yaw (inside an "
            "obstacle, against a wall or over the void: the reachability condition fails)"
        )
