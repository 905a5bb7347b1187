"""Speed-ups of the contact generator change no result.

The fast paths (cached box bounds in `surfaces.height_at`, the robot-bounds box filter
of `terrain_contacts`, the oriented-box pre-test of `self_contacts`, the LP shortcut
for flat stances with the CoM outside the support polygon, ...) are compared with the
straightforward versions they replace, kept here: piece by piece on random inputs, and
plan by plan (q, feet, guide_index, last_valid_index, coverage array for array) on
arena guides. When `.cache/contact_parity/arena_reference.npz` exists (written by
`benchmarks/contact_planner_speed.py --save-reference` at an older commit), the 24
arena guides it holds are re-planned and compared with it too.
"""

import sys
from pathlib import Path

import numpy as np
import pytest

from leas_jax.contacts.planner import projection as projection_module
from leas_jax.contacts.planner import surfaces as surfaces_module
from leas_jax.contacts.planner.generator import ContactGenerator, GeneratorConfig
from leas_jax.contacts.planner.surfaces import SOLE_CORNERS, sole_rotation
from leas_jax.contacts.robot.collision import robot_collision, terrain_collision
from leas_jax.contacts.robot.equilibrium import HppEquilibrium, flat_support_margin
from leas_jax.contacts.robot.model import load_talos

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

import contact_planner_speed as bench  # noqa: E402

REFERENCE = ROOT / ".cache" / "contact_parity" / "arena_reference.npz"
PLAN_ARRAYS = bench.PLAN_ARRAYS


# ---------------------------------------------------------------- the slow versions


def terrain_contacts_reference(robot, rot, pos, terrain, first_only=True, aabb=None):
    """`RobotCollision.terrain_contacts` before the speed-ups: every geometry against every box."""
    import coal

    if len(terrain.aabb) == 0:
        return []
    aabb = robot.world_aabb(rot, pos) if aabb is None else aabb
    overlap = np.all(
        (aabb[:, None, 0] <= terrain.aabb[None, :, 1]) & (aabb[:, None, 1] >= terrain.aabb[None, :, 0]),
        axis=2,
    )
    hits = []
    request, result = coal.CollisionRequest(), coal.CollisionResult()
    for g, b in zip(*np.nonzero(overlap)):
        result.clear()
        if coal.collide(
            robot.geometries[g],
            coal.Transform3s(rot[g], pos[g]),
            terrain.shapes[b],
            terrain.transforms[b],
            request,
            result,
        ):
            hits.append((int(g), int(b)))
            if first_only:
                break
    return hits


def self_contacts_reference(robot, rot, pos, first_only=True, aabb=None):
    """`RobotCollision.self_contacts` before the speed-ups: coal on every AABB-overlapping pair."""
    import coal

    aabb = robot.world_aabb(rot, pos) if aabb is None else aabb
    flat = aabb.reshape(len(aabb), 6)
    box_a, box_b = flat[robot.self_pairs[:, 0]], flat[robot.self_pairs[:, 1]]
    overlap = np.all((box_a[:, :3] <= box_b[:, 3:]) & (box_a[:, 3:] >= box_b[:, :3]), axis=1)
    hits = []
    request, result = coal.CollisionRequest(), coal.CollisionResult()
    for ga, gb in robot.self_pairs[overlap].tolist():
        result.clear()
        if coal.collide(
            robot.geometries[ga],
            coal.Transform3s(rot[ga], pos[ga]),
            robot.geometries[gb],
            coal.Transform3s(rot[gb], pos[gb]),
            request,
            result,
        ):
            hits.append((int(ga), int(gb)))
            if first_only:
                break
    return hits


@pytest.fixture(scope="module")
def arena():
    terrain, guides = bench.arena_guides(count=8, length=120)
    return terrain, guides


@pytest.fixture(scope="module")
def talos():
    return load_talos()


