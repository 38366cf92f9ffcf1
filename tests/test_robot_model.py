"""The parametric models: mass, limits, and URDF/MJCF agreement."""

import io

import mujoco
import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

from robot.joints import JOINT_NAMES
from robot.kinematic_tree import build_tree
from robot.limits import joint_limits
from robot.mjcf import joint_qpos_addresses, robot_spec
from robot.params import DRC_HUBO, HUBO2PLUS, robot_params
from robot.urdf import robot_urdf

FRAMES = ("L_palm", "R_palm", "L_sole", "R_sole", "imu", "torso_frame")


@pytest.mark.parametrize("params, published_kg", [(DRC_HUBO, 44.4), (HUBO2PLUS, 40.8)])
def test_total_mass_matches_published(params, published_kg):
    model = pin.buildModelFromXML(robot_urdf(params), pin.JointModelFreeFlyer())
    mass = pin.computeTotalMass(model)
    assert mass == pytest.approx(params.total_mass_kg, rel=1e-9)
    assert mass == pytest.approx(published_kg, rel=0.02)
    mj = robot_spec(params).compile()
    assert mj.body_subtreemass[1] == pytest.approx(mass, rel=1e-6)


def test_zero_pose_com_matches_published():
    model = pin.buildModelFromXML(robot_urdf("drc-hubo"), pin.JointModelFreeFlyer())
    data = model.createData()
    q = pin.neutral(model)
    q[2] = DRC_HUBO.pelvis_height_m
    com = pin.centerOfMass(model, data, q)
    np.testing.assert_allclose(com, [0.007, -0.001, 0.735], atol=0.015)


def test_soles_on_floor_in_zero_pose():
    assert DRC_HUBO.pelvis_height_m == pytest.approx(0.968, abs=1e-9)
    model = pin.buildModelFromXML(robot_urdf("drc-hubo"), pin.JointModelFreeFlyer())
    data = model.createData()
    q = pin.neutral(model)
    q[2] = DRC_HUBO.pelvis_height_m
    pin.framesForwardKinematics(model, data, q)
    for frame in ("L_sole", "R_sole"):
        assert data.oMf[model.getFrameId(frame)].translation[2] == pytest.approx(0.0, abs=1e-12)


def test_joint_limits_match_table():
    lim = joint_limits("drc-hubo")
    expect = {"RHY": (-1.92, 1.92), "LHR": (-0.52, 0.52), "RHP": (-1.57, 1.57),
              "LKN": (0, 2.61), "RAP": (-1.70, 1.70), "LAR": (-1.57, 1.57),
              "RSP": (-3.14, 3.14), "RSR": (-3.14, 0.26), "LSR": (-0.26, 3.14),
              "RSY": (-3.14, 2.0), "LSY": (-2.0, 3.14), "REB": (-2.65, 0), "LEB": (-2.65, 0),
              "RWY": (-3.14, 3.14), "LWP": (-3.14, 3.14), "WST": (-3.14, 3.14),
              "RF3": (-3.14, 3.14)}
    for name, (lo, hi) in expect.items():
        k = JOINT_NAMES.index(name)
        assert (lim.lower_rad[k], lim.upper_rad[k]) == (lo, hi), name
    torque = dict(zip(JOINT_NAMES, lim.torque_max_nm, strict=True))
    assert torque["RKN"] == 60 and torque["LHR"] == 34 and torque["REB"] == 23
    assert torque["LWP"] == 8.9 and torque["RWR"] == 4.8 and torque["NKY"] == 0.9
    speed = dict(zip(JOINT_NAMES, lim.velocity_max_rad_s, strict=True))
    assert speed["RKN"] == 7 and speed["LSP"] == 6 and speed["RF1"] == 10


def test_hubo2plus_has_no_wrist_roll_but_keeps_its_column():
    lim = joint_limits("hubo2plus")
    k = JOINT_NAMES.index("RWR")
    assert lim.lower_rad[k] == lim.upper_rad[k] == 0.0
    assert "RWR" not in build_tree(HUBO2PLUS).joint_links
    assert lim.upper_rad[JOINT_NAMES.index("LKN")] == 2.60


@pytest.mark.parametrize("robot", ["drc-hubo", "hubo2plus"])
def test_urdf_loads_in_yourdfpy_and_placo(robot):
    import placo

    urdf = robot_urdf(robot)
    assert len(yourdfpy.URDF.load(io.StringIO(urdf)).actuated_joint_names) == len(
        build_tree(robot_params(robot)).joint_links)
    wrapper = placo.RobotWrapper("", placo.Flags.ignore_collisions, urdf)
    wrapper.update_kinematics()
    assert wrapper.get_T_world_frame("L_palm").shape == (4, 4)


@pytest.mark.parametrize("robot", ["drc-hubo", "hubo2plus"])
def test_urdf_and_mjcf_agree_on_forward_kinematics(robot):
    """Palm, sole, IMU frames agree to 1e-6 m over random configurations and base poses."""
    model = pin.buildModelFromXML(robot_urdf(robot), pin.JointModelFreeFlyer())
    data = model.createData()
    mj = robot_spec(robot).compile()
    mjd = mujoco.MjData(mj)
    qadr = joint_qpos_addresses(mj)
    rng = np.random.default_rng(7)
    for _ in range(25):
        q = pin.randomConfiguration(model)
        q[:3] = rng.uniform(-1, 1, 3)
        quat = rng.normal(size=4)
        quat /= np.linalg.norm(quat)
        q[3:7] = quat  # pinocchio: x y z w
        pin.framesForwardKinematics(model, data, q)
        mjd.qpos[:3] = q[:3]
        mjd.qpos[3:7] = [quat[3], quat[0], quat[1], quat[2]]  # mujoco: w x y z
        for j in range(2, model.njoints):
            name = model.names[j]
            mjd.qpos[qadr[name]] = q[model.joints[j].idx_q]
        mujoco.mj_kinematics(mj, mjd)
        for frame in FRAMES:
            oMf = data.oMf[model.getFrameId(frame)]
            sid = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SITE, frame)
            np.testing.assert_allclose(mjd.site_xpos[sid], oMf.translation, atol=1e-6)
            np.testing.assert_allclose(mjd.site_xmat[sid].reshape(3, 3), oMf.rotation,
                                       atol=1e-6)


def test_robot_scene_stands_still_in_position_mode():
    mj = robot_spec("drc-hubo").compile()
    d = mujoco.MjData(mj)
    mujoco.mj_resetDataKeyframe(mj, d, 0)
    z0 = d.qpos[2]
    for _ in range(int(2.0 / mj.opt.timestep)):
        mujoco.mj_step(mj, d)
    assert abs(d.qpos[2] - z0) < 0.01
    tilt = 2 * np.arccos(min(1.0, abs(d.qpos[3])))
    assert tilt < np.radians(1.0)
    assert all(d.warning[i].number == 0 for i in range(len(d.warning)))
