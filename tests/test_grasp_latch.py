"""The grasp latch: latches on the rail, not off it; lets go on opening, overload, trip."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from make_fixture import cached_reach_fixture  # noqa: E402

from daemon.board_model import PlacementError  # noqa: E402
from daemon.grasp_latch import GripCapacity, GripConfig  # noqa: E402
from daemon.joint_control import JointController  # noqa: E402
from daemon.pwm import default_drc_gains  # noqa: E402
from execute.simulate import SimulationOptions, simulate  # noqa: E402
from ladders.spec import LadderSpec  # noqa: E402
from robot.joints import FINGER_JOINTS, JOINT_INDEX, NUM_JOINTS  # noqa: E402
from robot.plan_sidecar import read_sidecar, sidecar_path  # noqa: E402
from robot.trajectory_file import read_trajectory  # noqa: E402


@pytest.fixture(scope="module")
def plan(tmp_path_factory):
    path = cached_reach_fixture(tmp_path_factory.getbasetemp())
    sc = read_sidecar(sidecar_path(path))
    return read_trajectory(path, sc.rate_hz), sc, LadderSpec(**sc.ladder)


@pytest.fixture(scope="module")
def latched_run(plan):
    traj, sc, ladder = plan
    return simulate(traj, sc, ladder, SimulationOptions(strategy="mixed", record_qpos=False))


def _hold(run, ticks: int, ref: np.ndarray, extra=None) -> list:
    """Keep stepping a finished run's board with the control law at ``ref``."""
    board = run.board
    ctl = JointController()
    gains = default_drc_gains()
    comply = np.zeros(NUM_JOINTS, dtype=bool)
    events = []
    for k in range(ticks):
        if extra is not None:
            extra(k)
        out = ctl.tick(ref, 0, comply, board.joint_pos(), board.joint_vel(), gains)
        board.apply(out)
        events += board.step()[1]
    return events


def test_capacity_from_finger_torque():
    cap = GripCapacity.of(GripConfig(), friction=0.4, rail_radius_m=0.025)
    assert cap.radial_n == pytest.approx(5 * 5.0 / 0.06)
    assert cap.axial_n == pytest.approx(2 * 0.4 * cap.radial_n)
    axis = np.array([0.0, 0.0, 1.0])
    u, what = cap.utilisation(np.array([cap.radial_n * 1.5, 0, 0]), np.zeros(3), axis)
    assert u == pytest.approx(1.5) and what == "radial force"


def test_latches_on_the_rail(latched_run):
    latched = [g for g in latched_run.log.grasps if g.kind == "latched"]
    assert {g.hand for g in latched} == {"left", "right"}
    for g in latched:
        assert g.rail == f"rail_{g.hand}"
        assert g.distance_m <= 0.02 and g.angle_rad <= np.radians(20)
    assert latched_run.board.latches["left"].latched


def test_palm_off_the_rail_grasps_nothing(plan):
    traj, sc, ladder = plan
    # ladder 11.5 cm further away: the rails sit ≈ 10 cm beyond the closing palms
    run = simulate(traj, sc, ladder, SimulationOptions(
        strategy="position", placement=PlacementError(0.115, 0.0, 0.0), record_qpos=False))
    assert not any(g.kind == "latched" for g in run.log.grasps)
    missed = [g for g in run.log.grasps if g.kind == "missed"]
    assert missed and all(0.08 < g.distance_m < 0.12 for g in missed)
    assert run.verdict.failure.cause == "grasp_not_latched"


def test_releases_when_fingers_open(latched_run, plan):
    ref = latched_run.board.joint_pos()
    ref[[JOINT_INDEX[f] for f in FINGER_JOINTS["left"]]] = 0.0
    events = _hold(latched_run, 200, ref)
    assert any(g.kind == "released" and g.hand == "left" and "open" in g.reason
               for g in events)
    assert not latched_run.board.latches["left"].latched
    assert latched_run.board.latches["right"].latched


def test_releases_over_load(plan):
    traj, sc, ladder = plan
    run = simulate(traj, sc, ladder, SimulationOptions(strategy="mixed", record_qpos=False))
    board = run.board
    hand = board.latches["right"].body_id
    cap = board.latches["right"].capacity
    ref = board.joint_pos()
    # below capacity: holds
    board.data.xfrc_applied[hand, :3] = (0.0, 0.0, -0.5 * cap.radial_n)
    assert not _hold(run, 40, ref)
    # a pull of twice the radial capacity, away from the rail: it lets go
    board.data.xfrc_applied[hand, :3] = (0.0, 0.0, -2.0 * cap.radial_n)
    events = _hold(run, 40, ref)
    board.data.xfrc_applied[:] = 0.0
    rel = [g for g in events if g.kind == "released"]
    assert rel and rel[0].hand == "right" and "what the grip holds" in rel[0].reason
