"""Lock-step simulation: the scene steps cleanly; a wrist-roll trip drops the grip."""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from make_fixture import cached_reach_fixture  # noqa: E402

from daemon.joint_control import JointController  # noqa: E402
from daemon.pwm import default_drc_gains  # noqa: E402
from daemon.sim.board_model import BoardModel, PlacementError  # noqa: E402
from execute.validate.plan_compare import compare_with_plan  # noqa: E402
from execute.validate.simulate import SimulationOptions, simulate  # noqa: E402
from ladders.loader import BUNDLED_LADDERS, load_ladder, sidecar_ladder  # noqa: E402
from robot.errors import InputError  # noqa: E402
from robot.joints import JOINT_INDEX, NUM_JOINTS  # noqa: E402
from robot.plan_sidecar import read_sidecar, sidecar_path  # noqa: E402
from robot.trajectory_file import read_trajectory  # noqa: E402


def _warnings(data: mujoco.MjData) -> list[int]:
    # integer indices only: indexing data.warning with a string crashes the interpreter
    return [int(data.warning[i].number) for i in range(len(data.warning))]


@pytest.mark.parametrize("ladder", BUNDLED_LADDERS)
def test_scene_steps_one_second_without_warnings(ladder):
    board = BoardModel(load_ladder(ladder))
    ctl = JointController()
    gains = default_drc_gains()
    for _ in range(200):
        out = ctl.tick(np.zeros(NUM_JOINTS), 0, np.zeros(NUM_JOINTS, bool), board.joint_pos(),
                       board.joint_vel(), gains)
        board.apply(out)
        board.step()
    assert _warnings(board.data) == [0] * len(board.data.warning)
    assert board.data.qpos[2] == pytest.approx(0.968, abs=0.01)  # still standing


@pytest.fixture(scope="module")
def plan(tmp_path_factory):
    path = cached_reach_fixture(tmp_path_factory.getbasetemp())
    sc = read_sidecar(sidecar_path(path))
    return read_trajectory(path, sc.rate_hz), sc, sidecar_ladder(sc, str(path))


def test_fixture_climbs_in_mixed_without_warnings(plan):
    traj, sc, ladder = plan
    run = simulate(traj, sc, ladder, SimulationOptions(strategy="mixed"))
    assert run.verdict.climbed, run.verdict
    assert _warnings(run.board.data) == [0] * len(run.board.data.warning)
    assert run.log.pwm[-1, JOINT_INDEX["LSP"]] and not run.log.pwm[0, JOINT_INDEX["LSP"]]
    # the weld holds: the palm stays put while latched
    lat = run.log.latched[:, 0]
    assert lat[-1]


def test_a_stiff_arm_fights_a_grip_closed_off_centre_and_a_compliant_one_gives_way(plan):
    """The ladder 3 cm further than planned: both hands still close within the 2 cm
    tolerance (1.7 cm off the axis with rigid arms), and the closed fingers pull the rail
    into the grip centre. Rigid arms fight that pull up to an arm joint's torque limit;
    the mixed strategy's PWM arms give way."""
    traj, sc, ladder = plan
    misplaced = PlacementError(dx_m=0.03)
    arms = [JOINT_INDEX[n] for n in ("LSP", "LSR", "LSY", "LEB", "RSP", "RSR", "RSY", "REB")]
    peak = {}
    for strategy in ("position", "mixed"):
        run = simulate(traj, sc, ladder, SimulationOptions(strategy=strategy,
                                                           placement=misplaced))
        assert [g.kind for g in run.log.grasps] == ["latched", "latched"], run.log.grasps
        limit = run.board.trips.torque_max_nm[arms]
        peak[strategy] = float((np.abs(run.log.torque_nm[:, arms]) / limit).max())
    assert peak["position"] >= 0.99 > 0.8 > peak["mixed"]


def test_wrist_roll_trip_drops_the_fingers(plan):
    traj, sc, ladder = plan
    traj = traj.copy()
    # After the grasp, twist the left wrist roll against the rail it holds (rigid arms):
    # the welded hand cannot turn, LWR sits at its 4.8 N·m limit and EJMC5 trips.
    j = JOINT_INDEX["LWR"]
    hold = sc.segments[-1]
    first = hold.first_line + 5
    ramp = np.clip((np.arange(len(traj)) - first) / 10, 0, 1) * 0.4
    traj[:, j] += ramp
    run = simulate(traj, sc, ladder, SimulationOptions(strategy="position",
                                                       record_qpos=False))
    f = run.verdict.failure
    assert f is not None and f.cause == "board_trip"
    assert f.details["board"] == "EJMC5" and f.details["joint"] == "LWR"
    assert "fingers" in f.why
    released = [g for g in run.log.grasps if g.kind == "released"]
    assert released and released[0].hand == "left" and "finger board" in released[0].reason
    assert not run.board.state().active[JOINT_INDEX["LF1"]]
    assert f.time_s > run.board.latches["left"].config.slip_persistence_s
    # against the plan, the twisted wrist departs most (roll and yaw, both near their
    # limits), the roll at its limit: the torque of the tick before the trip, not the
    # unpowered board's zero
    c = compare_with_plan(run, traj, ladder)
    top = {j.joint: j for j in c.joints[:2]}
    assert c.line == f.line and set(top) == {"LWR", "LWY"}
    assert abs(top["LWR"].simulated_nm) == pytest.approx(top["LWR"].limit_nm, rel=0.02)
    assert abs(top["LWR"].planned_nm) < 0.5 * top["LWR"].limit_nm


def test_placement_error_parsing():
    assert PlacementError.parse("0.03,-0.01,0.05") == PlacementError(0.03, -0.01, 0.05)
    for bad in ("0.03,0", "a,b,c", "5,0,0", "nan,0,0"):
        with pytest.raises(InputError, match="placement-error"):
            PlacementError.parse(bad)


def test_unknown_strategy_refused():
    with pytest.raises(InputError, match="strategy"):
        SimulationOptions(strategy="stiff")
