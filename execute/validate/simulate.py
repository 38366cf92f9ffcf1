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

**Re-planning after the first touch** (closed loop, `MotionConfig.replan_beyond_m`): when
the motion layer stops because its first two grasps, made from the floor, found the
ladder where the plan's holds are too far from the real ones, the run does what an
operator would: the hands open and retrace the plan back to its first line, the planner
plans again (same seed, same top rung) for the ladder where the hands found it, and the
new plan is climbed from there, the same physics going on. The run's log and verdict are
the new plan's; `SimulationRun.replan` tells what was measured and how long planning took.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from daemon.joint_control import JointController
from daemon.pwm import PwmGains, default_drc_gains
from daemon.sim.board_model import TICK_S, BoardModel, BoardModelConfig, PlacementError
from daemon.sim.board_trip import TripEvent
from daemon.sim.grasp_latch import GraspEvent
from daemon.structs import STATE_DTYPE, new_sample
from execute.motion.config import MotionConfig
from execute.play.arm_modes import ArmModeSchedule
from execute.play.player import PlayerOptions, TrajectoryPlayer
from execute.validate.verdict import Failure, Verdict, VerdictConfig, VerdictMonitor
from ladders.geometry import LadderGeometry
from ladders.spec import LadderSpec
from robot.errors import InputError
from robot.plan_sidecar import PlanSidecar
from robot.vocabulary import ArmStrategy, FailureCause, HoldTargetKind, Limb

if TYPE_CHECKING:  # pinocchio: imported only when the loop is closed
    from execute.motion.layer import MotionLayer

__all__ = ["STRATEGIES", "SimulationLog", "SimulationOptions", "SimulationRun", "simulate"]

log = logging.getLogger(__name__)

STRATEGIES = tuple(ArmStrategy)
#: The least wall time between two calls of `simulate`'s progress callback [s].
PROGRESS_PERIOD_S = 0.5


@dataclass(frozen=True)
class SimulationOptions:
    """Attributes:
        strategy: ``mixed``, ``position`` or ``pwm``.
        placement: misplacement of the real ladder relative to the plan's.
        board: board-model tunables (battery voltage, trips, grip).
        verdict: verdict thresholds.
        gains: PWM gains (when None: the motion layer's closed loop,
            `daemon.pwm.default_drc_gains` open loop).
        stop_on_failure: end the run at the first failure.
        record_qpos: keep every tick's qpos (for snapshots and video).
        closed_loop: play through the motion layer (`execute.motion`), on the state
            struct the daemon publishes; False plays the file open loop, as
            hubo-read-trajectory did.
        motion: the motion layer's tunables.
    """

    strategy: str = "mixed"
    placement: PlacementError = field(default_factory=PlacementError)
    board: BoardModelConfig = field(default_factory=BoardModelConfig)
    verdict: VerdictConfig = field(default_factory=VerdictConfig)
    gains: PwmGains | None = None
    stop_on_failure: bool = True
    record_qpos: bool = True
    closed_loop: bool = True
    motion: MotionConfig = field(default_factory=MotionConfig)

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
    motion: dict | None = None  # what the motion layer did (`MotionLayer.report`)
    #: the re-plan after the first touch, when there was one (module docstring):
    #: measured shift [m] and yaw [rad], the new placement, planning wall time [s],
    #: the misplacement before it, and the first plan's motion report. ``sidecar``,
    #: ``trajectory_rad``, ``ladder`` and ``options.placement`` are then the new plan's
    #: (its ladder as measured, and the real ladder's misplacement from it).
    replan: dict | None = None
    trajectory_rad: np.ndarray | None = None  # the plan played (the lines of ``log``)
    ladder: LadderSpec | None = None  # the ladder that plan was made for

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