def random_placements(talos, robot, terrain, rng, count):
    """Geometry placements of random leg joints (within limits) at random arena roots, low
    enough that the feet often meet the terrain: (rot, pos) pairs."""
    out = []
    lo, hi = terrain.bounds[0] + 0.5, terrain.bounds[1] - 0.5
    for _ in range(count):
        xy = rng.uniform(lo, hi)
        yaw = rng.uniform(-np.pi, np.pi)
        z = float(terrain.height_at(xy)) + rng.uniform(0.6, 1.1)
        c, s = np.cos(yaw), np.sin(yaw)
        root_R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        leg_q = np.stack([rng.uniform(leg.lower, leg.upper) for leg in talos.legs])
        out.append(robot.placements_fast(talos, root_R, np.array([xy[0], xy[1], z]), leg_q))
    return out


# ---------------------------------------------------------------- piece by piece


def test_height_at_matches_terrain(arena):
    terrain, _ = arena
    rng = np.random.default_rng(1)
    xy = rng.uniform(terrain.bounds[0] - 0.5, terrain.bounds[1] + 0.5, size=(4000, 2))
    # Points exactly on box edges too (the closed-set tolerance of height_at).
    corners = np.concatenate([box.vertices()[:, :2] for box in terrain.boxes[:80]])
    xy = np.concatenate([xy, corners])
    assert np.array_equal(surfaces_module.height_at(terrain, xy), terrain.height_at(xy))


def test_terrain_and_self_contacts_match(arena, talos):
    terrain, _ = arena
    robot = robot_collision(talos)
    objects = terrain_collision(terrain)
    rng = np.random.default_rng(2)
    terrain_hits = self_hits = 0
    for rot, pos in random_placements(talos, robot, terrain, rng, 150):
        fast = robot.terrain_contacts(rot, pos, objects, first_only=False)
        assert fast == terrain_contacts_reference(robot, rot, pos, objects, first_only=False)
        assert robot.terrain_contacts(rot, pos, objects) == terrain_contacts_reference(
            robot, rot, pos, objects
        )
        terrain_hits += bool(fast)
        fast = robot.self_contacts(rot, pos, first_only=False)
        assert fast == self_contacts_reference(robot, rot, pos, first_only=False)
        assert robot.self_contacts(rot, pos) == self_contacts_reference(robot, rot, pos)
        self_hits += bool(fast)
    assert terrain_hits > 10 and self_hits > 10  # both outcomes are exercised


def test_flat_outside_support_fails_the_lp(talos):
    """The LP shortcut: flat contacts, CoM outside their hull -> hpp robustness < 0."""
    equilibrium = HppEquilibrium(talos.mass)
    rng = np.random.default_rng(3)
    rejected = 0
    for _ in range(200):
        feet = rng.integers(1, 3)
        pos = np.concatenate(
            [rng.uniform(-0.2, 0.2, (feet, 2)), np.full((feet, 1), rng.uniform(-1, 1))], axis=1
        )
        rot = sole_rotation(np.tile([0.0, 0.0, 1.0], (feet, 1)), rng.uniform(-np.pi, np.pi, feet))
        points = np.concatenate([p + SOLE_CORNERS @ r.T for p, r in zip(pos, rot)])
        normals = np.repeat(rot[:, :, 2], 4, axis=0)
        com = np.array([*rng.uniform(-0.35, 0.35, 2), pos[0, 2] + 0.9])
        margin = flat_support_margin(points, normals, com)
        if margin < -projection_module._OUTSIDE_MARGIN:
            equilibrium.set_contacts(points, normals)
            assert equilibrium.robustness(com) < 0.0
            rejected += 1
    assert rejected > 50


# ---------------------------------------------------------------- whole plans


def reference_generator(terrain, monkeypatch):
    """A generator running the slow versions of every sped-up piece."""
    monkeypatch.setattr(surfaces_module, "height_at", lambda terrain, xy: terrain.height_at(xy))
    monkeypatch.setattr(projection_module, "_OUTSIDE_MARGIN", np.inf)
    generator = ContactGenerator(terrain, GeneratorConfig())
    robot = generator.projection.robot
    monkeypatch.setattr(
        robot,
        "terrain_contacts",
        lambda rot, pos, objects, first_only=True, aabb=None: terrain_contacts_reference(
            robot, rot, pos, objects, first_only, aabb
        ),
        raising=False,
    )
    monkeypatch.setattr(
        robot,
        "self_contacts",
        lambda rot, pos, first_only=True, aabb=None: self_contacts_reference(
            robot, rot, pos, first_only, aabb
        ),
        raising=False,
    )
    return generator


