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


def test_joint_limit_violations(talos):
    q = talos.q_ref.copy()
    assert talos.joint_limit_violations(q) == []
    idx = talos.model.joints[talos.model.getJointId("arm_left_4_joint")].idx_q
    q[idx] = talos.upper[idx] + 0.1
    names = [v[0] for v in talos.joint_limit_violations(q)]
    assert names == ["arm_left_4_joint"]
