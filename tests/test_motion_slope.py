"""Talos standing on a 10 deg slope in MuJoCo: with MuJoCo's default solver its soft frictional
contacts let the soles creep downhill under the weight's tangential load (well inside the
friction cone); the noslip solver after the main one (`SimulationConfig.noslip_iterations`) or
frictional constraints harder than the normal ones (`SimulationConfig.impratio`) hold them, and
`simulate` runs both by default."""

import dataclasses
import math

import numpy as np
from motion_helpers import straight_plan

from leas_jax.contacts.robot.model import load_talos, matrix_from_quat_xyzw, quat_xyzw_from_matrix
from leas_jax.motion.config import SimulationConfig
from leas_jax.motion.motion import _homogeneous, make_motion, posture_frames
from leas_jax.motion.simulate import simulate
from leas_jax.motion.wbik import Targets, WholeBodyIK


def slope_plan(degrees: float):
    """Two equal double-support postures with both soles on a plane rising along +x by `degrees`,
    the trunk upright and the CoM over the soles' midpoint (a 0.5 s shift that does not move)."""
    plan, talos = straight_plan(0.3), load_talos()
    angle = math.radians(degrees)
    turn = np.array(
        [[math.cos(angle), 0, -math.sin(angle)], [0, 1, 0], [math.sin(angle), 0, math.cos(angle)]]
    )
    feet = np.array(
        [
            np.r_[turn @ f[:3], quat_xyzw_from_matrix(turn @ matrix_from_quat_xyzw(f[3:]))]
            for f in plan.feet[0]
        ]
    )
    soles = np.array([_homogeneous(f) for f in feet])
    q = plan.q[0].copy()
    _, com, rotation = posture_frames(talos, q)
    target = np.r_[soles[:, :2, 3].mean(axis=0), soles[:, 2, 3].mean() + com[2] - plan.feet[0, :, 2].mean()]
    q[2] += target[2] - com[2]
    q = WholeBodyIK(talos, 100, 1e-8, 1e-9).solve(q, Targets(soles, target, rotation, q))
    centre = turn @ np.array([4.0, 4.0, -0.15])
    terrain = (
        'name = "slope"\nbounds = [[0.0, 0.0], [8.0, 8.0]]\nvoid_height = -2.0\nresolution = 0.02\n\n'
        f"[[box]]\ncenter = [{centre[0]}, {centre[1]}, {centre[2]}]\nsize = [3.0, 3.0, 0.3]\nrpy = [0.0, {-angle}, 0.0]\n"
    )
    return dataclasses.replace(
        plan,
        q=np.array([q, q]),
        feet=np.array([feet, feet]),
        guide_index=plan.guide_index[:2],
        terrain=terrain,
    )


def test_the_noslip_solver_or_hard_friction_keeps_the_soles_on_a_slope():
    motion = make_motion(slope_plan(10.0))
    mujoco_default = {"noslip_iterations": 0, "cone": "pyramidal", "impratio": 1.0}
    runs = {
        "mujoco's default": mujoco_default,
        "noslip": mujoco_default | {"noslip_iterations": 5},
        "impratio 10": mujoco_default | {"impratio": 10.0},
        "simulate's default": {},
    }
    slip = {}
    for name, overrides in runs.items():
        rollout = simulate(motion, config=SimulationConfig(settle=1.5, **overrides))
        assert rollout.success, (name, rollout.message)
        slip[name] = rollout.summary()["max_slip_m"]
    # 2 s standing: 8.6 mm downhill with MuJoCo's default, 0.2-0.3 mm with either remedy
    assert slip["mujoco's default"] > 0.005
    assert max(slip[name] for name in runs if name != "mujoco's default") < 0.001, slip
