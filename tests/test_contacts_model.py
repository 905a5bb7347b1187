"""Talos model for the contact generator: constants measured from the model, conversions."""

import numpy as np
import pinocchio as pin
import pytest

from leas_jax.contacts.robot import model as M


@pytest.fixture(scope="module")
def talos():
    return M.load_talos()


def test_model_shape_and_reference(talos):
    assert talos.model.nq == 39 and talos.model.nv == 38
    assert talos.q_ref.shape == (39,)
    # Root at the origin with identity orientation (xyzw: w last).
    np.testing.assert_array_equal(talos.q_ref[:7], [0, 0, 0, 0, 0, 0, 1])
    assert M.load_talos() is talos  # cached once per process


def test_the_model_parses_the_urdf_once(talos, monkeypatch):
    """Building the model reads Talos's URDF (and its meshes) once, the slowest part of a
    contact worker's start-up; its paths are those of the one loader."""
    calls = []
    build = pin.RobotWrapper.BuildFromURDF

    def counted(*args, **kwargs):
        calls.append(args[0])
        return build(*args, **kwargs)

    monkeypatch.setattr(pin.RobotWrapper, "BuildFromURDF", staticmethod(counted))
    fresh = M.TalosModel()
    assert calls == [fresh.urdf_path]
    assert fresh.urdf_path == talos.urdf_path and fresh.srdf_path.endswith("talos.srdf")
    assert fresh.file_digest == talos.file_digest and fresh.mass == talos.mass


def test_nominal_root_height_is_measured_from_half_sitting(talos):
    # Half-sitting from the model with the root put back at its reference height:
    # both soles at z = 0, so the base height is NOMINAL_ROOT_HEIGHT.
    q = talos.q_ref.copy()
    q[2] = talos.ref_root_height
    soles = talos.sole_placements(q)
    assert np.allclose(soles[:, 2], 0.0, atol=1e-4)
    assert talos.ref_root_height == pytest.approx(M.NOMINAL_ROOT_HEIGHT, abs=1e-6)
    assert 1.0 < M.NOMINAL_ROOT_HEIGHT < 1.1
    # Soles at half-sitting: flat within 0.1 deg (ankle roll -0.0017 rad), 0.17 m apart.
    np.testing.assert_allclose(soles[:, 3:], [[0, 0, 0, 1], [0, 0, 0, 1]], atol=1e-3)
    assert soles[0, 1] - soles[1, 1] == pytest.approx(0.17, abs=0.002)


def test_leg_constants(talos):
    left, right = talos.legs
    assert (left.thigh, left.shin, left.sole_depth) == pytest.approx((0.38, 0.325, 0.107))
    np.testing.assert_allclose(left.hip_offset * [1, -1, 1], right.hip_offset)
    assert list(left.q_index) == list(range(7, 13)) and list(right.q_index) == list(range(13, 19))


def test_quaternion_conversion_matches_pinocchio():
    rng = np.random.default_rng(0)
    for _ in range(50):
        rot = pin.Quaternion(*rng.normal(size=4)).normalized().toRotationMatrix()
        quat = M.quat_xyzw_from_matrix(rot)
        quat_pin = pin.SE3ToXYZQUAT(pin.SE3(rot, np.zeros(3)))[3:]
        if quat_pin[3] < 0:
            quat_pin = -quat_pin
        np.testing.assert_allclose(quat, quat_pin, atol=1e-12)
        np.testing.assert_allclose(M.quat_xyzw_from_matrix_single(rot), quat, atol=1e-12)
        np.testing.assert_allclose(M.matrix_from_quat_xyzw(quat), rot, atol=1e-12)


def test_configuration_places_root(talos):
    rot = M.rotz(0.3)
    q = talos.configuration(np.array([1.0, 2.0, 1.0]), rot, np.zeros((2, 6)))
    oMroot = pin.XYZQUATToSE3(q[:7])
    np.testing.assert_allclose(oMroot.rotation, rot, atol=1e-12)
    np.testing.assert_allclose(q[7:19], 0.0)
    np.testing.assert_allclose(q[19:], talos.q_ref[19:])  # upper body at half-sitting


def test_arms_in_posture_is_narrower_within_limits_and_free_of_self_collision(talos):
    """The arms held in (`UPPER_BODY_POSTURES["arms_in"]`): mirrored, within the joint limits,
    free of self-collision on the SRDF's pairs, its arm and gripper boxes 0.1 m or more
    nearer the root's x axis than at half-sitting."""
    import itertools

    arms_in = talos.upper_refs["arms_in"]
    np.testing.assert_array_equal(talos.upper_refs["half_sitting"], talos.q_ref)
    assert talos.joint_limit_violations(arms_in) == []

    def joint(q, name):
        return q[talos.model.joints[talos.model.getJointId(name)].idx_q]

    for name, value in M.UPPER_BODY_POSTURES["arms_in"].items():
        assert joint(arms_in, name) == value != joint(talos.q_ref, name)
    assert joint(arms_in, "arm_right_2_joint") == -joint(arms_in, "arm_left_2_joint")
    assert joint(arms_in, "arm_right_4_joint") == joint(arms_in, "arm_left_4_joint")
    geom_model = talos.geom_model.copy()
    geom_model.addAllCollisionPairs()
    pin.removeCollisionPairs(talos.model, geom_model, talos.srdf_path)
    geom_data = pin.GeometryData(geom_model)
    data = talos.model.createData()

    def widest_arm(q):
        pin.updateGeometryPlacements(talos.model, data, geom_model, geom_data, q)
        widest = 0.0
        for g, obj in enumerate(geom_model.geometryObjects):
            if obj.name.startswith(("arm_", "gripper_")):
                obj.geometry.computeLocalAABB()
                box = zip(obj.geometry.aabb_local.min_, obj.geometry.aabb_local.max_)
                corners = np.array(list(itertools.product(*box)))
                world = corners @ geom_data.oMg[g].rotation.T + geom_data.oMg[g].translation
                widest = max(widest, float(np.abs(world[:, 1]).max()))
        return widest

    assert widest_arm(arms_in) < widest_arm(talos.q_ref) - 0.1
    assert not pin.computeCollisions(talos.model, data, geom_model, geom_data, arms_in, False)
    q = talos.configuration(np.array([1.0, 2.0, 1.0]), M.rotz(0.3), np.zeros((2, 6)), "arms_in")
    np.testing.assert_allclose(q[19:], arms_in[19:])


def test_upper_body_posture_outside_the_limits_is_refused(talos):
    with pytest.raises(ValueError, match="arm_left_2_joint = -0.5 is outside"):
        M.upper_body_reference(talos.model, talos.q_ref, {"arm_left_2_joint": -0.5})
    with pytest.raises(ValueError, match="no joint 'arm_left_9_joint'"):
        M.upper_body_reference(talos.model, talos.q_ref, {"arm_left_9_joint": 0.0})


def test_joint_limit_violations(talos):
    q = talos.q_ref.copy()
    assert talos.joint_limit_violations(q) == []
    idx = talos.model.joints[talos.model.getJointId("arm_left_4_joint")].idx_q
    q[idx] = talos.upper[idx] + 0.1
    names = [v[0] for v in talos.joint_limit_violations(q)]
    assert names == ["arm_left_4_joint"]
