"""Talos in MuJoCo (leas_jax.motion.robot) against Pinocchio's model of the same URDF."""

import mujoco
import numpy as np
import pytest

from leas_jax.contacts.robot.model import SOLE_FRAMES, SOLE_LENGTH, SOLE_WIDTH, load_talos
from leas_jax.motion.robot import SOLE_THICKNESS, scene_model, talos_mujoco

pin = pytest.importorskip("pinocchio")


@pytest.fixture(scope="module")
def robots():
    return talos_mujoco(), load_talos()


def _random_configurations(model, count, seed):
    rng = np.random.default_rng(seed)
    lower, upper = model.lowerPositionLimit[7:], model.upperPositionLimit[7:]
    out = []
    for _ in range(count):
        q = np.empty(39)
        q[:3] = rng.uniform(-2.0, 2.0, 3)
        quat = rng.normal(size=4)
        q[3:7] = quat / np.linalg.norm(quat)
        q[7:] = rng.uniform(lower, upper)
        out.append(q)
    return out


def test_joints_limits_and_motors(robots):
    mj, talos = robots
    model, pm = mj.model, talos.model
    assert model.nq == 39 and model.nv == 38 and model.nu == 32
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE
    for k, name in enumerate(mj.joint_names):
        jid = pm.getJointId(name)
        qi, vi = pm.joints[jid].idx_q, pm.joints[jid].idx_v
        mjid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        np.testing.assert_allclose(
            model.jnt_range[mjid], [pm.lowerPositionLimit[qi], pm.upperPositionLimit[qi]]
        )
        np.testing.assert_allclose(model.jnt_actfrcrange[mjid], [-pm.effortLimit[vi], pm.effortLimit[vi]])
        np.testing.assert_allclose(
            model.actuator_ctrlrange[mj.actuator_index[k]], model.jnt_actfrcrange[mjid]
        )
        assert model.dof_armature[mj.dof_index[k]] == pytest.approx(pm.armature[vi])


def test_masses_and_inertias_equal_pinocchio(robots):
    mj, talos = robots
    model, pm = mj.model, talos.model
    assert model.body_mass.sum() == pytest.approx(pin.computeTotalMass(pm), abs=1e-9)
    for jid in range(1, pm.njoints):
        name = pm.names[jid]
        body = model.jnt_bodyid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)]
        inertia = pm.inertias[jid]
        assert model.body_mass[body] == pytest.approx(inertia.mass, rel=1e-9), name
        np.testing.assert_allclose(model.body_ipos[body], inertia.lever, atol=1e-9, err_msg=name)
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[body])
        rot = rot.reshape(3, 3)
        full = rot @ np.diag(model.body_inertia[body]) @ rot.T
        np.testing.assert_allclose(full, inertia.inertia, atol=1e-7, err_msg=name)


def test_sole_forward_kinematics_within_1mm(robots):
    mj, talos = robots
    model, pm = mj.model, talos.model
    pdata, data = pm.createData(), mujoco.MjData(model)
    frames = [pm.getFrameId(f) for f in SOLE_FRAMES]
    worst = 0.0
    for q in _random_configurations(pm, 20, seed=3):
        pin.framesForwardKinematics(pm, pdata, q)
        data.qpos[:] = mj.qpos_from_pin(q)
        mujoco.mj_kinematics(model, data)
        np.testing.assert_allclose(mj.pin_from_qpos(data.qpos), q, atol=1e-12)
        for site, frame in zip(mj.sole_sites, frames):
            worst = max(worst, np.linalg.norm(data.site_xpos[site] - pdata.oMf[frame].translation))
            np.testing.assert_allclose(
                data.site_xmat[site].reshape(3, 3), pdata.oMf[frame].rotation, atol=1e-6
            )
        mujoco.mj_comPos(model, data)
        np.testing.assert_allclose(data.subtree_com[mj.root_body], pin.centerOfMass(pm, pdata, q), atol=1e-6)
    assert worst < 1e-3


def test_sole_boxes_are_the_sole_rectangle(robots):
    mj, talos = robots
    model = mj.model
    data = mujoco.MjData(model)
    data.qpos[:] = mj.qpos_from_pin(talos.q_ref)
    mujoco.mj_kinematics(model, data)
    for geom, site in zip(mj.sole_geoms, mj.sole_sites):
        np.testing.assert_allclose(
            model.geom_size[geom], [SOLE_LENGTH / 2, SOLE_WIDTH / 2, SOLE_THICKNESS / 2]
        )
        # bottom face centre on the sole frame
        bottom = data.geom_xpos[geom] - data.geom_xmat[geom].reshape(3, 3)[:, 2] * SOLE_THICKNESS / 2
        np.testing.assert_allclose(bottom, data.site_xpos[site], atol=1e-12)


def test_inverse_dynamics_agree_with_pinocchio(robots):
    """At rest, MuJoCo's joint torques for an acceleration (armature included) equal Pinocchio's rnea."""
    mj, talos = robots
    model, pm = mj.model, talos.model
    pdata, data = pm.createData(), mujoco.MjData(model)
    saved = model.opt.disableflags
    # the URDF's joint damping and friction, which rnea leaves out
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_DAMPER
    try:
        rng = np.random.default_rng(0)
        for q in _random_configurations(pm, 3, seed=5):
            a = rng.normal(size=38)
            tau = pin.rnea(pm, pdata, q, np.zeros(38), a)
            data.qpos[:] = mj.qpos_from_pin(q)
            data.qvel[:] = 0.0
            data.qacc[:] = mj.qvel_from_pin_at(q, a)  # at rest the two accelerations differ by the frame
            mujoco.mj_inverse(model, data)
            np.testing.assert_allclose(
                data.qfrc_inverse[mj.dof_index], tau[6:], atol=1e-6 * np.abs(tau).max()
            )
    finally:
        model.opt.disableflags = saved


def test_scene_holds_terrain_and_robot():
    from leas_jax.terrain import load_terrain
    from leas_jax.terrain.export import terrain_to_mjcf

    terrain = load_terrain("terrains/eval_ground.toml")
    mj = scene_model(terrain_to_mjcf(terrain), 0.001)
    assert mj.model.opt.timestep == 0.001
    assert mj.model.ngeom == talos_mujoco().model.ngeom + len(terrain.boxes) + len(terrain.meshes)
    terrain_geoms = [g for g in range(mj.model.ngeom) if mj.model.geom_bodyid[g] == 0]
    assert len(terrain_geoms) == len(terrain.boxes) + len(terrain.meshes)
