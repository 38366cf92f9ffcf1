"""A closed grip's load from the arm's motor currents (`execute.motion.grip_load`)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from make_fixture import cached_reach_fixture  # noqa: E402
from test_grasp_latch import _hold, _holding_ref  # noqa: E402

from execute.motion.grip_load import GripLoad  # noqa: E402
from execute.motion.robot_model import MotionRobotModel  # noqa: E402
from execute.validate.simulate import SimulationOptions, simulate  # noqa: E402
from ladders.loader import sidecar_ladder  # noqa: E402
from robot.joints import JOINT_INDEX, NUM_JOINTS  # noqa: E402
from robot.plan_sidecar import read_sidecar, sidecar_path  # noqa: E402
from robot.trajectory_file import read_trajectory  # noqa: E402


@pytest.fixture(scope="module")
def model():
    return MotionRobotModel()


def test_the_wrench_is_what_the_arms_torques_hold_against_gravity(model):
    """τ = g − Jᵀw for a known palm wrench w: the estimate gives w back (frame, sign)."""
    import pinocchio as pin

    q = np.zeros(NUM_JOINTS)
    q[JOINT_INDEX["RSP"]], q[JOINT_INDEX["RSR"]], q[JOINT_INDEX["REB"]] = -1.2, -0.2, -0.8
    q[JOINT_INDEX["RWY"]], q[JOINT_INDEX["RWP"]] = 0.3, -0.4
    R = pin.rpy.rpyToMatrix(0.05, -0.1, 0.3)
    wrench = np.array([12.0, -30.0, 55.0, 1.5, -2.0, 0.7])
    chain = model.chains["right_hand"]
    d = model._kinematics_at(q, R)
    J = pin.getFrameJacobian(model.model, d, model.model.getFrameId(chain.frame),
                             pin.LOCAL_WORLD_ALIGNED)
    tau = model.gravity_torques(q, R)
    arm = np.array(chain.columns)
    tau[arm] -= (J.T @ wrench)[model._v_of_col[arm]]
    assert model.hand_wrench(q, R, "right_hand", tau) == pytest.approx(wrench, abs=1e-6)


@pytest.fixture(scope="module")
def held_run(tmp_path_factory):
    """The reach fixture played to its end: both hands latched on their rails."""
    path = cached_reach_fixture(tmp_path_factory.getbasetemp())
    sc = read_sidecar(sidecar_path(path))
    ladder = sidecar_ladder(sc, str(path))
    run = simulate(read_trajectory(path, sc.rate_hz), sc, ladder,
                   SimulationOptions(strategy="mixed", record_qpos=False))
    return run, ladder


@pytest.mark.parametrize("push_n", [(0.0, 0.0, 0.0), (40.0, 0.0, -60.0), (0.0, 50.0, -30.0)])
def test_the_estimated_grip_load_is_the_latchs(model, held_run, push_n):
    """Pushing the body loads both grips; the estimate from currents, encoders and the
    body's tilt agrees with the latch's wrench on each closed hand, as a share of what the
    grip holds."""
    run, ladder = held_run
    board = run.board
    pelvis = board.model.body("pelvis").id
    board.data.xfrc_applied[pelvis, :3] = push_n
    try:
        assert not _hold(run, 300, _holding_ref(board))  # 0.75 s: no grip lets go
        s = board.state()
        R = board.data.body("pelvis").xmat.reshape(3, 3)
        loads = GripLoad(model, ladder.friction, ladder.rail_radius_m)
        for side, latch in board.latches.items():
            assert latch.latched
            force, torque = latch.grip_load()
            axis = latch._rail_axis(latch.rail)
            truth = latch.capacity.utilisation(force, torque, axis)
            share, _load = loads.release_share(side, s.pos_rad, R,
                                               board.motors.torque_nm(s.cur_a), axis)
            assert share == pytest.approx(max(truth["radial force"], truth["bending torque"]),
                                          abs=0.02)
    finally:
        board.data.xfrc_applied[pelvis] = 0.0
