"""Lock-step simulation: player → per-joint control law → MuJoCo board model.

One loop iteration is one 5 ms daemon tick, run as fast as the CPU allows:

1. the boards report (encoders, velocities);
2. the `execute.play.player.TrajectoryPlayer` gives the reference, modes and compliance for
   ``n · 5 ms``;
3. the `daemon.joint_control.JointController` (the code the daemon runs) turns them
   into sent references and PWM duties, the compliant arms' feed-forward torques (the
   sidecar's `ArmFeedforward`) into feed-forward duty at the board's battery voltage;
4. the `daemon.sim.board_model.BoardModel` applies them and steps the physics one tick;
5. the `execute.validate.verdict.VerdictMonitor` checks for a failure.

Strategies (how the arms are driven; legs, waist, neck and fingers are always in
position mode):

- ``mixed``: the sidecar's per-arm schedule (the thesis's best strategy);
- ``position``: both arms rigid throughout;
- ``pwm``: both arms compliant throughout (PWM with the DRC default gains).

The robot starts at rest in the pose of line 1, soles on the floor where the plan's
first segment puts them.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np

from daemon.joint_control import JointController
from daemon.pwm import PwmGains, default_drc_gains
from daemon.sim.board_model import TICK_S, BoardModel, BoardModelConfig, PlacementError
from daemon.sim.board_trip import TripEvent
from daemon.sim.grasp_latch import GraspEvent
from execute.play.player import ArmModeSchedule, PlayerOptions, TrajectoryPlayer
from execute.validate.verdict import Verdict, VerdictConfig, VerdictMonitor
from ladders.geometry import LadderGeometry
from ladders.spec import LadderSpec
from robot.errors import InputError
from robot.plan_sidecar import PlanSidecar

__all__ = ["STRATEGIES", "SimulationLog", "SimulationOptions", "SimulationRun", "simulate"]

log = logging.getLogger(__name__)

STRATEGIES = ("mixed", "position", "pwm")


@dataclass(frozen=True)
class SimulationOptions:
    """Attributes:
        strategy: ``mixed``, ``position`` or ``pwm``.
        placement: misplacement of the real ladder relative to the plan's.
        board: board-model tunables (battery voltage, trips, grip).
        verdict: verdict thresholds.
        gains: PWM gains (`daemon.pwm.default_drc_gains` when None).
        stop_on_failure: end the run at the first failure.
        record_qpos: keep every tick's qpos (for snapshots and video).
    """

    strategy: str = "mixed"
    placement: PlacementError = field(default_factory=PlacementError)
    board: BoardModelConfig = field(default_factory=BoardModelConfig)
    verdict: VerdictConfig = field(default_factory=VerdictConfig)
    gains: PwmGains | None = None
    stop_on_failure: bool = True
    record_qpos: bool = True

    def __post_init__(self) -> None:
        if self.strategy not in STRATEGIES:
            raise InputError(f"--strategy {self.strategy!r}: choose one of "
                             f"{', '.join(STRATEGIES)}")


@dataclass
class SimulationLog:
    """Per-tick records, arrays with one row per tick."""

    time_s: np.ndarray
    line_index: np.ndarray
    ref_rad: np.ndarray  # (T, 40) reference the boards ran on (hubo-state ``ref``)
    pos_rad: np.ndarray  # (T, 40)
    torque_nm: np.ndarray  # (T, 40)
    pwm: np.ndarray  # (T, 40) bool
    latched: np.ndarray  # (T, 2) bool: left, right
    com_m: np.ndarray  # (T, 3) whole-robot centre of mass
    sole_m: np.ndarray  # (T, 2, 3) left, right sole positions
    qpos: np.ndarray | None  # (T, nq)
    trips: list[TripEvent]
    grasps: list[GraspEvent]


@dataclass
class SimulationRun:
    """A finished run: what happened, and the objects to inspect it."""

    verdict: Verdict
    log: SimulationLog
    board: BoardModel
    sidecar: PlanSidecar
    options: SimulationOptions
    wall_s: float
    simulated_s: float
    rate_hz: float

    @property
    def real_time_factor(self) -> float:
        return self.simulated_s / self.wall_s if self.wall_s > 0 else math.inf


def _schedule(strategy: str, sidecar: PlanSidecar, n: int) -> tuple[ArmModeSchedule,
                                                                        frozenset]:
    if strategy == "mixed":
        return ArmModeSchedule.from_runs(sidecar.arm_modes, n), frozenset()
    if strategy == "pwm":
        return ArmModeSchedule.all_position(n), frozenset({"left", "right"})
    return ArmModeSchedule.all_position(n), frozenset()


def simulate(trajectory_rad: np.ndarray, sidecar: PlanSidecar, ladder: LadderSpec,
             options: SimulationOptions | None = None, robot: str = "drc-hubo"
             ) -> SimulationRun:
    """Play a trajectory in MuJoCo through the player, the control law and the boards.

    Args:
        trajectory_rad: validated (N, 40) trajectory [rad].
        sidecar: its plan sidecar (rate, holds, arm schedule).
        ladder: the ladder the plan was made for (the placement error is applied here).
        options: strategy, misplacement, battery...
        robot: robot name.

    The sidecar's arm feed-forward is played under every strategy; it acts only on
    joints in PWM mode.
    """
    opt = options or SimulationOptions()
    n = len(trajectory_rad)
    real_ladder = opt.placement.apply(ladder)
    board = BoardModel(real_ladder, robot, opt.board)
    T_err = LadderGeometry(real_ladder).T_world_ladder @ np.linalg.inv(
        LadderGeometry(ladder).T_world_ladder)
    first = sidecar.segments[0] if sidecar.segments else None
    soles = None
    if first is not None:
        soles = {k.split("_")[0]: np.asarray(h.position_m) for k, h in first.holds.items()
                 if k.endswith("_foot") and h.target == "floor"}
    board.reset(trajectory_rad[0], soles or None)
    schedule, compliant = _schedule(opt.strategy, sidecar, n)
    rate = int(round(sidecar.rate_hz))
    player = TrajectoryPlayer(trajectory_rad, PlayerOptions(rate_hz=rate,
                                                            compliant_arms=compliant),
                              schedule, sidecar.arm_feedforward)
    controller = JointController(robot=robot)
    gains = opt.gains or default_drc_gains()
    monitor = VerdictMonitor(board, sidecar, T_err, player.time_of_line, opt.verdict)

    total_ticks = int(math.ceil((player.duration_s + opt.verdict.settle_s) / TICK_S))
    nq = board.model.nq
    t_arr = np.zeros(total_ticks)
    line_arr = np.zeros(total_ticks, dtype=np.int32)
    ref = np.zeros((total_ticks, 40))
    pos = np.zeros((total_ticks, 40))
    tau = np.zeros((total_ticks, 40))
    pwm = np.zeros((total_ticks, 40), dtype=bool)
    latched = np.zeros((total_ticks, 2), dtype=bool)
    com = np.zeros((total_ticks, 3))
    sole = np.zeros((total_ticks, 2, 3))
    qpos = np.zeros((total_ticks, nq)) if opt.record_qpos else None
    trips_all: list[TripEvent] = []
    grasps_all: list[GraspEvent] = []
    d = board.data
    pelvis = monitor.pelvis
    sole_sites = [d.site("L_sole"), d.site("R_sole")]
    failure = None
    line_index = 0
    k = 0
    wall0 = time.perf_counter()
    for k in range(total_ticks):
        now = k * TICK_S
        pos_now = board.joint_pos()
        vel_now = board.joint_vel()
        tick = player.step(now, pos_now)
        line_index = tick.line_index
        out = controller.tick(tick.ref_rad, tick.mode, tick.comply, pos_now, vel_now, gains,
                              player.feedforward_duty(tick, opt.board.battery_v, board.motors))
        board.apply(out)
        trips, grasps = board.step()
        trips_all += trips
        grasps_all += grasps
        t_arr[k] = board.time_s
        line_arr[k] = line_index
        ref[k] = out.ref_sent_rad
        pos[k] = board.joint_pos()
        tau[k] = board.joint_torque()
        pwm[k] = out.pwm
        latched[k] = (board.latches["left"].latched, board.latches["right"].latched)
        com[k] = d.subtree_com[pelvis]
        sole[k, 0], sole[k, 1] = sole_sites[0].xpos, sole_sites[1].xpos
        if qpos is not None:
            qpos[k] = d.qpos
        if failure is None:
            failure = monitor.check(board.time_s, line_index, trips, grasps)
            if failure is not None:
                log.info("failure: %s", failure.why)
                if opt.stop_on_failure:
                    break
    wall = time.perf_counter() - wall0
    used = k + 1
    sim_log = SimulationLog(t_arr[:used], line_arr[:used], ref[:used], pos[:used],
                            tau[:used], pwm[:used], latched[:used], com[:used], sole[:used],
                            None if qpos is None else qpos[:used], trips_all, grasps_all)
    if failure is not None:
        verdict = Verdict(False, failure, {})
    else:
        verdict = monitor.final(board.time_s, line_index)
    return SimulationRun(verdict, sim_log, board, sidecar, opt, wall, board.time_s, rate)
