"""Analytic leg IK against Pinocchio's forward kinematics."""

import numpy as np
import pinocchio as pin
import pytest

from leas_jax.contacts.robot.ik import leg_fk, leg_ik, leg_ik_single, within_limits
from leas_jax.contacts.robot.model import load_talos, rotz


@pytest.fixture(scope="module")
def talos():
    return load_talos()


@pytest.mark.parametrize("side", [0, 1])
def test_ik_hits_pinocchio_fk_targets(talos, side):
    """Random leg configurations within limits: Pinocchio FK gives a sole placement in
    the root frame (root moved and turned); the IK must reproduce it within 1 mm / 1 deg
    (it is exact: 1e-9)."""
    leg = talos.legs[side]
    rng = np.random.default_rng(side)
    root_R = rotz(0.7)
    root_p = np.array([0.3, -1.2, 1.0])
    q_true = rng.uniform(leg.lower, leg.upper, size=(200, 6))
    rot, pos = np.empty((200, 3, 3)), np.empty((200, 3))
    for k, joints in enumerate(q_true):
        q = talos.configuration(root_p, root_R, np.zeros((2, 6)))
        q[leg.q_index] = joints
        pin.framesForwardKinematics(talos.model, talos.data, q)
        oMf = talos.data.oMf[talos.sole_frame_ids[side]]
        rot[k] = root_R.T @ oMf.rotation
        pos[k] = root_R.T @ (oMf.translation - root_p)
    q_ik, reachable = leg_ik(leg, rot, pos)
    assert reachable.all() and within_limits(leg, q_ik).all()
    # Unique solution within the limits (knee >= 0, |roll| < pi/2).
    np.testing.assert_allclose(q_ik, q_true, atol=1e-7)
    for k in range(0, 200, 10):
        q = talos.configuration(root_p, root_R, np.zeros((2, 6)))
        q[leg.q_index] = q_ik[k]
        pin.framesForwardKinematics(talos.model, talos.data, q)
        oMf = talos.data.oMf[talos.sole_frame_ids[side]]
        assert np.linalg.norm(oMf.translation - (root_p + root_R @ pos[k])) < 1e-9
        assert np.linalg.norm(pin.log3(oMf.rotation.T @ root_R @ rot[k])) < 1e-9
        np.testing.assert_allclose(leg_ik_single(leg, rot[k], pos[k]), q_ik[k], atol=1e-12)


def test_leg_fk_matches_pinocchio(talos):
    rng = np.random.default_rng(3)
    for side in (0, 1):
        leg = talos.legs[side]
        joints = rng.uniform(leg.lower, leg.upper, size=(20, 6))
        rot, pos = leg_fk(leg, joints)
        for k in range(20):
            q = talos.q_ref.copy()
            q[leg.q_index] = joints[k]
            pin.framesForwardKinematics(talos.model, talos.data, q)
            oMf = talos.data.oMf[talos.sole_frame_ids[side]]
            np.testing.assert_allclose(oMf.translation, pos[k], atol=1e-12)
            np.testing.assert_allclose(oMf.rotation, rot[k], atol=1e-12)


def test_unreachable_and_limits(talos):
    leg = talos.legs[0]
    # 1.2 m below the hip: beyond thigh + shin + sole (0.812 m).
    far = leg.hip_offset + np.array([0.0, 0.0, -1.2])
    _, reachable = leg_ik(leg, np.eye(3)[None], far[None])
    assert not reachable[0]
    assert leg_ik_single(leg, np.eye(3), far) is None
    # Sole turned inward by 0.6 rad: the hip yaw limit is 0.35 rad inward for the left leg.
    nominal = talos.nominal_sole_in_root[0]
    assert leg_ik_single(leg, rotz(-0.6), nominal) is None
    assert leg_ik_single(leg, rotz(0.6), nominal) is not None  # outward is allowed
    # Half-sitting is recovered from its own sole placement.
    pin.framesForwardKinematics(talos.model, talos.data, talos.q_ref)
    oMf = talos.data.oMf[talos.sole_frame_ids[0]]
    q = leg_ik_single(leg, oMf.rotation, oMf.translation)
    np.testing.assert_allclose(q, talos.q_ref[leg.q_index], atol=1e-9)


def test_ik_speed_single(talos):
    """The hot path: one leg solve well under 100 us (typically ~5 us)."""
    import time

    leg = talos.legs[1]
    target = talos.nominal_sole_in_root[1] + np.array([0.1, 0.0, 0.05])
    start = time.perf_counter()
    for _ in range(2000):
        leg_ik_single(leg, rotz(0.1), target)
    assert (time.perf_counter() - start) / 2000 < 1e-4