class _Recorder:
    """Per-tick records in arrays that grow as the run goes on (a closed-loop run lasts
    as long as its waits and re-reaches)."""

    def __init__(self, ticks: int, nq: int):
        self.n = 0
        self.nq = nq
        self.arrays = {"t": np.zeros(ticks), "line": np.zeros(ticks, dtype=np.int32),
                       "ref": np.zeros((ticks, 40)), "pos": np.zeros((ticks, 40)),
                       "tau": np.zeros((ticks, 40)), "pwm": np.zeros((ticks, 40), dtype=bool),
                       "latched": np.zeros((ticks, 2), dtype=bool), "com": np.zeros((ticks, 3)),
                       "sole": np.zeros((ticks, 2, 3))}
        if nq:
            self.arrays["qpos"] = np.zeros((ticks, nq))
        self.trips: list[TripEvent] = []
        self.grasps: list[GraspEvent] = []

    def add(self, board: BoardModel, out, line_index: int, com_m: np.ndarray, sole_sites,
            trips: list[TripEvent], grasps: list[GraspEvent]) -> None:
        a, k = self.arrays, self.n
        if k == len(a["t"]):
            for key, arr in a.items():
                a[key] = np.concatenate([arr, np.zeros_like(arr)])
        a["t"][k] = board.time_s
        a["line"][k] = line_index
        a["ref"][k] = out.ref_sent_rad
        a["pos"][k] = board.joint_pos()
        a["tau"][k] = board.joint_torque()
        a["pwm"][k] = out.pwm
        a["latched"][k] = (board.latches["left"].latched, board.latches["right"].latched)
        a["com"][k] = com_m
        a["sole"][k, 0], a["sole"][k, 1] = sole_sites[0].xpos, sole_sites[1].xpos
        if self.nq:
            a["qpos"][k] = board.data.qpos
        self.trips += trips
        self.grasps += grasps
        self.n += 1

    def log(self) -> SimulationLog:
        a, n = self.arrays, self.n
        return SimulationLog(a["t"][:n], a["line"][:n], a["ref"][:n], a["pos"][:n],
                             a["tau"][:n], a["pwm"][:n], a["latched"][:n], a["com"][:n],
                             a["sole"][:n], a["qpos"][:n] if self.nq else None,
                             self.trips, self.grasps)


def simulate(trajectory_rad: np.ndarray, sidecar: PlanSidecar, ladder: LadderSpec,
             options: SimulationOptions | None = None, robot: str = "drc-hubo",
             progress: Callable[[float, float], None] | None = None) -> SimulationRun:
    """Play a trajectory in MuJoCo through the player, the control law and the boards.

    Args:
        trajectory_rad: validated (N, 40) trajectory [rad].
        sidecar: its plan sidecar (rate, holds, arm schedule).
        ladder: the ladder the plan was made for (the placement error is applied here).
        options: strategy, misplacement, battery...
        robot: robot name.
        progress: called as ``progress(simulated_s, expected_s)`` at most
            `PROGRESS_PERIOD_S` apart in wall time (the expected length: the plan and the
            settling time; the motion layer's pauses may run past it).

    The sidecar's arm feed-forward is played under every strategy; it acts only on
    joints in PWM mode.
    """
    opt = options or SimulationOptions()
    board, T_err = _placed_board(trajectory_rad[0], sidecar, ladder, opt, robot)
    rate = int(round(sidecar.rate_hz))
    controller = JointController(robot=robot)
    player, motion, monitor, rec = _playback(trajectory_rad, sidecar, ladder, opt, board,
                                             robot, T_err)
    gains = opt.gains or (default_drc_gains() if motion is None else motion.pwm_gains)
    wall0 = time.perf_counter()
    failure, line_index = _run_ticks(board, player, motion, controller, monitor, gains, rec,
                                     opt, progress)
    replan = None
    if failure is None and motion is not None and motion.stop is not None \
            and motion.stop.cause is FailureCause.LADDER_MISPLACED:
        real_ladder = opt.placement.apply(ladder)
        failure, line_index = _retract(board, controller, gains, opt, trajectory_rad,
                                       sidecar, line_index, motion.last_reference_rad)
        new_plan = None
        if failure is None:
            new_plan, replan = _replan_after_touch(robot, sidecar, ladder, motion)
        if new_plan is not None:
            trajectory_rad, sidecar, ladder = new_plan
            replan["placement_error_before"] = dataclasses.asdict(opt.placement)
            # one re-plan: the new plan's own small misplacement is corrected reach by reach
            opt = dataclasses.replace(opt, placement=PlacementError.between(ladder, real_ladder),
                                      motion=dataclasses.replace(opt.motion, replan_beyond_m=0.0))
            player, motion, monitor, rec = _playback(
                trajectory_rad, sidecar, ladder, opt, board, robot,
                _misplacement(ladder, opt.placement), go_to_init=True)
            failure, line_index = _run_ticks(board, player, motion, controller, monitor,
                                             gains, rec, opt, progress, t0_s=board.time_s)
    wall = time.perf_counter() - wall0
    sim_log = rec.log()
    verdict = _final_verdict(failure, motion, monitor, board.time_s, line_index)
    return SimulationRun(verdict, sim_log, board, sidecar, opt, wall, board.time_s, rate,
                         None if motion is None else motion.report(), replan,
                         trajectory_rad, ladder)


