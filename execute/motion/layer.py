"""The motion layer: closed-loop playback of a plan on sensed state.

It sits between the trajectory player and the daemon's control law, and rebuilds what
hubo-motion-rt and the thesis's operator did (thesis §4.3.4, §6.2):

- **gravity compensation** of the compliant arms (`execute.motion.gravity_compensation`),
  which run with their PWM clamps at the safety ceiling (`execute.motion.gains`);
- **catching up before complying**: a mixed arm moves stiff through the air and complies
  on the last lines of its reach; if its palm still lags its reference by more than
  ``arrival_tolerance_m`` on the last stiff line, the player waits there, the arm in
  position mode, at most ``arrival_timeout_s``; an arm still behind finishes the reach
  stiff;
- **arrival**: before a hand closes, the player waits until the encoders put its palm
  within ``arrival_tolerance_m`` of where its reference does (a PWM arm lags its
  reference), at most ``arrival_timeout_s``. An arm still short of it, if its schedule
  moved it in position mode through the air (mixed), then finishes the reach in position
  mode and waits as long again; it complies again once its grasp is verified (the mixed
  strategy: position in the air, PWM on the rail);
- **aim before closing**: an arrived palm that the estimate puts farther than
  ``aim_tolerance_m`` across its rail from where a hand last held that rail is moved
  there (bounded) before the hand closes. The body can turn on its standing feet
  while a hand reaches (3.4° on `ship`); the gyro's heading lets the estimate see it;
- **grasp verification**: at the end of every grasp the plan makes, the player waits
  until the finger encoders read the hand closed on its rail
  (`execute.motion.grasp_check`). Only then does the plan go on to put load on it;
- **re-reach**: a hand that closed on nothing opens and moves first by the miss the
  estimate measured (across the rail), then to the next point of a small pattern around
  its target (across the rail, towards and away from the ladder, and sideways), and
  closes again, up to ``grasp_retries`` times. If it still holds nothing
  the layer **stops**: the player stays paused, every verified grip is kept, and the
  climb ends with the reason. The weight never moves onto an unverified grasp;
- **guarded landing**: a step's foot must stand on its rung before the plan goes on (the
  next step moves weight onto it). At the end of the step the player waits until the
  foot's F/T sensor reads ``landing_load_n``; if it does not within ``landing_wait_s``, the
  foot reaches further down towards its rung, at ``landing_speed_m_s``, until it does, at
  most ``landing_reach_m``; then the layer **stops** as for a grasp;
- **guarded swing**: a swinging foot whose F/T sensor reads a push from above (its toe
  rising under the rung it steps onto, the body a few centimetres nearer the ladder than
  planned) stops, the player paused, and backs away from the ladder by
  ``strike_backoff_m``; it keeps that back-off while it rises, to the highest point of its
  step, and reaches its hold from there. After ``strike_tries`` back-offs in one step the
  layer **stops** as for a grasp. A reaching hand that its wrist F/T shows pushed by the
  ladder along the forearm (its palm plate on the rail it leaves, the body nearer the
  ladder than planned) backs off along the push the same way, and lets the back-off go
  over the rest of its reach; its grasp is verified at the end as every grasp is. On the
  compliant last stretch of a reach a push is the hand meeting its rail, not a strike;
- **a guard on stiff arms**: a stiff arm that pushes near a torque limit complies again;
- **wrist-roll relief** of a gripping arm (`execute.motion.wrist_relief`), from its motor
  current, while its fingers hold the rail;
- **leg relief** (`execute.motion.leg_relief`): while a stance leg's joint pushes near its
  torque limit (motor current), the gripping compliant arms lift more of the body, unless
  a closed grip's load, estimated from the arms' currents (`execute.motion.grip_load`),
  nears what it holds;
- **reach correction**: every verified grasp measures where its rail is
  (`execute.motion.ladder_estimate`); every later reach of a hand or a foot to a hold on
  the ladder is re-targeted by that estimate, by inverse kinematics on the limb's chain
  from the plan's end pose of the reach (`execute.motion.robot_model`), blended in over
  the reach. Corrections are bounded (`MotionConfig.max_reach_correction_m`);
- **holds kept where they are**: while a limb holds, its correction is a displacement of
  its hold (from its references as it starts to hold), realised again at each segment's pose
  (`_follow_holds`). While a foot stands on the floor the body keeps the plan's posture
  over the floor; once none does, the body takes the ladder's placement and the holds on
  the ladder need no correction of their own (`_body_shift_m`);
- **the body trimmed to the rails**: once the ladder alone carries the robot, at every
  segment the hands that hold verified grasps measure, by their arms' encoders, how far
  the body stands towards the ladder from the plan's posture relative to the rails (a
  creeping stance foot, compliant arms pulling on their grips); every holding limb's
  references then move the body back, horizontally, within ``max_body_trim_m``
  (`_trim_body`);
- **the feet aimed from the rails**: once the ladder alone carries the robot, each foot's
  reach to a rung is aimed against the body's offset that the holding hands read, within
  ``max_foot_aim_m``; the body itself stays (`_foot_aim_m`).

Its only input is the daemon's state struct (`execute.motion.sensed_state`). It writes
references, modes and feed-forward, the same things the open-loop player writes.

One module: the steps above share one state machine over the plan's segments (the
offsets, the pending grasp, the pause) that each tick advances.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from daemon.control_modes import RefMode
from execute.motion.config import MotionConfig
from execute.motion.estimator import BodyEstimate, StateEstimator
from execute.motion.events import MotionEvent, MotionEventKind, MotionStop
from execute.motion.gains import motion_pwm_gains
from execute.motion.grasp_check import GraspReading, closed_around_rail, read_grasp
from execute.motion.gravity_compensation import ArmGravityCompensation
from execute.motion.grip_bending_relief import GripBendingRelief
from execute.motion.grip_load import GripLoad
from execute.motion.ladder_estimate import LadderEstimate, RailObservation
from execute.motion.leg_relief import LegRelief
from execute.motion.robot_model import MotionRobotModel
from execute.motion.sensed_state import SensedState
from execute.motion.wrist_relief import WRIST_ROLL, WristRelief
from execute.play.player import PlayerTick, TrajectoryPlayer, min_jerk
from ladders.geometry import LadderGeometry, rot_z
from ladders.spec import LadderSpec
from robot.joints import ARM_JOINTS, FINGER_JOINTS, JOINT_NAMES, joint_indices
from robot.limits import joint_limits
from robot.motors import motor_table
from robot.plan_sidecar import PlanSidecar, Segment, segment_of_lines
from robot.vocabulary import FailureCause

__all__ = ["MotionLayer"]

log = logging.getLogger(__name__)

SIDES = ("left", "right")
#: Re-reach pattern, in search steps (towards the ladder across the rail, sideways): the
#: eight neighbours of a square grid, the nearer four first. At a step of 2.5 cm every
#: point within a step of the target in both directions lies within the latch's 2 cm of
#: one of them (half the diagonal is 1.8 cm); the four alone left a ladder 3.7 cm off
#: diagonally unfound (DRC seed 3 under a 2.5 cm, 2.1 cm, 2.4° placement error).
SEARCH_PATTERN = ((1, 0), (0, 1), (0, -1), (-1, 0), (1, 1), (1, -1), (-1, 1), (-1, -1))
#: A correction smaller than this is not applied [m]: the estimate's own error (leg
#: odometry drift, a hand settled off the axis within the grip) is below it, and the grip
#: and the feet tolerate it.
MIN_CORRECTION_M = 0.01
#: A body offset the foot aim leaves alone [m]: the hands read the body's place within
#: 0.6 cm of MuJoCo's (median 0.2 cm, DRC seed 1, 2026-11-29); `ship`'s feet drift
#: 0.5 cm a rung, under `MIN_CORRECTION_M`.
FOOT_AIM_DEADBAND_M = 0.005
#: A palm whose estimate moves slower than this [m/s], over `SEAT_WINDOW_S` of the daemon's
#: time, stands still in its grip: the grasp is then seated and its palm read as where the
#: rail is. Fingers read on-rail as soon as they stop on it; the grip then draws the rail
#: into its middle and a compliant arm gives way, over about a second (a ladder 1.2 cm off
#: the plan's: the palm read 1.7 cm when the fingers stopped, 1.19 cm once still; under
#: CPU load the first reading was 0.1 cm, 2026-11-29).
SEATED_SPEED_M_S = 0.003
SEAT_WINDOW_S = 0.1
#: The planned swing's highest point is looked for on every this many lines.
APEX_STRIDE_LINES = 20
#: A backing-off foot also moves down by this share of its back-off, off the underside it
#: met.
STRIKE_DOWN_SHARE = 1.0 / 3.0
#: Two targets closer than this are the same [m].
SAME_TARGET_M = 0.005
#: A body error across the rails smaller than this does not move the body [m]: a grip
#: holds its rail anywhere within a few millimetres of the palm's planned point.
BODY_TRIM_DEADBAND_M = 0.005
#: Share of the body error the trim takes out at each segment: at 1 the error read at
#: the next segment changed sign at most segments (over-correction; DRC seed 1 swung
#: from −2.8 to +4.4 cm within 8 s, 2026-11-29); half damps it.
BODY_TRIM_GAIN = 0.5
#: A stiff arm whose motor currents say a joint has pushed harder than this share of its
#: torque limit for `STIFF_ARM_YIELD_S` complies again: its open hand pushes on the rail
#: or a rung (a stiff re-reach on `stair` tripped a shoulder's board so, 2026-11-27; a
#: board trips at 0.99 held for 0.5 s). The wait lets the stiff reach's own start pass.
STIFF_ARM_YIELD = 0.8
STIFF_ARM_YIELD_S = 0.2


def _side(limb: str) -> str:
    return limb.split("_")[0]


@dataclass
class _Blend:
    """A limb's joint offset moving from ``start`` to ``end`` between two lines (or two
    times, while the player waits)."""

    start: np.ndarray
    end: np.ndarray
    t0: float
    t1: float
    time_based: bool = False  #: t0, t1 are times [s] (a re-reach), not line indices

    def at(self, t: float) -> np.ndarray:
        if self.t1 <= self.t0:
            return self.end
        return self.start + min_jerk((t - self.t0) / (self.t1 - self.t0)) * (self.end - self.start)

    def on_tick(self, now_s: float, line_index: int) -> np.ndarray:
        """The offset on a tick: at its time or at its line, whichever the blend runs on."""
        return self.at(now_s if self.time_based else float(line_index))


@dataclass
class _Regrasp:
    """A hand that is being verified or re-reached while the player waits."""

    side: str
    segment: int
    rail: str
    planned_m: np.ndarray
    phase: str  # "catch_up", "retarget", "arrive", "verify", "open", "shift", "close", "seat"
    since_s: float
    tries: int = 0
    candidates: list = dataclasses.field(default_factory=list)  # re-reach shifts [m]
    seat_time_s: float = 0.0  # while seating: the daemon time of the last palm sample [s]
    seat_palm_m: np.ndarray | None = None  # and that palm estimate [m]


@dataclass
class _Landing:
    """A foot at the end of its step that its F/T sensor does not show standing yet,
    while the player waits."""

    side: str
    segment: int
    target: str  # the rung it steps onto
    since_s: float
    phase: str = "wait"  # "wait", then "reach" (down towards the rung)
    reach_s: float = 0.0  # how long the full reach takes [s]


@dataclass
class _Strike:
    """A swinging foot that met something from above, or a reaching hand that the ladder
    pushed, backing off while the player waits."""

    limb: str
    segment: int
    since_s: float
    backoff_dq: np.ndarray  # the limb's joint offset once backed off [rad]
    target_dq: np.ndarray  # the step's own correction at its last line [rad]


class MotionLayer:
    """Closed-loop playback (module docstring).

    Args:
        player: the trajectory player (the layer pauses and resumes it).
        trajectory_rad: the plan, shape (N, 40) [rad].
        sidecar: its sidecar (segments, holds).
        ladder: the ladder the plan was made for.
        robot: robot name.
        config: tunables.
    """

    def __init__(self, player: TrajectoryPlayer, trajectory_rad: np.ndarray,
                 sidecar: PlanSidecar, ladder: LadderSpec, robot: str = "drc-hubo",
                 config: MotionConfig | None = None):
        self.player = player
        self.trajectory_rad = trajectory_rad
        self.sidecar = sidecar
        self.config = config or MotionConfig()
        self.geometry = LadderGeometry(ladder)
        self._rail_axes: dict[str, np.ndarray] = {}  # rail → unit direction (`_rail_direction`)
        self.model = MotionRobotModel(robot)
        first = sidecar.segments[0]
        soles = {_side(limb): np.asarray(h.position_m) for limb, h in first.holds.items()
                 if limb.endswith("_foot")}
        self.estimator = StateEstimator(self.model, soles, self.config.estimator)
        self.gravity = ArmGravityCompensation(self.model)
        self.wrist_relief = WristRelief(robot)
        self.leg_relief = LegRelief(self.model, robot)
        self.grip_load = GripLoad(self.model, ladder.friction, ladder.rail_radius_m)
        onset = self.config.grip_bending_onset
        self.bending_relief = None if onset == 0.0 else GripBendingRelief(
            self.model, self.grip_load.capacity.bending_nm, onset_share=onset)
        #: The gains the daemon should run the compliant arms with (`execute.motion.gains`).
        self.pwm_gains = motion_pwm_gains()
        self._last_now: float | None = None
        self.ladder = LadderEstimate(self.config.max_reach_correction_m,
                                     self.config.max_reach_correction_rad)
        #: The rails in the estimate's frame as the hands last found them: every verified
        #: grasp, and every hand still holding one at the start of a segment. A re-reach
        #: searches around it (see `_candidates`).
        self.rails = LadderEstimate(self.config.max_reach_correction_m,
                                    self.config.max_reach_correction_rad)
        self._segment_of_line = segment_of_lines(sidecar, "plan")
        #: every hold the plan puts on the ladder (rungs, rails), world [m]
        self._ladder_holds_m = np.array(
            [h.position_m for seg in sidecar.segments for h in seg.holds.values()
             if self._on_ladder(h.target)]).reshape(-1, 3)
        self._next_hold = self._next_holds(sidecar.segments)
        self._finger_cols = {side: joint_indices(FINGER_JOINTS[side]) for side in SIDES}
        self._arm_cols = {side: joint_indices(ARM_JOINTS[side]) for side in SIDES}
        self._offsets: dict[str, _Blend] = {}
        self._shift_m: dict[str, np.ndarray] = {}  # limb → world shift its offset makes [m]
        self._segment = -1
        self._verified_segments: set[tuple[int, str]] = set()
        #: side → (rail, planned hold [m]) of a verified grasp the hand still holds
        self._held_rails: dict[str, tuple[str, np.ndarray]] = {}
        #: holding limb → its correction as a world shift [m] and turn (`_follow_holds`)
        self._hold_corrections: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        #: no foot of this segment stands on the floor: the body takes the ladder's
        #: placement (`_body_shift_m`)
        self._body_on_ladder = False
        #: horizontal, towards the ladder (world): the direction of the body trim
        self._towards_ladder = self.geometry.R_world_ladder[:, 0].copy()
        #: how far the body is moved towards the ladder, on top of the ladder's
        #: placement, to stand in the plan's posture relative to the held rails [m]
        #: (`_trim_body`)
        self._body_trim_m = 0.0
        #: along the rungs (world): the lateral part of the body error
        self._along_rungs = self.geometry.R_world_ladder[:, 1].copy()
        #: side → what its grasp's own seat adds to the body error it reads, towards the
        #: ladder and along the rungs [m] (`_hand_readings_m`, `_seat_grasp`)
        self._grasp_seat_m: dict[str, np.ndarray] = {}
        self._arrived: set[tuple[int, str]] = set()
        #: side → (first compliant line, grasp's first line, grasp segment) of each reach
        #: whose arm the schedule turns compliant in the air before its grasp, 0-based
        self._final_approaches = self._compliant_final_approaches()
        #: the last stiff line of each of those (0-based) → (side, grasp segment)
        self._catch_up_at: dict[int, list[tuple[str, int]]] = {}
        for side, approaches in self._final_approaches.items():
            for start, _first, k in approaches:
                self._catch_up_at.setdefault(start - 1, []).append((side, k))
        self._caught_up: set[tuple[int, str]] = set()
        self._last_ref = np.asarray(trajectory_rad[0], dtype=float).copy()
        self._regrasp: _Regrasp | None = None
        self._landing: _Landing | None = None
        self._landed: set[int] = set()  # steps whose foot landing has been checked
        self._strike: _Strike | None = None
        self._strikes: dict[int, int] = {}  # step segment → back-offs so far
        self._open_fingers: set[str] = set()
        self._stiff_arms: set[str] = set()  # arms held in position mode until they grip
        self._yielded: set[str] = set()  # stiff arms that pushed on something, until they grip
        self._pushing_s: dict[str, float] = {}  # stiff arm → how long it has pushed hard [s]
        self._torque_limit_nm = joint_limits(robot).torque_max_nm
        self.motors = motor_table()
        #: This tick's joint torques from the motor currents [N·m], by column.
        self._sensed_torque_nm = np.zeros(len(JOINT_NAMES))
        self.events: list[MotionEvent] = []
        self.stop: MotionStop | None = None
        #: the plan's ladder placed where the first grasps found it, seen from where the
        #: robot stood, when the layer stopped for it (`_misplaced_ladder`)
        self.measured_ladder: LadderSpec | None = None
        self.estimate: BodyEstimate | None = None
        self._line = 0
        self._now = 0.0
        self._pos_rad = np.asarray(trajectory_rad[0], dtype=float)  # the last sample's encoders

    def stance(self) -> tuple[np.ndarray, float]:
        """Where the robot stands in the estimate's frame: the middle of its soles [m]
        and their mean heading [rad], from the last sample's encoders and the body's
        estimated pose (feet can turn on the floor while the hands search)."""
        T_wp = self.estimate.T_world_pelvis
        frames = self.model.frames_in_pelvis(self._pos_rad, ("L_sole", "R_sole"))
        soles = [T_wp @ T for T in frames.values()]
        middle = np.mean([T[:3, 3] for T in soles], axis=0)
        x_axis = np.sum([T[:3, 0] for T in soles], axis=0)  # the soles' mean heading
        return middle, float(np.arctan2(x_axis[1], x_axis[0]))

    @property
    def last_reference_rad(self) -> np.ndarray:
        """The references of the last tick's command [rad] (a copy): the plan's line
        with the layer's corrections."""
        return self._last_ref.copy()

    # ------------------------------------------------------------------ plan queries
    @staticmethod
    def _next_holds(segments: tuple[Segment, ...]) -> list[dict]:
        """Per segment: moving limb → (segment index, hold) of the hold it goes to."""
        out = []
        for k, seg in enumerate(segments):
            targets = {}
            for limb in seg.moving_limbs:
                for j in range(k + 1, len(segments)):
                    if limb in segments[j].holds:
                        targets[limb] = (j, segments[j].holds[limb])
                        break
            out.append(targets)
        return out

    def _compliant_final_approaches(self) -> dict[str, list[tuple[int, int, int]]]:
        """Per arm, the reaches the schedule moves stiff through the air and finishes
        compliant before their grasp begins (mixed arms comply on the last lines of a
        reach): (first compliant line, the grasp's first line, the grasp's segment),
        lines 0-based."""
        out: dict[str, list[tuple[int, int, int]]] = {side: [] for side in SIDES}
        # the first line of every PWM run, per arm
        run_starts = {side: np.flatnonzero(np.diff(pwm.astype(np.int8), prepend=0) == 1)
                      for side, pwm in self.player.schedule.pwm_by_line.items()}
        for k, seg in enumerate(self.sidecar.segments):
            if seg.phase != "grasp":
                continue
            for limb, (_j, hold) in self._next_hold[k].items():
                if not (limb.endswith("_hand") and hold.target.startswith("rail")):
                    continue
                side = _side(limb)
                first = seg.first_line - 1
                if not self.player.schedule.pwm_by_line[side][first]:
                    continue
                starts = run_starts[side]
                start = int(starts[np.searchsorted(starts, first, side="right") - 1])
                if 0 < start < first:
                    out[side].append((start, first, k))
        return out

    def _in_final_approach(self, side: str, line_index: int) -> bool:
        """Whether ``side``'s arm is on the compliant last stretch of a reach at
        ``line_index`` (`_compliant_final_approaches`)."""
        return any(start <= line_index < first
                   for start, first, _k in self._final_approaches[side])

    def _on_ladder(self, target: str) -> bool:
        return target != "floor"

    @staticmethod
    def _feet_on_floor(seg: Segment) -> bool:
        """Both feet stand on the floor: leg odometry is exact."""
        return all(h.target == "floor" for limb, h in seg.holds.items() if limb.endswith("_foot"))

    def _rail_direction(self, rail: str) -> np.ndarray:
        """The plan's ladder's ``rail`` as a unit direction, world (asked every tick for
        each closed grip: computed once per rail)."""
        axis = self._rail_axes.get(rail)
        if axis is None:
            p0, p1 = self.geometry.rail_axis(rail.removeprefix("rail_"))
            axis = self._rail_axes[rail] = (p1 - p0) / np.linalg.norm(p1 - p0)
        return axis

    # ------------------------------------------------------------------ events
    def _event(self, kind: MotionEventKind, limb: str, size_m: float, cause: str) -> None:
        ev = MotionEvent(kind, self._now, self._line + 1, self._segment, limb, size_m, cause)
        log.info("%s", ev)
        self.events.append(ev)

    # ------------------------------------------------------------------ offsets
    def _offset(self, limb: str) -> np.ndarray:
        """``limb``'s joint offset on this tick; zero without one (where a new blend
        starts)."""
        blend = self._offsets.get(limb)
        return np.zeros(len(JOINT_NAMES)) if blend is None else blend.on_tick(self._now,
                                                                              self._line)

    def _limb_shift_dq(self, limb: str, line_index: int, shift_world_m: np.ndarray,
                       turn_world: np.ndarray | None = None) -> tuple[np.ndarray, float]:
        """Joint offsets that move ``limb`` by ``shift_world_m`` and turn it by
        ``turn_world`` (world frame; when None, the ladder estimate's yaw less the body's,
        `_body_yaw_rad`) at the plan's pose of ``line_index``."""
        R_world_pelvis = self.estimate.T_world_pelvis[:3, :3]
        if turn_world is None:
            turn_world = rot_z(self.ladder.yaw_rad - self._body_yaw_rad())
        return self.model.limb_correction(self.trajectory_rad[line_index],
                                          self.model.chains[limb],
                                          R_world_pelvis.T @ shift_world_m,
                                          R_world_pelvis.T @ turn_world @ R_world_pelvis)

    def _ladder_shift(self, planned_m: np.ndarray, estimate: LadderEstimate | None = None,
                      relative_to_body: bool = True) -> np.ndarray:
        """Where ``estimate`` (the ladder estimate unless given) puts a hold planned at
        ``planned_m``, as a shift [m]: a limb's correction towards it, less the body's own
        placement (`_body_shift_m`) unless ``relative_to_body`` is False. Zero without an
        estimate or below `MIN_CORRECTION_M`, bounded above."""
        estimate = self.ladder if estimate is None else estimate
        if not estimate.observed:
            return np.zeros(3)
        shift = estimate.correction_m(planned_m)
        if relative_to_body:
            shift = shift - self._body_shift_m(planned_m)
        shift = self._bounded(shift)
        return shift if float(np.linalg.norm(shift)) >= MIN_CORRECTION_M else np.zeros(3)

    def _body_shift_m(self, planned_m: np.ndarray) -> np.ndarray:
        """How far the body's own placement moves a hold planned at ``planned_m`` [m]:
        nothing while a foot stands on the floor (the plan's posture over the floor
        feet); once the ladder alone carries the robot, the ladder estimate's shift
        there, so that the body keeps the plan's posture relative to the ladder, plus the
        trim that takes it back there (`_trim_body`)."""
        if not self._body_on_ladder:
            return np.zeros(3)
        return (self._bounded(self.ladder.correction_m(planned_m))
                + self._body_trim_m * self._towards_ladder)

    def _body_yaw_rad(self) -> float:
        """The yaw of the body's own placement (`_body_shift_m`) [rad]."""
        return self.ladder.yaw_rad if self._body_on_ladder else 0.0

    def _bounded(self, shift_m: np.ndarray, cap_m: float | None = None) -> np.ndarray:
        """``shift_m`` shortened to ``cap_m`` (default ``max_reach_correction_m``) [m]."""
        cap = self.config.max_reach_correction_m if cap_m is None else cap_m
        length = float(np.linalg.norm(shift_m))
        return shift_m if length <= cap else shift_m * (cap / length)

    def _observe_held_rails(self, seg: Segment) -> None:
        """Measure the rails again with every hand still holding its verified grasp.

        Leg odometry anchors a stance foot where it landed; a sole that creeps on its
        rung carries the whole estimate with it, and the rails seem to move the other
        way (2–3 cm within 200 s on `ship`, 2026-11-27). The reaches keep the floor's
        estimate, so that the body keeps its planned posture relative to its holds
        (docs/decisions/rails-measured-again.md); only a hand that closed on nothing
        searches where the rails now seem to be. A hand that let go of its hold is
        forgotten until its next grasp is verified."""
        on_floor = self._feet_on_floor(seg)
        for side in SIDES:
            if side not in self._held_rails:
                continue
            rail, planned_m = self._held_rails[side]
            hold = seg.holds.get(f"{side}_hand")
            if hold is None or hold.target != rail \
                    or np.linalg.norm(np.asarray(hold.position_m) - planned_m) > SAME_TARGET_M:
                del self._held_rails[side]
                continue
            self.rails.add(RailObservation(rail, planned_m, self.estimate.palm_m[side],
                                           self._rail_direction(rail)), fits_yaw=on_floor)

    def _correction_at(self, limb: str, q_held_rad: np.ndarray, planned_m: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
        """Where ``limb``'s references ``q_held_rad`` put it against the plan at this line,
        as a world shift [m] and turn (bounded), the body's own placement included
        (`_body_shift_m` at its hold ``planned_m``): its end frame against the plan's,
        both in the pelvis frame."""
        frame = self.model.chains[limb].frame
        T_plan = self.model.frame_in_pelvis(self.trajectory_rad[self._line], frame)
        T_held = self.model.frame_in_pelvis(q_held_rad, frame)
        R_wp = self.estimate.T_world_pelvis[:3, :3]
        turn = Rotation.from_matrix(T_held[:3, :3] @ T_plan[:3, :3].T).as_rotvec()
        angle_rad = float(np.linalg.norm(turn))
        cap_rad = self.config.max_reach_correction_rad
        if angle_rad > cap_rad:
            turn *= cap_rad / angle_rad
        return (self._bounded(R_wp @ (T_held[:3, 3] - T_plan[:3, 3]))
                + self._body_shift_m(planned_m),
                R_wp @ Rotation.from_rotvec(turn).as_matrix() @ R_wp.T
                @ rot_z(self._body_yaw_rad()))

    def _hand_readings_m(self, rails: dict[str, str]) -> dict[str, np.ndarray]:
        """side → how far the body stands from the plan's posture relative to its rail
        (``rails``: side → rail), horizontally towards the ladder and along the rungs, as
        that hand on it reads it [m]; the palms of all the hands from one forward
        kinematics each of the plan's line and of the encoders.

        The plan's palm (the grip centre, on the rail's axis) from its pelvis, turned
        by the plan's attitude of the pelvis (`_planned_pelvis_rotation`), against the
        encoders' palm from the pelvis, turned by the estimated attitude, gives the
        body's offset across the rail; along it a grip may slide. Read as a horizontal
        offset (a stance foot creeps along its tread; the legs, near straight, set the
        height), it is the across part's component towards the ladder over that
        direction's share across the rail. Along the rungs the rail's axis has no share:
        that component is the offset's own. No odometry enters. It includes where the
        grasp seated on its rail against where the ladder estimate has the hold
        (`_seat_grasp`)."""
        palms = tuple(f"{side[0].upper()}_palm" for side in rails)
        planned = self.model.frames_in_pelvis(self.trajectory_rad[self._line], palms)
        sensed = self.model.frames_in_pelvis(self._pos_rad, palms)
        R_plan = self._planned_pelvis_rotation()
        R_est = self.estimate.T_world_pelvis[:3, :3]
        n = self._towards_ladder
        out = {}
        for (side, rail), palm in zip(rails.items(), palms, strict=True):
            offset = R_plan @ planned[palm][:3, 3] - R_est @ sensed[palm][:3, 3]
            axis = self._rail_direction(rail)
            across = offset - (offset @ axis) * axis
            out[side] = np.array([float(n @ across) / (1.0 - float(n @ axis) ** 2),
                                  float(self._along_rungs @ across)])
        return out

    def _planned_pelvis_rotation(self) -> np.ndarray:
        """The plan's attitude of the pelvis on this line, world frame, with the body's
        own placement's yaw (`_body_yaw_rad`): from a foot the segment holds, its sole
        flat on its tread (check-plan places the plan's body the same way). A pitch of
        1° between the plan's body and the real one moves a palm 0.9 cm relative to the
        pelvis; the DRC body stood 2.3° off the plan's (2026-11-29)."""
        seg = self.sidecar.segments[int(self._segment_of_line[self._line])]
        foot = next(limb for limb in ("left_foot", "right_foot") if limb in seg.holds)
        R_world_sole = (np.eye(3) if seg.holds[foot].target == "floor"
                        else self.geometry.R_world_ladder)
        R_pelvis_sole = self.model.frame_in_pelvis(self.trajectory_rad[self._line],
                                                   f"{foot[0].upper()}_sole")[:3, :3]
        return rot_z(self._body_yaw_rad()) @ R_world_sole @ R_pelvis_sole.T

    def _body_error_m(self, but: str = "") -> np.ndarray | None:
        """How far the body stands from the plan's posture relative to the rails,
        horizontally towards the ladder and along the rungs [m]: the mean over the hands
        that hold verified grasps (`_held_rails`), other than ``but``, of what each reads
        less its grasp's seat; None without one."""
        held = {side: rail for side, (rail, _planned_m) in sorted(self._held_rails.items())
                if side != but and side in self._grasp_seat_m}
        if not held:
            return None
        readings = self._hand_readings_m(held)
        return np.mean([readings[side] - self._grasp_seat_m[side] for side in held], axis=0)

    def _seat_grasp(self, side: str, rail: str, on_floor: bool) -> None:
        """With the body read (`_reads_body`), record what a newly verified grasp's seat adds to the
        body error its hand reads (`_hand_readings_m`). A grasp made from the floor seats
        where the ladder estimate has its rail (the estimate is fitted to the palms):
        nothing. A grasp on the ladder seats within the fingers' reach of its hold, up to
        2 cm from it (1.8 cm between the two hands' readings on DRC seed 1, 2026-11-29):
        its reading is taken against the body error that the hands already holding read
        at that moment, so that the error is carried from grasp to grasp."""
        if not self._reads_body:
            return
        if on_floor:
            self._grasp_seat_m[side] = np.zeros(2)
            return
        seat = self._hand_readings_m({side: rail})[side]
        body = self._body_error_m(but=side)
        self._grasp_seat_m[side] = seat if body is None else seat - body

    @property
    def _reads_body(self) -> bool:
        """The body's offset from the held rails is read (`_body_error_m`): the body trim
        or the foot aim is on."""
        return self._trims_body or self.config.max_foot_aim_m > 0.0

    def _foot_aim_m(self) -> np.ndarray:
        """Where a foot's reach to a rung is aimed, on top of the ladder estimate's shift,
        once the ladder alone carries the robot [m]: against the body's offset from the
        plan's posture relative to the held rails (`_body_error_m`), horizontally, within
        ``max_foot_aim_m``. The reach is relative to the body; a body that stands off
        on offset feet would otherwise set the next foot as far off again. Zero with the
        aim off, on the floor, or with no hand holding."""
        cap = self.config.max_foot_aim_m
        if cap <= 0.0 or not self._body_on_ladder:
            return np.zeros(3)
        error = self._body_error_m()
        if error is None or float(np.linalg.norm(error)) < FOOT_AIM_DEADBAND_M:
            return np.zeros(3)
        return self._bounded(-(error[0] * self._towards_ladder
                               + error[1] * self._along_rungs), cap)

    @property
    def _trims_body(self) -> bool:
        """The body trim is on (``max_body_trim_m`` above 0)."""
        return self.config.max_body_trim_m > 0.0

    def _trim_body(self) -> None:
        """Once the ladder alone carries the robot, move the body back to the plan's
        posture relative to the held rails (`_body_error_m`), horizontally: the trim
        integrates the error (`BODY_TRIM_GAIN`), within ``max_body_trim_m``, and every
        holding limb realises it over the segment (`_follow_holds`). A stance foot that
        creeps on its rung carries the body with it (2–3 cm over a DRC climb), and
        compliant arms that pull on their grips draw it towards the ladder (2.1 cm on
        `ship`, where the plan keeps a shin 2 cm clear of its rung): leg odometry sees
        neither, the arms' encoders both. Across the rail the body's height shows too; a
        trim that also lifted the body wound up against legs near straight (DRC seed 1
        tripped LHR, 2026-11-29)."""
        if not (self._trims_body and self._body_on_ladder):
            self._body_trim_m = 0.0
            return
        cap = self.config.max_body_trim_m
        body_error = self._body_error_m()
        if body_error is None or abs(body_error[0]) < BODY_TRIM_DEADBAND_M:
            return
        error = float(body_error[0])  # towards the ladder
        trim = float(np.clip(self._body_trim_m - BODY_TRIM_GAIN * error, -cap, cap))
        if trim == self._body_trim_m:
            return  # at its bound
        self._event(MotionEventKind.BODY_TRIM, "", abs(trim - self._body_trim_m),
                    f"the holding hands put the body {error * 100:+.1f} cm towards the ladder "
                    f"from the plan's posture; it moves {(trim - self._body_trim_m) * 100:+.1f} "
                    f"cm (trim {trim * 100:+.1f} cm)")
        self._body_trim_m = trim

    def _follow_holds(self, seg: Segment) -> None:
        """Keep every holding limb's correction where it holds at this segment's poses.

        A correction is a displacement of the hold in the world (`_correction_at`): taken
        from the limb's references when it starts to hold, it is realised, less the
        body's own placement (`_body_shift_m`), by inverse kinematics at the segment's
        last pose and blended in over the segment. A joint offset solved at one pose and
        kept moves the end frame elsewhere at another: the body rises 30 cm past a held
        hand, and a foot turned for the ladder's yaw was pulled against its rung by both
        stiff legs. Once the last foot leaves the floor, the body takes the ladder's
        placement and the holds on the ladder need no correction of their own."""
        for limb in seg.moving_limbs:
            self._hold_corrections.pop(limb, None)
        for limb, hold in seg.holds.items():
            planned_m = np.asarray(hold.position_m)
            if limb not in self._hold_corrections:
                if limb not in self._offsets and not self._trims_body:
                    # no correction of its own: it stays where the plan has it relative
                    # to the body (its share of the ladder's placement was under
                    # `MIN_CORRECTION_M`); only the body trim moves the body further
                    continue
                q_held = self.trajectory_rad[self._line] + self._offset(limb)
                self._hold_corrections[limb] = self._correction_at(limb, q_held, planned_m)
            shift_world_m, turn_world = self._hold_corrections[limb]
            shift_m = shift_world_m - self._body_shift_m(planned_m)
            turn = turn_world @ rot_z(self._body_yaw_rad()).T
            if limb not in self._offsets and float(np.linalg.norm(shift_m)) < 1e-6 \
                    and np.allclose(turn, np.eye(3), atol=1e-9):
                continue  # held where the plan has it relative to the body
            dq, _residual = self._limb_shift_dq(limb, seg.last_line - 1, shift_m, turn)
            self._offsets[limb] = _Blend(self._offset(limb), dq, float(seg.first_line - 1),
                                         float(seg.last_line - 1))

    def _enter_segment(self, k: int) -> None:
        """Measure the held rails again; keep the holding limbs where they hold (the body
        on the ladder's placement once no foot stands on the floor, trimmed back to the
        plan's posture relative to the held rails); re-target the reaches of segment
        ``k`` from the ladder estimate."""
        seg = self.sidecar.segments[k]
        self._observe_held_rails(seg)
        self._body_on_ladder = not any(limb.endswith("_foot") and h.target == "floor"
                                       for limb, h in seg.holds.items())
        self._trim_body()
        self._follow_holds(seg)
        for limb, (_j, hold) in self._next_hold[k].items():
            if seg.phase != "limb" or not self._on_ladder(hold.target):
                continue
            shift = self._ladder_shift(np.asarray(hold.position_m))
            if limb.endswith("_foot"):
                shift = shift + self._foot_aim_m()
            if not shift.any():
                if limb not in self._offsets:
                    continue
                dq, residual = np.zeros(len(JOINT_NAMES)), 0.0
            else:
                dq, residual = self._limb_shift_dq(limb, seg.last_line - 1, shift)
            self._offsets[limb] = _Blend(self._offset(limb), dq,
                                         float(seg.first_line - 1),
                                         float(seg.last_line - 1))
            self._shift_m[limb] = shift
            self._event(MotionEventKind.REACH_CORRECTION, limb, float(np.linalg.norm(shift)),
                        f"{hold.target} estimated {np.round(shift * 100, 1).tolist()} cm from "
                        f"the plan (IK residual {residual * 1000:.1f} mm)")

    # ------------------------------------------------------------------ grasps
    def _pending_grasp(self, k: int) -> tuple[str, str, np.ndarray] | None:
        """(side, rail, planned hold) of the hand segment ``k`` closes, if not yet verified."""
        seg = self.sidecar.segments[k]
        if seg.phase != "grasp":
            return None
        for limb, (_j, hold) in self._next_hold[k].items():
            side = _side(limb)
            if limb.endswith("_hand") and hold.target.startswith("rail") \
                    and (k, side) not in self._verified_segments:
                return side, hold.target, np.asarray(hold.position_m)
        return None

    def _grasp_due(self, line_index: int) -> _Regrasp | None:
        """A grasp that ends on this line and is not yet verified; or, on a grasp's first
        line, a hand whose target the ladder estimate has moved since it reached."""
        k = int(self._segment_of_line[line_index])
        seg = self.sidecar.segments[k]
        pending = self._pending_grasp(k)
        if pending is None:
            return None
        side, rail, planned = pending
        if line_index >= seg.last_line - 1:
            return _Regrasp(side, k, rail, planned, "verify", self._now)
        if line_index == seg.first_line - 1 and (k, side) not in self._arrived:
            limb = f"{side}_hand"
            wanted = self._ladder_shift(planned)
            if np.linalg.norm(wanted - self._shift_m.get(limb, np.zeros(3))) > SAME_TARGET_M:
                g = _Regrasp(side, k, rail, planned, "retarget", self._now)
                self._move_hand(g, wanted, "the ladder estimate moved its target")
                return g
            return _Regrasp(side, k, rail, planned, "arrive", self._now)
        return None

    def _catch_up_due(self, line_index: int, s: SensedState) -> _Regrasp | None:
        """A stiff reaching arm whose schedule turns it compliant after this line while
        its palm still lags its reference by more than ``arrival_tolerance_m``: the
        player waits in position mode for it (a compliant arm switched on far from its
        reference is flung by its PWM error; on DRC seed 6 under a 0.9, 1.3 cm, 1°
        placement error, a right arm 0.18 rad behind in shoulder pitch struck its rail,
        2026-11-29)."""
        for side, k in self._catch_up_at.get(line_index, ()):
            if (k, side) in self._caught_up or side in self._stiff_arms:
                continue
            self._caught_up.add((k, side))
            if self._palm_lag_m(side, s) <= self.config.arrival_tolerance_m:
                continue
            _j, hold = self._next_hold[k][f"{side}_hand"]
            return _Regrasp(side, k, hold.target, np.asarray(hold.position_m), "catch_up",
                            self._now)
        return None

    def _palm_lag_m(self, side: str, s: SensedState) -> float:
        """How far the sensed palm stands from where its reference puts it, in the pelvis
        frame (no pose estimate involved) [m]."""
        frame = f"{side[0].upper()}_palm"
        want = self.model.frame_in_pelvis(self._last_ref, frame)[:3, 3]
        got = self.model.frame_in_pelvis(s.pos_rad, frame)[:3, 3]
        return float(np.linalg.norm(got - want))

    def _candidates(self, g: _Regrasp) -> list[np.ndarray]:
        """Re-reach shifts [m]: first where the hands last found the rails
        (`_observe_held_rails`), then the miss as the estimate measured it, taken back
        across the rail (where the palm closed against where it was sent), then a pattern
        around the first. Each within the bound and different from where the hand closed
        last and from the others."""
        centre = self._ladder_shift(g.planned_m, self.rails)
        towards_ladder = -self.geometry.rung_line_normal
        step = self.config.search_step_m
        current = self._shift_m.get(f"{g.side}_hand", np.zeros(3))
        sent_m = g.planned_m + self._body_shift_m(g.planned_m) + current
        miss = self._across_rail(g, self.estimate.palm_m[g.side] - sent_m)
        pattern = [self._bounded(centre + step * (across * towards_ladder
                                                  + lateral * self.geometry.lateral_direction))
                   for across, lateral in SEARCH_PATTERN]
        out: list[np.ndarray] = []
        for shift in [centre, self._bounded(current - miss)] + pattern:
            if all(np.linalg.norm(shift - t) > SAME_TARGET_M for t in [current] + out):
                out.append(shift)
        return out

    def _across_rail(self, g: _Regrasp, offset_m: np.ndarray) -> np.ndarray:
        """``offset_m`` less its share along the rail of grasp ``g`` [m]."""
        axis = self._rail_direction(g.rail)
        return offset_m - (offset_m @ axis) * axis

    def _aim(self, g: _Regrasp) -> bool:
        """Move an arrived hand onto its rail where a hand last held that rail (before
        any grasp of it, where the ladder estimate puts the hold), if the estimate puts
        its palm farther than ``aim_tolerance_m`` across the rail from there. Returns
        whether it moves.

        The rail's last hold, not the rails estimate's fit: that fit is one shift for
        both rails, and it set the two hands' aims against each other by ±2–6 cm on the
        DRC ladder (2026-11-28)."""
        limb = f"{g.side}_hand"
        current = self._shift_m.get(limb, np.zeros(3))
        rail_m = self.rails.last_held_m(g.rail)
        if rail_m is None:
            rail_m = g.planned_m + self._ladder_shift(g.planned_m, relative_to_body=False)
        miss = self._across_rail(g, self.estimate.palm_m[g.side] - rail_m)
        if float(np.linalg.norm(miss)) <= self.config.aim_tolerance_m:
            return False
        self._move_hand(g, self._bounded(current - miss),
                        f"the palm stood {np.linalg.norm(miss) * 100:.1f} cm across its rail "
                        "from where it was last held; aimed before closing",
                        MotionEventKind.AIM)
        return True

    def _move_hand(self, g: _Regrasp, shift: np.ndarray, why: str,
                   kind: MotionEventKind | None = None) -> None:
        """Blend the hand's offset to one that moves it by ``shift`` [m], over shift_s."""
        limb = f"{g.side}_hand"
        dq, residual = self._limb_shift_dq(limb, self._line, shift)
        self._offsets[limb] = _Blend(self._offset(limb), dq, self._now,
                                     self._now + self.config.shift_s,
                                     time_based=True)
        self._shift_m[limb] = shift
        if kind is None:
            kind = MotionEventKind.RE_REACH if g.tries else MotionEventKind.REACH_CORRECTION
        self._event(kind, limb, float(np.linalg.norm(shift)),
                    f"{why}: target moved {np.round(shift * 100, 1).tolist()} cm (IK "
                    f"residual {residual * 1000:.1f} mm)")

    def _stiff_in_air(self, g: _Regrasp) -> bool:
        """Whether the arm's schedule moved it in position mode through the air on its way
        to this grasp (on any line of the reach that precedes it: a mixed arm still
        complies as it leaves its rail, and again on the last lines before it closes)."""
        limb = f"{g.side}_hand"
        reach = next((seg for seg in reversed(self.sidecar.segments[:g.segment])
                      if seg.phase == "limb" and limb in seg.moving_limbs), None)
        return reach is not None and \
            not self.player.schedule.pwm_by_line[g.side][reach.first_line - 1:reach.last_line].all()

    def _update_regrasp(self, s: SensedState) -> None:
        g, cfg, now = self._regrasp, self.config, self._now
        limb = f"{g.side}_hand"
        elapsed = now - g.since_s
        if g.phase == "retarget":
            if elapsed >= cfg.shift_s:
                self._settle_offset(limb)
                self._regrasp = None
                self.player.resume(now)
        elif g.phase == "catch_up":
            lag = self._palm_lag_m(g.side, s)
            if lag <= cfg.arrival_tolerance_m:
                self._event(MotionEventKind.ARRIVAL_WAIT, limb, lag,
                            f"waited {elapsed:.2f} s in position mode for the palm to reach "
                            f"its reference before the arm complies ({lag * 100:.1f} cm off "
                            "at the end)")
            elif elapsed >= cfg.arrival_timeout_s:
                self._stiffen(g.side, lag,
                              f"the arm stayed {lag * 100:.1f} cm behind its reference for "
                              f"{elapsed:.2f} s in position mode: it finishes the reach in "
                              "position mode until the grasp is verified")
            else:
                return
            self._regrasp = None
            self.player.resume(now)
        elif g.phase == "arrive":
            lag = self._palm_lag_m(g.side, s)
            if lag > cfg.arrival_tolerance_m and elapsed >= cfg.arrival_timeout_s \
                    and g.side not in self._stiff_arms | self._yielded \
                    and self._stiff_in_air(g):
                # the compliant arm cannot carry itself to the hold: it finishes the reach
                # in position mode, as it moved in the air, until its grasp is verified
                self._stiffen(g.side, lag,
                              f"the compliant arm stayed {lag * 100:.1f} cm from its reference "
                              f"for {elapsed:.2f} s: it finishes the reach in position mode "
                              "until the grasp is verified")
                g.since_s = now
                return
            if lag <= cfg.arrival_tolerance_m or elapsed >= cfg.arrival_timeout_s:
                self._arrived.add((g.segment, g.side))
                if elapsed > 0.0:
                    self._event(MotionEventKind.ARRIVAL_WAIT, limb, lag,
                                f"waited {elapsed:.2f} s for the palm to reach its reference "
                                f"before closing ({lag * 100:.1f} cm off at the end)")
                if self._aim(g):
                    g.phase, g.since_s = "retarget", now
                    return
                self._regrasp = None
                self.player.resume(now)
        elif g.phase == "seat":
            self._update_seat(g, s, elapsed)
        elif g.phase in ("verify", "close"):
            reading = self._grasp_reading(g.side, s)
            waited = cfg.verify_timeout_s + (cfg.close_s if g.phase == "close" else 0.0)
            if reading is GraspReading.ON_RAIL and (g.phase == "verify" or elapsed >= cfg.close_s):
                g.phase, g.since_s = "seat", now
                g.seat_time_s, g.seat_palm_m = s.time_s, self.estimate.palm_m[g.side].copy()
                return
            if reading is GraspReading.CLOSING and elapsed < waited:
                return
            if reading is GraspReading.ON_RAIL:
                return
            curl = self.estimate.finger_curl_rad[g.side]
            off = self.estimate.palm_m[g.side] - g.planned_m
            self._event(MotionEventKind.GRASP_MISSED, limb, 0.0,
                        f"fingers at {curl:.2f} rad ({reading.value}) on {g.rail}; palm "
                        f"{np.round(off * 100, 1).tolist()} cm from the planned hold")
            if g.tries == 0:
                g.candidates = self._candidates(g)
            if g.tries >= min(cfg.grasp_retries, len(g.candidates)):
                self._stop(g, f"{limb} closed on nothing after {g.tries} re-reach"
                              f"{'es' if g.tries != 1 else ''} for {g.rail}: the weight was "
                              "not moved onto it")
                return
            if g.side not in self._stiff_arms | self._yielded and self._stiff_in_air(g):
                # a hand that closed on nothing is in the air: a mixed arm re-reaches in
                # position mode, as it moved through the air, until its grasp is verified
                # (compliant, an open hand sagged 3–4 cm below each new target on ship)
                self._stiffen(g.side, 0.0, "closed on nothing: the arm re-reaches in position "
                                           "mode until the grasp is verified")
            g.tries += 1
            g.phase, g.since_s = "open", now
            self._open_fingers.add(g.side)
        elif g.phase == "open" and elapsed >= cfg.open_s:
            self._move_hand(g, g.candidates[g.tries - 1],
                            f"try {g.tries} of {cfg.grasp_retries}")
            g.phase, g.since_s = "shift", now
        elif g.phase == "shift" and elapsed >= cfg.shift_s:
            self._open_fingers.discard(g.side)
            g.phase, g.since_s = "close", now

    def _grasp_reading(self, side: str, s: SensedState) -> GraspReading:
        """What ``side``'s finger encoders say of its grip on this ladder's rails
        (`read_grasp`)."""
        return read_grasp(side, s.pos_rad, s.vel_rad_s, self.geometry.spec.rail_radius_m)

    def _update_seat(self, g: _Regrasp, s: SensedState, elapsed_s: float) -> None:
        """Fingers that read on-rail: the grasp is verified once the palm stands still in
        the grip (`SEATED_SPEED_M_S`), or after ``seat_timeout_s``, the fingers still
        reading on-rail. Fingers that close on past the rail lost it, and fingers still
        moving at the timeout are read afresh, as a grasp being verified."""
        reading = self._grasp_reading(g.side, s)
        if reading is GraspReading.EMPTY:
            g.phase = "verify"
            return
        window_s = s.time_s - g.seat_time_s
        if window_s < SEAT_WINDOW_S:
            return
        palm = self.estimate.palm_m[g.side]
        speed_m_s = float(np.linalg.norm(palm - g.seat_palm_m)) / window_s
        g.seat_time_s, g.seat_palm_m = s.time_s, palm.copy()
        timed_out = elapsed_s >= self.config.seat_timeout_s
        if reading is GraspReading.ON_RAIL and (speed_m_s <= SEATED_SPEED_M_S or timed_out):
            self._grasp_verified(g, elapsed_s, speed_m_s)
        elif timed_out:
            g.phase, g.since_s = "verify", self._now

    def _stiffen(self, side: str, size_m: float, cause: str) -> None:
        """Hold ``side``'s arm in position mode until its grasp is verified, as the mixed
        strategy moves an arm through the air (`_stiff_arms`)."""
        self._stiff_arms.add(side)
        self._event(MotionEventKind.STIFF_REACH, f"{side}_hand", size_m, cause)

    def _guard_stiff_arms(self, torque_nm: np.ndarray, dt: float) -> None:
        """A stiff arm one of whose joints has pushed past `STIFF_ARM_YIELD` of its limit
        (motor current) for `STIFF_ARM_YIELD_S` complies again until its grasp is
        verified: an open hand moved in position mode can meet the rail or a rung.
        ``torque_nm``: the sensed joint torques by column [N·m]."""
        for side in sorted(self._stiff_arms):
            cols = self._arm_cols[side]
            ratio = np.abs(torque_nm[cols]) / self._torque_limit_nm[cols]
            k = int(np.argmax(ratio))
            pushing = self._pushing_s.get(side, 0.0) + dt if ratio[k] > STIFF_ARM_YIELD else 0.0
            self._pushing_s[side] = pushing
            if pushing >= STIFF_ARM_YIELD_S:
                self._stiff_arms.discard(side)
                self._yielded.add(side)
                self._pushing_s.pop(side)
                self._event(MotionEventKind.STIFF_REACH, f"{side}_hand", 0.0,
                            f"{JOINT_NAMES[cols[k]]} pushed at {ratio[k]:.0%} of its torque "
                            f"limit for {pushing:.2f} s: the arm complies again until its "
                            "grasp is verified")

    def _settle_offset(self, limb: str) -> None:
        """A time-based offset stays where it is now while the limb holds (it has arrived,
        or a foot reaching down found its rung mid-way): index it by line again."""
        blend = self._offsets.get(limb)
        if blend is not None and blend.time_based:
            held = blend.end if self._now >= blend.t1 else blend.at(self._now)
            self._offsets[limb] = _Blend(held, held, float(self._line), float(self._line))

    def _grasp_verified(self, g: _Regrasp, seated_s: float, palm_speed_m_s: float) -> None:
        """The grasp holds (`_update_seat`): its palm, ``seated_s`` [s] after the fingers
        stopped on the rail and moving at ``palm_speed_m_s`` [m/s], measures the rail."""
        limb = f"{g.side}_hand"
        self._stiff_arms.discard(g.side)  # on the rail: the plan's compliance again
        self._yielded.discard(g.side)
        palm = self.estimate.palm_m[g.side]
        self._verified_segments.add((g.segment, g.side))
        self._settle_offset(limb)
        off = palm - g.planned_m
        self._event(MotionEventKind.GRASP_VERIFIED, limb, 0.0,
                    f"fingers at {self.estimate.finger_curl_rad[g.side]:.2f} rad on {g.rail}; "
                    f"palm {np.round(off * 100, 1).tolist()} cm from the planned hold, "
                    + (f"still in the grip after {seated_s:.2f} s"
                       if palm_speed_m_s <= SEATED_SPEED_M_S else
                       f"still moving at {palm_speed_m_s * 100:.1f} cm/s after {seated_s:.2f} s")
                    + (f"; {g.tries} re-reach{'es' if g.tries != 1 else ''}"
                       if g.tries else ""))
        observed = RailObservation(g.rail, g.planned_m, palm, self._rail_direction(g.rail))
        on_floor = self._feet_on_floor(self.sidecar.segments[g.segment])
        self.rails.add(observed, fits_yaw=on_floor)
        self._seat_grasp(g.side, g.rail, on_floor)
        self._held_rails[g.side] = (g.rail, g.planned_m)
        if on_floor:
            # standing on the floor, leg odometry is exact; on the ladder it carries the
            # feet's creep, which would read as the ladder moving
            self.ladder.add(observed)
            self._event(MotionEventKind.LADDER_ESTIMATE, "",
                        float(np.linalg.norm(self.ladder.shift_m)),
                        f"ladder shifted {np.round(self.ladder.shift_m * 100, 1).tolist()} "
                        f"cm, yawed {np.degrees(self.ladder.yaw_rad):.1f}°")
        self._regrasp = None
        if on_floor and self._misplaced_ladder():
            return  # the pose is held: the plan is for a ladder elsewhere
        self.player.resume(self._now)

    def _misplaced_ladder(self) -> bool:
        """With both rails measured from the floor, stop the climb (``ladder_misplaced``)
        if the plan's holds lie further than ``replan_beyond_m`` from where the ladder has
        them (`MotionConfig.replan_beyond_m`): the details give the ladder's measured
        placement change, for a new plan."""
        limit_m = self.config.replan_beyond_m
        if limit_m <= 0.0 or self.ladder.rails_fitting_yaw < 2 or not len(self._ladder_holds_m):
            return False
        offsets_m = [float(np.linalg.norm(self.ladder.correction_m(p)[:2]))
                     for p in self._ladder_holds_m]
        worst_m = max(offsets_m)
        if worst_m <= limit_m:
            return False
        shift_m, yaw_rad = self.ladder.shift_m, self.ladder.yaw_rad
        stance_m, heading_rad = self.stance()
        placed = self.ladder.placed(self.geometry.spec, stance_m, heading_rad)
        self.measured_ladder = placed
        placement = {"x_m": round(placed.placement_x_m, 4), "y_m": round(placed.placement_y_m, 4),
                     "yaw_rad": round(placed.placement_yaw_rad, 4)}
        reason = (f"the hands found the ladder shifted {np.round(shift_m[:2] * 100, 1).tolist()} "
                  f"cm and turned {np.degrees(yaw_rad):.1f}° from where the plan has it: its "
                  f"holds lie up to {worst_m * 100:.1f} cm from the real ones (re-plan beyond "
                  f"{limit_m * 100:.1f} cm); the weight was not moved onto the ladder. Plan "
                  "again with the spec's placement, seen from where the robot stands: "
                  + ", ".join(f"{k} = {v:g}" for k, v in placement.items()))
        self.stop = MotionStop(self._now, self._line + 1, "", reason,
                               FailureCause.LADDER_MISPLACED, 0,
                               {"shift_m": [round(float(v), 4) for v in shift_m],
                                "yaw_rad": round(float(yaw_rad), 5),
                                "worst_hold_m": round(worst_m, 4), "placement": placement,
                                "stance_m": [round(float(v), 4) for v in stance_m[:2]],
                                "stance_heading_rad": round(heading_rad, 5)})
        self._event(MotionEventKind.STOP, "", worst_m, reason)
        return True

    def _stop(self, g: _Regrasp, reason: str) -> None:
        self._open_fingers.add(g.side)
        self.stop = MotionStop(self._now, self._line + 1, f"{g.side}_hand", reason,
                               FailureCause.GRASP_UNVERIFIED, g.tries, {"rail": g.rail})
        self._event(MotionEventKind.STOP, f"{g.side}_hand", 0.0, reason)
        self._regrasp = None

    # ------------------------------------------------------------------ landings
    def _landing_due(self, line_index: int, s: SensedState) -> _Landing | None:
        """A foot whose step onto a rung ends on this line and whose F/T sensor does not
        show it standing yet."""
        k = int(self._segment_of_line[line_index])
        seg = self.sidecar.segments[k]
        if seg.phase != "limb" or line_index < seg.last_line - 1 or k in self._landed:
            return None
        for limb, (_j, hold) in self._next_hold[k].items():
            if limb.endswith("_foot") and self._on_ladder(hold.target):
                self._landed.add(k)
                side = _side(limb)
                if s.foot_load_n(side) >= self.config.landing_load_n:
                    return None
                return _Landing(side, k, hold.target, self._now)
        return None

    def _update_landing(self, s: SensedState) -> None:
        """Wait for the foot's load; then reach down towards its rung until it stands, or
        stop once the reach is spent."""
        f, cfg, now = self._landing, self.config, self._now
        limb = f"{f.side}_foot"
        load = s.foot_load_n(f.side)
        elapsed = now - f.since_s
        if load >= cfg.landing_load_n:
            self._event(MotionEventKind.FOOT_LANDING, limb,
                        self._landing_depth_m(f, elapsed),
                        f"stands on {f.target} ({load:.0f} N) after {elapsed:.2f} s"
                        + (" of reaching down" if f.phase == "reach" else " of waiting"))
            self._settle_offset(limb)
            self._landing = None
            self.player.resume(now)
            return
        if f.phase == "wait" and elapsed >= cfg.landing_wait_s:
            if cfg.landing_reach_m <= 0.0:
                self._stop_landing(f, load, 0.0)
                return
            # from where the step's own correction put the foot, straight down
            down = self._shift_m.get(limb, np.zeros(3)) + [0.0, 0.0, -cfg.landing_reach_m]
            dq, _residual = self._limb_shift_dq(limb, self._line, down)
            f.reach_s = cfg.landing_reach_m / cfg.landing_speed_m_s
            self._offsets[limb] = _Blend(self._offset(limb), dq, now, now + f.reach_s,
                                         time_based=True)
            f.phase, f.since_s = "reach", now
            self._event(MotionEventKind.FOOT_LANDING, limb, 0.0,
                        f"the step ended with the foot's F/T at {load:.0f} N (standing: "
                        f"{cfg.landing_load_n:.0f} N): it reaches down towards {f.target}, "
                        f"at most {cfg.landing_reach_m * 100:.0f} cm")
        elif f.phase == "reach" and elapsed >= f.reach_s:
            self._stop_landing(f, load, cfg.landing_reach_m)

    def _landing_depth_m(self, f: _Landing, elapsed_s: float) -> float:
        """How far down a reaching foot has gone [m]."""
        if f.phase != "reach" or f.reach_s <= 0.0:
            return 0.0
        return self.config.landing_reach_m * min_jerk(elapsed_s / f.reach_s)

    def _stop_landing(self, f: _Landing, load_n: float, reached_m: float) -> None:
        reason = (f"{f.side}_foot found no rung: its F/T read {load_n:.0f} N after reaching "
                  f"{reached_m * 100:.0f} cm below its planned hold on {f.target}: the weight "
                  "was not moved onto it")
        self._stop_step(f"{f.side}_foot", f.target, reason, 0, reached_m)
        self._landing = None

    def _stop_step(self, limb: str, rung: str, reason: str, tries: int, size_m: float) -> None:
        """Stop the climb on a step its foot could not finish; no weight moved onto it."""
        self.stop = MotionStop(self._now, self._line + 1, limb, reason,
                               FailureCause.FOOTHOLD_UNVERIFIED, tries, {"rung": rung})
        self._event(MotionEventKind.STOP, limb, size_m, reason)

    # ------------------------------------------------------------------ swing strikes
    def _strike_due(self, line_index: int, s: SensedState) -> _Strike | None:
        """A foot in the middle of its step whose F/T sensor reads a push from above, or a
        hand on its way to a rail that its wrist F/T shows pushed by the ladder: start its
        back-off (or, for a foot, stop the climb once its step has used its back-offs)."""
        k = int(self._segment_of_line[line_index])
        seg = self.sidecar.segments[k]
        if seg.phase != "limb" or line_index >= seg.last_line - 1:
            return None  # the step's end is the guarded landing's; a grasp's, the aim's
        cfg = self.config
        for limb in seg.moving_limbs:
            side = _side(limb)
            target = self._next_hold[k].get(limb, (k, None))[1]
            hold = target.target if target is not None else "its hold"
            if limb.endswith("_foot"):
                load = s.foot_load_n(side)
                if load > -cfg.strike_load_n:
                    continue
                away = -self.geometry.R_world_ladder[:, 0]  # horizontal, from the ladder
                direction = away + [0.0, 0.0, -STRIKE_DOWN_SHARE]
                why = (f"its F/T read {load:.0f} N (a foot in the air reads about −12 N): "
                       f"something presses on it from above on its way to {hold}")
                kind = MotionEventKind.FOOT_STRIKE
            else:
                load = float(s.hand_wrench(side)[2])
                if load < cfg.hand_strike_load_n or self._in_final_approach(side, line_index):
                    # on its compliant last stretch the hand meets the rail it goes to:
                    # its arm gives way, and the arrival and aim place it (backed off
                    # there, DRC seed 6's right hand under a 0.9, 1.3 cm, 1° placement
                    # error ended 8 cm from its rail and never held it, 2026-11-29)
                    continue
                # the ladder pushes the hand towards the wrist: it gives way along the push
                frame = self.model.chains[limb].frame
                direction = self.estimate.T_world_pelvis[:3, :3] @ \
                    self.model.frame_in_pelvis(s.pos_rad, frame)[:3, 2]
                why = (f"its wrist F/T read {load:.0f} N along the forearm (a hand in the "
                       f"air reads −3 to −12 N): the ladder pushes it on its way to {hold}")
                kind = MotionEventKind.HAND_STRIKE
            tries = self._strikes.get(k, 0)
            if tries >= cfg.strike_tries:
                if limb.endswith("_hand"):
                    continue  # its grasp is verified at the reach's end
                reason = (f"{limb} was pressed from above ({load:.0f} N on its F/T) on its "
                          f"way to {hold} after {tries} back-off{'s' if tries != 1 else ''}: "
                          "the step was not finished and no weight moved onto it")
                self._stop_step(limb, hold, reason, tries, 0.0)
                return None
            self._strikes[k] = tries + 1
            backoff = cfg.strike_backoff_m * (tries + 1)
            shift = self._shift_m.get(limb, np.zeros(3)) + backoff * np.asarray(direction)
            backoff_dq, _residual = self._limb_shift_dq(limb, line_index, shift)
            blend = self._offsets.get(limb)
            # the reach's own correction, reached at its last line (a first strike finds it
            # as the reach correction's blend; a later one as the last strike's)
            target_dq = blend.end if blend is not None else np.zeros_like(backoff_dq)
            self._offsets[limb] = _Blend(self._offset(limb), backoff_dq, self._now,
                                         self._now + cfg.strike_backoff_s, time_based=True)
            self._event(kind, limb, backoff,
                        f"{why}; it backs off {backoff * 100:.0f} cm and goes on from there "
                        "to the highest point of its reach")
            return _Strike(limb, k, self._now, backoff_dq, target_dq)
        return None

    def _update_strike(self) -> None:
        """Once the foot has backed off, go on: it keeps the back-off up to the highest
        point of its planned step, and reaches its hold from there."""
        f = self._strike
        if self._now < f.since_s + self.config.strike_backoff_s:
            return
        seg = self.sidecar.segments[f.segment]
        limb = f.limb
        # a foot keeps its back-off up to its step's highest point; a hand, whose reach
        # rises along its rail to the end, lets it go over the rest of the reach
        apex = self._apex_line(limb, self._line, seg.last_line - 1) \
            if limb.endswith("_foot") else self._line
        self._offsets[limb] = _Blend(f.backoff_dq, f.target_dq, float(apex),
                                     float(seg.last_line - 1))
        self._strike = None
        self.player.resume(self._now)

    def _apex_line(self, limb: str, first: int, last: int) -> int:
        """The line in [first, last] where the plan has ``limb`` highest (world, at the
        body's sensed tilt)."""
        frame = self.model.chains[limb].frame
        lines = np.arange(first, last + 1, APEX_STRIDE_LINES)
        up_in_pelvis = self.estimate.R_tilt[2]  # the world's z axis, in the pelvis frame
        heights = [float(up_in_pelvis @ self.model.frame_in_pelvis(self.trajectory_rad[line],
                                                                   frame)[:3, 3])
                   for line in lines]
        return int(lines[int(np.argmax(heights))])

    # ------------------------------------------------------------------ the tick
    def step(self, now_s: float, state_sample: np.ndarray) -> PlayerTick:
        """The command of the tick at ``now_s``, from the daemon's state sample."""
        self._now = now_s
        s = SensedState.from_sample(state_sample)
        self._pos_rad = s.pos_rad
        self.estimate = self.estimator.update(s)
        dt = 0.0 if self._last_now is None else now_s - self._last_now
        self._last_now = now_s
        self._sensed_torque_nm = self.motors.torque_nm(s.cur_a)
        self._guard_stiff_arms(self._sensed_torque_nm, dt)
        if self._regrasp is not None:
            self._update_regrasp(s)
        elif self._landing is not None:
            self._update_landing(s)
        elif self._strike is not None:
            self._update_strike()
        tick = self.player.step(now_s, s.pos_rad)
        self._line = tick.line_index
        k = int(self._segment_of_line[tick.line_index])
        if k != self._segment and not tick.going_to_init:
            self._segment = k
            self._enter_segment(k)
        if self._regrasp is None and self._landing is None and self._strike is None \
                and self.stop is None and not tick.going_to_init:
            due = self._catch_up_due(tick.line_index, s) or self._grasp_due(tick.line_index)
            if due is not None:
                self._regrasp = due
                self.player.pause(now_s)
            else:
                self._landing = self._landing_due(tick.line_index, s)
                if self._landing is None:
                    self._strike = self._strike_due(tick.line_index, s)
                if self._landing is not None or self._strike is not None \
                        or self.stop is not None:
                    self.player.pause(now_s)
        return self._command(tick, s, dt)

    def _command(self, tick: PlayerTick, s: SensedState, dt: float) -> PlayerTick:
        """The tick's references, modes and feed-forward; ``dt``: time since the last
        tick [s]."""
        plan_rad = tick.ref_rad
        ref = plan_rad.copy()
        for blend in self._offsets.values():
            ref += blend.on_tick(self._now, tick.line_index)
        for side in self._open_fingers:
            ref[self._finger_cols[side]] = 0.0
        self._last_ref = ref
        mode = tick.mode
        seg = self.sidecar.segments[int(self._segment_of_line[tick.line_index])]
        lifting: list[str] = []  # compliant arms gripping a rail
        closed: dict[str, str] = {}  # side → the rail its fingers are closed round
        for side in SIDES:
            hold = seg.holds.get(f"{side}_hand")
            cols = self._arm_cols[side]
            gripping = (hold is not None and hold.target.startswith("rail")
                        and bool(tick.comply[cols].all()))
            if gripping and side not in self._stiff_arms:
                lifting.append(side)
            # the wrist roll gives way while the fingers say the hand holds its rail, in
            # either arm mode and through a release until the fingers have let go: a
            # grip twisted against the rail loads it whatever the plan's phase
            wrist_roll = WRIST_ROLL[side]
            holding = closed_around_rail(side, s.pos_rad, self.geometry.spec.rail_radius_m)
            if holding:
                closed[side] = (hold.target if hold is not None and hold.target.startswith("rail")
                                else f"rail_{side}")
            ref[wrist_roll] += self.wrist_relief.update(wrist_roll, holding,
                                                        self._sensed_torque_nm, dt)
            share = self.config.holding_arm_stiffness
            if gripping and share < 1.0:
                soft = [c for c in cols if c != wrist_roll]
                ref[soft] = s.pos_rad[soft] + share * (ref[soft] - s.pos_rad[soft])
                if mode is tick.mode:
                    mode = tick.mode.copy()
                mode[soft] = RefMode.DIRECT  # the share is the stiffness; no filter lag
        comply = tick.comply
        if self._stiff_arms:
            comply = comply.copy()
            for side in self._stiff_arms:
                comply[self._arm_cols[side]] = False
        ff = tick.feedforward_nm
        if self.config.gravity_compensation and comply.any():  # else ff goes unused
            ff = self.gravity.feedforward_nm(ff, plan_rad, s.pos_rad, self.estimate.R_tilt)
        stance = self._stance_sides(seg)
        ff = self._relieve_legs(stance, lifting, closed, s, ff, dt)
        ff = self._relieve_bending(stance, lifting, closed, s, ff, dt)
        if ff is not tick.feedforward_nm or comply is not tick.comply:
            ff = np.where(comply, ff, 0.0)  # feed-forward acts only on compliant joints
        return dataclasses.replace(tick, ref_rad=ref, mode=mode, comply=comply,
                                   feedforward_nm=ff)

    def _stance_sides(self, seg: Segment) -> tuple[str, ...]:
        """The sides whose feet hold in ``seg`` and stand, as their F/T sensors show."""
        return tuple(side for side in SIDES if f"{side}_foot" in seg.holds
                     and self.estimate.standing.get(side, False))

    def _relieve_legs(self, stance: tuple[str, ...], lifting: list[str],
                      closed: dict[str, str], s: SensedState, ff: np.ndarray,
                      dt: float) -> np.ndarray:
        """``ff`` plus the leg relief's lift on the ``lifting`` arms (`LegRelief`) for the
        ``stance`` legs, bounded by the loads of the grips ``closed`` (side → rail)."""
        relief = self.leg_relief
        before, was_bound = relief.lift_n, relief.grip_bound
        # side → (share, load) of each closed grip; only a lift on or due needs them
        needed = bool(lifting) and relief.needs_grip_share(stance, self._sensed_torque_nm)
        grips = {side: self.grip_load.release_share(
                     side, s.pos_rad, self.estimate.R_tilt, self._sensed_torque_nm,
                     self._rail_direction(rail))
                 for side, rail in closed.items()} if needed else {}
        side = max(grips, key=lambda k: grips[k][0], default="")
        share, what = grips.get(side, (0.0, ""))
        lift = relief.update(stance, bool(lifting), self._sensed_torque_nm, dt, share)
        if relief.grip_bound and not was_bound and before > 0.0:
            self._event(MotionEventKind.LEG_RELIEF, f"{side}_hand", 0.0,
                        f"{what} at {share:.0%} of what the {side} grip holds: the lift "
                        f"of {before:.0f} N gives way")
        if before == 0.0 and lift > 0.0:
            self._event(MotionEventKind.LEG_RELIEF, "", 0.0,
                        f"{JOINT_NAMES[relief.joint_col]} at {relief.load_share:.0%} of its "
                        "torque limit: the "
                        f"{' and '.join(lifting)} arm{'s' if len(lifting) > 1 else ''} "
                        "lift more")
        if lift == 0.0:
            return ff
        return ff + relief.feedforward_nm(lifting, s.pos_rad, self.estimate.R_tilt,
                                          self._sensed_torque_nm)

    def _relieve_bending(self, stance: tuple[str, ...], lifting: list[str],
                         closed: dict[str, str], s: SensedState, ff: np.ndarray,
                         dt: float) -> np.ndarray:
        """``ff`` plus each compliant gripping arm's bending relief
        (`GripBendingRelief`), for the arms ``lifting`` whose fingers are ``closed``
        (side → rail), sparing the ``stance`` legs."""
        relief = self.bending_relief
        if relief is None:
            return ff
        for side in SIDES:
            rail = closed.get(side)
            holding = side in lifting and rail is not None
            was_on = side in relief.active
            relief.update(side, holding, s.pos_rad, self.estimate.R_tilt,
                          self._sensed_torque_nm,
                          self._rail_direction(rail) if holding else np.zeros(3), dt,
                          stance)
            if side in relief.active and not was_on:
                share = relief.share[side]
                self._event(MotionEventKind.GRIP_RELIEF, f"{side}_hand", 0.0,
                            f"bending torque at {share:.0%} of what the {side} grip holds: "
                            f"its arm takes the excess off by feed-forward")
            if holding and side in relief.moment_nm:
                ff = ff + relief.feedforward_nm(side, s.pos_rad, self.estimate.R_tilt)
        return ff

    # ------------------------------------------------------------------ report
    def report(self) -> dict:
        """What the layer did, for the result JSON."""
        counts: dict[str, int] = {}
        for ev in self.events:
            counts[ev.kind.value] = counts.get(ev.kind.value, 0) + 1
        return {
            "config": {"gravity_compensation": self.config.gravity_compensation,
                       "holding_arm_stiffness": self.config.holding_arm_stiffness,
                       "arm_max_pwm_pct": float(self.pwm_gains.max_pwm_pct.max()),
                       "max_reach_correction_m": self.config.max_reach_correction_m,
                       "max_body_trim_m": self.config.max_body_trim_m,
                       "grasp_retries": self.config.grasp_retries,
                       "grip_bending_onset": self.config.grip_bending_onset},
            "counts": counts,
            "ladder_shift_m": [round(float(v), 4) for v in self.ladder.shift_m],
            "ladder_yaw_rad": round(self.ladder.yaw_rad, 4),
            "body_trim_m": round(self._body_trim_m, 4),
            "leg_relief_peak_n": round(self.leg_relief.peak_lift_n, 1),
            "leg_relief_joint": self.leg_relief.peak_joint,
            "grip_bending_relief_peak_nm": (0.0 if self.bending_relief is None else
                                            round(self.bending_relief.peak_moment_nm, 2)),
            "stop": None if self.stop is None else dataclasses.asdict(self.stop),
            "events": [ev.to_json() for ev in self.events],
        }