def assert_same_plan(plan, reference: dict, label: str):
    for key in PLAN_ARRAYS:
        assert bench.same_array(getattr(plan, key), reference[key]), f"{label}: {key} differs"


def test_plans_match_the_slow_versions(arena, monkeypatch):
    terrain, guides = arena
    fast = ContactGenerator(terrain, GeneratorConfig())
    plans = [fast.plan(guide, bench.DT) for guide in guides]
    with monkeypatch.context() as patch:
        slow = reference_generator(terrain, patch)
        for k, (guide, plan) in enumerate(zip(guides, plans)):
            again = slow.plan(guide, bench.DT)
            assert_same_plan(plan, {key: getattr(again, key) for key in PLAN_ARRAYS}, f"guide {k}")
    assert sum(len(p) for p in plans) > 20  # the guides exercise the generator


@pytest.mark.skipif(
    not REFERENCE.is_file(),
    reason="no saved reference plans (benchmarks/contact_planner_speed.py "
    "--save-reference .cache/contact_parity/arena_reference.npz)",
)
def test_plans_match_saved_reference():
    from leas_jax.terrain import load_terrain

    data = np.load(REFERENCE)
    generator = ContactGenerator(load_terrain(bench.ARENA), GeneratorConfig())
    for k in range(int(data["count"])):
        plan = generator.plan(data[f"guide_{k}"], bench.DT)
        assert_same_plan(plan, {key: data[f"{key}_{k}"] for key in PLAN_ARRAYS}, f"arena guide {k}")


def test_near_disk_and_column_match_near_column():
    """`near_disk` + `near_column_z` (one disk for several faces) = `near_column` = brute force."""
    from leas_jax.contacts.robot.database import leg_database

    rng = np.random.default_rng(4)
    for side in (0, 1):
        db = leg_database(side)
        lo, hi = db.bounds
        for _ in range(100):
            point = rng.uniform(lo - 0.05, hi + 0.05)
            radius, half = rng.uniform(0.02, 0.2), rng.uniform(0.02, 0.15)
            dx, dy = db.positions[:, 0] - point[0], db.positions[:, 1] - point[1]
            brute = np.flatnonzero(
                (dx * dx + dy * dy <= radius * radius) & (np.abs(db.positions[:, 2] - point[2]) <= half)
            )
            column = db.near_column(point, radius, half)
            assert np.array_equal(column, brute)
            assert np.array_equal(db.near_column_z(db.near_disk(point, radius), point[2], half), brute)


def legs_joint_frames_reference(hip_offset, thigh, shin, q):
    """`collision._legs_joint_frames` before the speed-ups (one assignment per joint and entry)."""
    c, s = np.cos(q), np.sin(q)
    steps = np.zeros((2, 6, 4, 4))
    steps[:, :, 3, 3] = 1.0
    for k, axis in enumerate((2, 0, 1, 1, 1, 0)):
        i, j = [(1, 2), (2, 0), (0, 1)][axis]
        steps[:, k, axis, axis] = 1.0
        steps[:, k, i, i] = c[:, k]
        steps[:, k, j, j] = c[:, k]
        steps[:, k, i, j] = -s[:, k]
        steps[:, k, j, i] = s[:, k]
    steps[:, 0, :3, 3] = hip_offset
    steps[:, 3, 2, 3] = -thigh
    steps[:, 4, 2, 3] = -shin
    frames = np.empty((2, 6, 4, 4))
    frames[:, 0] = steps[:, 0]
    for k in range(1, 6):
        frames[:, k] = frames[:, k - 1] @ steps[:, k]
    return frames


def test_legs_joint_frames_match(talos):
    from leas_jax.contacts.robot.collision import _legs_joint_frames

    hip = np.array([leg.hip_offset for leg in talos.legs])
    thigh = np.array([leg.thigh for leg in talos.legs])
    shin = np.array([leg.shin for leg in talos.legs])
    rng = np.random.default_rng(5)
    for _ in range(500):
        q = rng.uniform(-2.5, 2.5, (2, 6))
        assert np.array_equal(
            _legs_joint_frames(hip, thigh, shin, q), legs_joint_frames_reference(hip, thigh, shin, q)
        )