def _playback(trajectory_rad: np.ndarray, sidecar: PlanSidecar, ladder: LadderSpec,
              opt: SimulationOptions, board: BoardModel, robot: str, T_err: np.ndarray,
              go_to_init: bool = False
              ) -> tuple[TrajectoryPlayer, MotionLayer | None, VerdictMonitor, _Recorder]:
    """What plays a plan on ``board``: its player (``go_to_init``: from where the robot
    stands), the motion layer when the loop is closed (else None), the verdict monitor
    (T_err: the planned ladder to the real one) and the recorder."""
    schedule, compliant = _schedule(opt.strategy, sidecar, len(trajectory_rad))
    player = TrajectoryPlayer(trajectory_rad,
                              PlayerOptions(rate_hz=int(round(sidecar.rate_hz)),
                                            compliant_arms=compliant, go_to_init=go_to_init),
                              schedule, sidecar.arm_feedforward)
    monitor = VerdictMonitor(board, sidecar, T_err, opt.verdict)
    motion = None
    if opt.closed_loop:
        from execute.motion.layer import MotionLayer  # pinocchio: only when closing the loop

        motion = MotionLayer(player, trajectory_rad, sidecar, ladder, robot, opt.motion)
    rec = _Recorder(int(math.ceil((player.duration_s + opt.verdict.settle_s) / TICK_S)),
                    board.model.nq if opt.record_qpos else 0)
    return player, motion, monitor, rec


def _retract(board: BoardModel, controller: JointController, gains: PwmGains,
             opt: SimulationOptions, trajectory_rad: np.ndarray, sidecar: PlanSidecar,
             line_index: int, held_ref_rad: np.ndarray) -> tuple[Failure | None, int]:
    """After a ``ladder_misplaced`` stop: `execute.motion.retract.retract_lines` from line
    ``line_index`` and the layer's last reference ``held_ref_rad``, in position mode, the
    weight still on the floor (module docstring).

    Returns:
        A failure on the way (None if none) and the line index it ended on (0).
    """
    from execute.motion.retract import retract_lines

    rate = int(round(sidecar.rate_hz))
    lines = retract_lines(trajectory_rad, line_index, held_ref_rad, rate)
    retract = TrajectoryPlayer(lines, PlayerOptions(rate_hz=rate),
                               ArmModeSchedule.all_position(len(lines)))
    monitor = VerdictMonitor(board, sidecar, np.eye(4), opt.verdict)
    rec = _Recorder(int(math.ceil(retract.duration_s / TICK_S)) + 1, 0)
    failure, _line = _run_ticks(board, retract, None, controller, monitor, gains, rec,
                                dataclasses.replace(opt, strategy="position",
                                                    stop_on_failure=True, record_qpos=False,
                                                    closed_loop=False),
                                None, t0_s=board.time_s, settle_s=0.0, holds=False)
    return failure, 0


def _replan_after_touch(robot: str, sidecar: PlanSidecar, ladder: LadderSpec, motion
                        ) -> tuple[tuple[np.ndarray, PlanSidecar, LadderSpec] | None, dict]:
    """Plan again (the sidecar's seed and top rung) for ``ladder`` where the motion
    layer's hands found it (module docstring).

    Returns:
        The new plan's trajectory, sidecar and ladder (None if the planner found no
        plan: the run then ends on the layer's stop), and the `SimulationRun.replan`
        record (``no_plan`` says why there is none).
    """
    import tempfile
    from pathlib import Path

    from execute.motion.replan import ReplanSettings
    from planner.output import write_plan
    from planner.search import ClimbPlanner, PlannerConfig, PlanningFailed
    from planner.timing import TimingError
    from robot.plan_sidecar import read_sidecar, sidecar_path
    from robot.trajectory_file import read_trajectory

    stop = motion.stop
    placed = motion.measured_ladder
    settings = ReplanSettings.of(sidecar)
    config = PlannerConfig(**settings.planner)
    t0 = time.perf_counter()
    new_plan, no_plan = None, None
    try:
        planner = ClimbPlanner(placed, robot=robot, config=config, seed=settings.seed)
        result = planner.plan(top_rung=settings.top_rung)
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "replanned.traj"
            write_plan(result, planner, out, sidecar.rate_hz, {"search_s": result.total_s})
            new_sidecar = read_sidecar(sidecar_path(out))
            new_plan = (read_trajectory(out, new_sidecar.rate_hz, new_sidecar.robot),
                        new_sidecar, placed)
    except (PlanningFailed, TimingError) as exc:  # the robot keeps holding nothing
        no_plan = str(exc)
    record = {"time_s": round(stop.time_s, 3), "line": stop.line,
              "shift_m": stop.details["shift_m"], "yaw_rad": stop.details["yaw_rad"],
              "worst_hold_m": stop.details["worst_hold_m"],
              **{k: stop.details[k] for k in ("placement", "stance_m", "stance_heading_rad")},
              "planning_s": round(time.perf_counter() - t0, 1), "no_plan": no_plan,
              "first_plan_motion": motion.report()}
    return new_plan, record


