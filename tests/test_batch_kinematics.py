"""check-plan's kinematics on many lines at once agree with pinocchio's, one line at a time:
joint and frame placements, centre of mass, generalized gravity and frame Jacobians."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from planner.verify.batch_kinematics import BatchKinematics, PinConfigurations
from robot.params import robot_params
from robot.urdf import robot_urdf


@pytest.fixture(scope="module", params=["drc-hubo", "hubo2plus"])
def model(request):
    return pin.buildModelFromXML(robot_urdf(robot_params(request.param)),
                                 pin.JointModelFreeFlyer())


def _configurations(model, n: int = 6) -> np.ndarray:
    np.random.seed(3)  # pinocchio's randomConfiguration draws from numpy's global generator
    return np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                     for _ in range(n)])


def test_placements_com_gravity_and_jacobians_match_pinocchio(model):
    data = model.createData()
    kin = BatchKinematics(model)
    qs = _configurations(model)
    R_base = np.array([pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix() for q in qs])
    poses = kin.joint_poses(qs, R_base, qs[:, :3])
    com, grav = kin.com(poses), kin.gravity_torques(poses)
    palm = model.getFrameId("R_palm")
    frame = model.frames[palm]
    R_f, p_f = poses.frame(frame.parentJoint, frame.placement.rotation,
                           frame.placement.translation)
    jac = kin.frame_jacobian(poses, frame.parentJoint, p_f)
    for i, q in enumerate(qs):
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        for j in range(model.njoints):
            np.testing.assert_allclose(poses.R[i, j], data.oMi[j].rotation, atol=1e-12)
            np.testing.assert_allclose(poses.p[i, j], data.oMi[j].translation, atol=1e-12)
        np.testing.assert_allclose(R_f[i], data.oMf[palm].rotation, atol=1e-12)
        np.testing.assert_allclose(jac[i], pin.getFrameJacobian(
            model, data, palm, pin.LOCAL_WORLD_ALIGNED), atol=1e-12)
        np.testing.assert_allclose(com[i], pin.centerOfMass(model, data, q), atol=1e-12)
        np.testing.assert_allclose(grav[i], pin.computeGeneralizedGravity(model, data, q),
                                   atol=1e-9)


def test_a_chain_alone_and_the_configurations_for_pinocchio(model):
    kin = BatchKinematics(model)
    qs = _configurations(model, 3)
    R = np.array([pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix() for q in qs])
    whole = kin.joint_poses(qs, R, qs[:, :3])
    foot = model.frames[model.getFrameId("L_sole")].parentJoint
    chain = kin.joint_poses(qs, R, qs[:, :3], upto=foot)
    np.testing.assert_allclose(chain.R[:, foot], whole.R[:, foot], atol=1e-12)
    np.testing.assert_allclose(chain.p[:, foot], whole.p[:, foot], atol=1e-12)
    configs = PinConfigurations(qs, R, qs[:, :3])
    data = model.createData()
    for i in range(len(qs)):
        pin.forwardKinematics(model, data, configs[i])
        np.testing.assert_allclose(data.oMi[foot].translation, whole.p[i, foot], atol=1e-12)
    assert len(configs.subset(np.array([0, 2]))) == 2


def test_only_revolute_joints_after_the_free_flyer():
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    model.addJoint(j, pin.JointModelPX(), pin.SE3.Identity(), "slider")
    with pytest.raises(ValueError, match="slider is a JointModelPX"):
        BatchKinematics(model)