def _placed_board(q0_rad: np.ndarray, sidecar: PlanSidecar, ladder: LadderSpec,
                  opt: SimulationOptions, robot: str) -> tuple[BoardModel, np.ndarray]:
    """The board model on the ladder as placed (``opt.placement``), the robot at rest in
    pose ``q0_rad`` with its soles where the plan's first segment puts them on the floor;
    and T_err, the (4, 4) transform from the planned ladder to the placed one."""
    board = BoardModel(opt.placement.apply(ladder), robot, opt.board)
    first = sidecar.segments[0] if sidecar.segments else None
    soles = None
    if first is not None:
        soles = {Limb(k).side.value: np.asarray(h.position_m) for k, h in first.holds.items()
                 if Limb(k).is_foot and h.hold_target.kind is HoldTargetKind.FLOOR}
    board.reset(q0_rad, soles or None)
    return board, _misplacement(ladder, opt.placement)


def _misplacement(ladder: LadderSpec, placement: PlacementError) -> np.ndarray:
    """T_err: the (4, 4) transform from ``ladder`` as planned to ``ladder`` as
    ``placement`` puts it."""
    return LadderGeometry(placement.apply(ladder)).T_world_ladder @ np.linalg.inv(
        LadderGeometry(ladder).T_world_ladder)


def _run_ticks(board: BoardModel, player: TrajectoryPlayer, motion, controller: JointController,
               monitor: VerdictMonitor, gains: PwmGains, rec: _Recorder,
               opt: SimulationOptions, progress: Callable[[float, float], None] | None,
               t0_s: float = 0.0, settle_s: float | None = None, holds: bool = True
               ) -> tuple[Failure | None, int]:
    """The lock-step loop, one daemon tick per iteration, until the plan has settled, the
    motion layer's hold after a stop is over, or (``opt.stop_on_failure``) a failure.
    ``t0_s``: the board's time as the player starts [s]; ``settle_s``: how long the
    robot rests after the last line (the verdict's settling time when None); ``holds``:
    the monitor checks the plan's holds (False when the player plays other lines).

    Returns:
        The first failure the monitor saw (None if none) and the last tick's line index.
    """
    state = new_sample(STATE_DTYPE)
    d = board.data
    pelvis = monitor.pelvis
    sole_sites = [d.site("L_sole"), d.site("R_sole")]
    failure = None
    line_index = 0
    finished_at = stopped_at = None
    k = 0
    wall_report = time.perf_counter()
    settle_s = opt.verdict.settle_s if settle_s is None else settle_s
    expected_s = t0_s + player.duration_s + settle_s
    while True:
        now = t0_s + k * TICK_S
        pos_now = board.joint_pos()
        vel_now = board.joint_vel()
        if motion is None:
            tick = player.step(now, pos_now)
        else:
            board.fill_state(state)
            tick = motion.step(now, state)
        line_index = tick.line_index
        out = controller.tick(tick.ref_rad, tick.mode, tick.comply, pos_now, vel_now, gains,
                              player.feedforward_duty(tick, opt.board.battery_v, board.motors))
        board.apply(out)
        trips, grasps = board.step()
        rec.add(board, out, line_index, d.subtree_com[pelvis], sole_sites, trips, grasps)
        k += 1
        if progress is not None and k % 100 == 0 and \
                time.perf_counter() - wall_report >= PROGRESS_PERIOD_S:
            wall_report = time.perf_counter()
            progress(board.time_s, expected_s)
        if failure is None:
            failure = monitor.check(board.time_s, line_index, trips, grasps, holds)
            if failure is not None:
                log.info("failure: %s", failure.why)
                if opt.stop_on_failure:
                    break
        if motion is not None and motion.stop is not None:
            stopped_at = board.time_s if stopped_at is None else stopped_at
            if board.time_s - stopped_at >= motion.config.hold_after_stop_s - 1e-9:
                break
        if tick.finished:
            finished_at = board.time_s if finished_at is None else finished_at
            if board.time_s - finished_at >= settle_s - 1e-9:
                break
    return failure, line_index


def _final_verdict(failure: Failure | None, motion, monitor: VerdictMonitor, time_s: float,
                   line_index: int) -> Verdict:
    """The run's verdict: its first failure; else a motion layer that stopped (a grasp or
    a foothold it could not verify); else the monitor's checks of the final stance."""
    if failure is None and motion is not None and motion.stop is not None:
        stop = motion.stop
        failure = Failure(stop.cause, stop.time_s, stop.line,
                          f"the motion layer held the pose and stopped: {stop.reason}",
                          {"limb": stop.limb, "tries": stop.tries, **stop.details})
    if failure is not None:
        return Verdict(False, failure, {})
    return monitor.final(time_s, line_index)
