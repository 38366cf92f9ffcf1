"""The trajectory player: a 40-column trajectory + options → per-tick references and modes.

This is hubo-read-trajectory's logic (hubo-facts §2) without its I/O: no file reading, no
sleeping, no channel. The caller passes the time in, so one object serves both

- lock-step (``validate-plan``): ``player.step(n * TICK_S, pos_rad)`` for n = 0, 1, …;
- real time (``play-trajectory``): ``player.step(time.monotonic(), pos_rad)`` every tick.

Timing. Playback starts at the first :meth:`TrajectoryPlayer.step` (or an explicit
:meth:`TrajectoryPlayer.start`). With rate f and start row s (0-based, ``start_line − 1``),
row ``s + k`` is the reference from ``T_init + k/f`` on, held until the next row
(zero-order hold; the daemon's reference filter smooths the steps, as on the robot). At
the end the last row stays the reference and ``finished`` becomes true once that row has
had its full 1/f. Pauses freeze the clock: resuming continues where it stopped and the
whole remaining schedule shifts by the pause (no catch-up).

Go-to-init (``-i``). From the measured pose at start to the start row, over
``go_to_init_s`` (3 s by default, the thesis figure) along a minimum-jerk blend
``s(u) = 10u³ − 15u⁴ + 6u⁵``, which starts and ends with zero velocity and acceleration.
The original code blended linearly (200 steps of 10 ms), which jerks at both ends. During
the move the arms are in the modes of the start row.

Modes. The reference mode of every joint is FILTER, or DIRECT with ``no_filter``
(``-nf``). Arms (shoulder, elbow, wrist: 7 joints each) switch between position and PWM
per line from a sidecar run-length schedule; ``-c``/``-cl``/``-cr`` force the named arm(s)
to PWM for the whole file, overriding the schedule for that arm only. The wrist roll is
asked to comply with its arm; the control law (``daemon.joint_control``) knows it cannot.

Feed-forward. A compliant arm that tracks its reference gives almost no torque, so a
sidecar may carry the arm torques the plan needs (`robot.plan_sidecar.ArmFeedforward`:
the torque LP's share of the load for a hand on a rail, the arm's own weight for a hand
in the air); each tick carries them, interpolated between the sampled lines, for the
joints in PWM mode (0 elsewhere, and during go-to-init), with the velocity the daemon's
reference filter will give the reference (the motor's back-EMF costs duty while it
moves). `TrajectoryPlayer.feedforward_duty` turns them into hubo-ach's feed-forward duty
(``pwm_command``) at the battery voltage the caller knows.

A holding arm. An arm in PWM mode keeps hubo-ach's law while its hand holds the rail:
its stiffness towards the reference (kp) plus the feed-forward. The closed chain through
the rail leaves the arm's pose free (a hand turns on its rail, `daemon.sim.grasp_latch`),
and the stiffness is what holds it there (docs/decisions/arm-feedforward.md).

The per-arm schedule is `execute.play.arm_modes`'s.

Size: one state machine (hubo-read-trajectory's: go-to-init, play, pause, finish) and
what it applies each tick (the arms' modes, the feed-forward).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from daemon.control_modes import TICK_S, RefMode, default_filter_config, filter_reference
from daemon.pwm import feedforward_duty_pct
from execute.play.arm_modes import ArmModeSchedule, ModeScheduleError
from robot.errors import HuboLadderError, InputError
from robot.joints import ARM_JOINTS, NUM_JOINTS, joint_indices
from robot.motors import MotorTable
from robot.plan_sidecar import ArmFeedforward
from robot.vocabulary import ARM_MODES, SIDES

__all__ = [
    "ALLOWED_RATES_HZ",
    "ARMS",
    "ARM_MODES",
    "PlayerOptionError",
    "PlayerOptions",
    "PlayerStateError",
    "PlayerTick",
    "TrajectoryPlayer",
    "compliant_arms_from_flags",
    "min_jerk",
]

#: Line rates hubo-read-trajectory accepted [Hz] (the thesis lists all but 500).
ALLOWED_RATES_HZ = (10, 25, 50, 100, 200, 500)
ARMS = SIDES
_EPS_LINES = 1e-9  # [lines] float slack so that t = k/f exactly lands on line k


class PlayerOptionError(InputError):
    """A player option or the trajectory array is refused; names the option and range."""


class PlayerStateError(HuboLadderError):
    """The player was used out of order (e.g. paused before it started)."""


def compliant_arms_from_flags(c: bool = False, cl: bool = False, cr: bool = False) -> frozenset:
    """The arms forced compliant by hubo-read-trajectory's ``-c``, ``-cl``, ``-cr``.

    Args:
        c: ``-c``, both arms.
        cl: ``-cl``, the left arm.
        cr: ``-cr``, the right arm.

    Returns:
        A subset of ``{"left", "right"}``.
    """
    arms = set()
    if c or cl:
        arms.add("left")
    if c or cr:
        arms.add("right")
    return frozenset(arms)


@dataclass(frozen=True)
class PlayerOptions:
    """Playback options (the flags of hubo-read-trajectory).

    Attributes:
        rate_hz: line rate [Hz], one of :data:`ALLOWED_RATES_HZ` (``-f``, default 25).
        go_to_init: move smoothly to the start line first (``-i``).
        go_to_init_s: duration of that move [s] (thesis default 3 s).
        compliant_arms: arms forced to PWM for the whole file (``-c``/``-cl``/``-cr``).
        no_filter: send references in DIRECT mode instead of FILTER (``-nf``).
        start_line: 1-based line to start from (``-line``).
    """

    rate_hz: int = 25
    go_to_init: bool = False
    go_to_init_s: float = 3.0
    compliant_arms: frozenset = field(default_factory=frozenset)
    no_filter: bool = False
    start_line: int = 1

    def __post_init__(self) -> None:
        rate = self.rate_hz
        if (
            isinstance(rate, bool)
            or not isinstance(rate, int | float | np.number)
            or rate not in ALLOWED_RATES_HZ
        ):
            raise PlayerOptionError(
                f"rate_hz = {rate!r} is not allowed; choose one of "
                f"{', '.join(map(str, ALLOWED_RATES_HZ))} Hz"
            )
        object.__setattr__(self, "rate_hz", int(rate))
        if not (math.isfinite(self.go_to_init_s) and self.go_to_init_s > 0.0):
            raise PlayerOptionError(f"go_to_init_s = {self.go_to_init_s!r}: must be > 0 [s]")
        arms = frozenset(
            [self.compliant_arms] if isinstance(self.compliant_arms, str) else self.compliant_arms
        )
        if not arms <= set(ARMS):
            raise PlayerOptionError(
                f"compliant_arms = {sorted(arms)!r}: allowed arms are {', '.join(ARMS)}"
            )
        object.__setattr__(self, "compliant_arms", arms)
        if (
            isinstance(self.start_line, bool)
            or not isinstance(self.start_line, int | np.integer)
            or self.start_line < 1
        ):
            raise PlayerOptionError(f"start_line = {self.start_line!r}: must be an integer >= 1")

    @property
    def period_s(self) -> float:
        """Time per line [s]."""
        return 1.0 / self.rate_hz


@dataclass(frozen=True, eq=False)
class PlayerTick:
    """What the player commands on one daemon tick.

    Attributes:
        ref_rad: reference per joint [rad], shape (40,).
        mode: :class:`~daemon.control_modes.RefMode` per joint, shape (40,) int8.
        comply: joints asked to be compliant (PWM), shape (40,) bool.
        feedforward_nm: feed-forward torque of the compliant joints [N·m], shape (40,).
        velocity_rad_s: velocity of the reference as the daemon's filter sends it
            [rad/s], shape (40,); 0 during go-to-init and pauses, and without
            feed-forward (only the feed-forward uses it).
        line_index: 0-based trajectory row being played (the start row during go-to-init).
        arm_modes: arm → ``"position"`` or ``"pwm"``.
        going_to_init: the go-to-init move is in progress.
        paused: playback is paused (the reference is held).
        finished: the last line has had its full period; its reference is held.

    ``mode`` and ``comply`` are shared read-only arrays; copy them to modify.
    """

    ref_rad: np.ndarray
    mode: np.ndarray
    comply: np.ndarray
    feedforward_nm: np.ndarray
    velocity_rad_s: np.ndarray
    line_index: int
    arm_modes: Mapping[str, str]
    going_to_init: bool
    paused: bool
    finished: bool

    @property
    def line_number(self) -> int:
        """1-based line number in the file."""
        return self.line_index + 1

    def __repr__(self) -> str:
        if self.finished:
            phase = "finished"
        elif self.paused:
            phase = "paused"
        else:
            phase = "init" if self.going_to_init else "play"
        return (
            f"PlayerTick(line={self.line_number}, {phase}, "
            f"left={self.arm_modes['left']}, right={self.arm_modes['right']})"
        )


def min_jerk(u: float) -> float:
    """Minimum-jerk blend ``10u³ − 15u⁴ + 6u⁵`` of a phase u, clipped to [0, 1]."""
    u = min(max(u, 0.0), 1.0)
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u))


class TrajectoryPlayer:
    """Plays a validated (N, 40) trajectory tick by tick (see the module docstring).

    Args:
        trajectory_rad: the trajectory [rad], shape (N, 40), N >= 1, all finite (as
            returned by ``robot.trajectory_file.read_trajectory``).
        options: playback options; defaults (25 Hz, no init, filter mode) when None.
        schedule: per-arm mode schedule (``ArmModeSchedule`` or the sidecar's run-length
            mapping); both arms in position mode when None.
        feedforward: the sidecar's arm torques; no feed-forward when None.

    Raises:
        PlayerOptionError: a bad trajectory array, or ``start_line`` beyond its end.
        ModeScheduleError: a bad schedule, or feed-forward rows that do not cover the file.
    """

    def __init__(
        self,
        trajectory_rad: np.ndarray,
        options: PlayerOptions | None = None,
        schedule: ArmModeSchedule | Mapping[str, Sequence[tuple[int, int, str]]] | None = None,
        feedforward: ArmFeedforward | None = None,
    ):
        self.options = options or PlayerOptions()
        traj = np.array(trajectory_rad, dtype=float)
        if traj.ndim != 2 or traj.shape[1] != NUM_JOINTS or traj.shape[0] < 1:
            raise PlayerOptionError(
                f"trajectory has shape {traj.shape}; expected (N, {NUM_JOINTS}) with N >= 1"
            )
        if not np.isfinite(traj).all():
            row, col = np.argwhere(~np.isfinite(traj))[0]
            raise PlayerOptionError(f"trajectory line {row + 1} column {col + 1} is not finite")
        traj.setflags(write=False)
        self.trajectory_rad = traj
        n = traj.shape[0]
        if self.options.start_line > n:
            raise PlayerOptionError(
                f"start_line = {self.options.start_line} is beyond the last line ({n})"
            )
        if schedule is None:
            schedule = ArmModeSchedule.all_position(n)
        elif not isinstance(schedule, ArmModeSchedule):
            schedule = ArmModeSchedule.from_runs(schedule, n)
        if schedule.num_lines != n:
            raise ModeScheduleError(
                f"mode schedule covers {schedule.num_lines} lines; the trajectory has {n}"
            )
        self._pwm_by_line = {
            arm: np.ones(n, dtype=bool)
            if arm in self.options.compliant_arms
            else schedule.pwm_by_line[arm]
            for arm in ARMS
        }
        self.schedule = ArmModeSchedule(MappingProxyType(dict(self._pwm_by_line)))
        mode = RefMode.DIRECT if self.options.no_filter else RefMode.FILTER
        self._mode = np.full(NUM_JOINTS, mode, dtype=np.int8)
        self._mode.setflags(write=False)
        arm_idx = {arm: joint_indices(ARM_JOINTS[arm]) for arm in ARMS}
        self._comply = {}
        for left in (False, True):
            for right in (False, True):
                mask = np.zeros(NUM_JOINTS, dtype=bool)
                mask[arm_idx["left"]] = left
                mask[arm_idx["right"]] = right
                mask.setflags(write=False)
                self._comply[(left, right)] = mask
        self._arm_modes = {(left, right): MappingProxyType({"left": ARM_MODES[left],
                                                            "right": ARM_MODES[right]})
                           for left, right in self._comply}
        if feedforward is not None and len(feedforward.torque_nm) != feedforward.rows_for(n):
            raise ModeScheduleError(
                f"feed-forward has {len(feedforward.torque_nm)} rows; {n} lines every "
                f"{feedforward.every_lines} need {feedforward.rows_for(n)}")
        self._feedforward = feedforward
        self._ff_cols = None if feedforward is None else joint_indices(feedforward.joints)
        self._filtered_rad: np.ndarray | None = None
        self._filter_length = default_filter_config().filter_length
        self._start_row = self.options.start_line - 1
        self._init_s = self.options.go_to_init_s if self.options.go_to_init else 0.0
        self._t0_s: float | None = None
        self._init_from_rad: np.ndarray | None = None
        self._last_now_s = -math.inf
        self._paused_since_s: float | None = None
        self._paused_total_s = 0.0

    # ----------------------------------------------------------------- schedule
    @property
    def has_feedforward(self) -> bool:
        """Whether ticks carry the sidecar's arm feed-forward."""
        return self._feedforward is not None

    @property
    def num_lines(self) -> int:
        """Lines in the trajectory."""
        return self.trajectory_rad.shape[0]

    @property
    def duration_s(self) -> float:
        """Time from start to ``finished`` without pauses [s]."""
        return self._init_s + (self.num_lines - self._start_row) / self.options.rate_hz

    def time_of_line(self, line_index: int) -> float:
        """When 0-based row ``line_index`` becomes the reference, after start, no pauses [s]."""
        if not self._start_row <= line_index < self.num_lines:
            raise PlayerOptionError(
                f"line index {line_index} is outside {self._start_row}..{self.num_lines - 1}"
            )
        return self._init_s + (line_index - self._start_row) / self.options.rate_hz

    @property
    def started(self) -> bool:
        """Whether playback has started."""
        return self._t0_s is not None

    @property
    def paused(self) -> bool:
        """Whether playback is paused."""
        return self._paused_since_s is not None

    # ----------------------------------------------------------------- control
    def start(self, now_s: float, current_pos_rad: np.ndarray | None = None) -> None:
        """Starts playback at ``now_s`` (``step`` does this on its first call).

        Args:
            now_s: current time [s], any monotonic clock.
            current_pos_rad: measured pose [rad], shape (40,); required with go-to-init.

        Raises:
            PlayerStateError: already started.
            PlayerOptionError: go-to-init without a valid current pose.
        """
        if self.started:
            raise PlayerStateError("the player has already started")
        if self.options.go_to_init:
            if current_pos_rad is None:
                raise PlayerOptionError("go_to_init needs the current pose (current_pos_rad)")
            pos = np.array(current_pos_rad, dtype=float)
            if pos.shape != (NUM_JOINTS,) or not np.isfinite(pos).all():
                raise PlayerOptionError(
                    f"current_pos_rad must be {NUM_JOINTS} finite values; got shape {pos.shape}"
                )
            self._init_from_rad = pos
        self._t0_s = float(now_s)
        self._last_now_s = float(now_s)

    def pause(self, now_s: float) -> None:
        """Freezes playback at ``now_s``; the reference is held. No-op when paused."""
        now = self._clock(now_s)
        if self._paused_since_s is None:
            self._paused_since_s = now

    def resume(self, now_s: float) -> None:
        """Continues from where playback stopped; the rest of the schedule shifts."""
        now = self._clock(now_s)
        if self._paused_since_s is not None:
            self._paused_total_s += now - self._paused_since_s
            self._paused_since_s = None

    def toggle_pause(self, now_s: float) -> bool:
        """The ``p`` key: pause if playing, resume if paused. Returns the new paused state."""
        if self.paused:
            self.resume(now_s)
        else:
            self.pause(now_s)
        return self.paused

    def step(self, now_s: float, current_pos_rad: np.ndarray | None = None) -> PlayerTick:
        """The command for the daemon tick at ``now_s``.

        Args:
            now_s: current time [s]; in lock-step ``n * TICK_S``. A time earlier than the
                last one is treated as the last one.
            current_pos_rad: measured pose [rad]; used only when starting with go-to-init.

        Returns:
            The reference, modes and status of this tick.
        """
        if not self.started:
            self.start(now_s, current_pos_rad)
        t_s = self._play_time_s(self._clock(now_s))
        going_to_init = t_s < self._init_s - _EPS_LINES / self.options.rate_hz
        if going_to_init:
            row = self._start_row
            target = self.trajectory_rad[row]
            blend = min_jerk(t_s / self._init_s)
            ref = self._init_from_rad + blend * (target - self._init_from_rad)
            finished = False
        else:
            k = math.floor((t_s - self._init_s) * self.options.rate_hz + _EPS_LINES)
            finished = self._start_row + k >= self.num_lines
            row = min(self._start_row + max(k, 0), self.num_lines - 1)
            ref = self.trajectory_rad[row].copy()
        left = bool(self._pwm_by_line["left"][row])
        right = bool(self._pwm_by_line["right"][row])
        comply = self._comply[(left, right)]
        feedforward, velocity = self._feedforward_tick(ref, row, comply, going_to_init)
        return PlayerTick(
            ref_rad=ref,
            mode=self._mode,
            comply=comply,
            feedforward_nm=feedforward,
            velocity_rad_s=velocity,
            line_index=row,
            arm_modes=self._arm_modes[(left, right)],
            going_to_init=going_to_init,
            paused=self.paused,
            finished=finished,
        )

    def feedforward_duty(self, tick: PlayerTick, battery_v: float,
                         motors: MotorTable | None = None) -> np.ndarray | None:
        """The tick's feed-forward as duty [%] (`daemon.pwm.feedforward_duty_pct`, with
        the reference's velocity), or None when the player has no feed-forward."""
        if self._feedforward is None:
            return None
        return feedforward_duty_pct(tick.feedforward_nm, battery_v, tick.velocity_rad_s,
                                    motors)

    # ----------------------------------------------------------------- internals
    def _feedforward_tick(self, ref: np.ndarray, row: int, comply: np.ndarray,
                          going_to_init: bool) -> tuple[np.ndarray, np.ndarray]:
        """(feed-forward [N·m], reference velocity [rad/s]) of a tick: zeros without
        feed-forward (module docstring)."""
        feedforward = np.zeros(NUM_JOINTS)
        if self._feedforward is None:
            return feedforward, np.zeros(NUM_JOINTS)
        velocity = self._filter_velocity(ref, going_to_init)
        if going_to_init:
            return feedforward, velocity
        feedforward[self._ff_cols] = self._feedforward_at(row)
        feedforward[~comply] = 0.0
        return feedforward, velocity

    def _filter_velocity(self, ref: np.ndarray, going_to_init: bool) -> np.ndarray:
        """Velocity of ``ref`` through the daemon's reference filter [rad/s] (0 while
        paused or going to the start line, where the filter is reset onto ``ref``)."""
        prev = self._filtered_rad
        if prev is None or going_to_init:
            self._filtered_rad = ref.copy()
            return np.zeros(NUM_JOINTS)
        if self.paused:
            return np.zeros(NUM_JOINTS)
        self._filtered_rad = filter_reference(self._mode, ref, prev, prev, self._filter_length)
        return (self._filtered_rad - prev) / TICK_S

    def _feedforward_at(self, row: int) -> np.ndarray:
        """The feed-forward torques of 0-based ``row``, linear between sampled rows."""
        ff = self._feedforward
        k, rest = divmod(row, ff.every_lines)
        if rest == 0:
            return ff.torque_nm[k]
        u = rest / ff.every_lines
        return (1.0 - u) * ff.torque_nm[k] + u * ff.torque_nm[k + 1]

    def _clock(self, now_s: float) -> float:
        if not self.started:
            raise PlayerStateError("start the player (or step it once) before pausing")
        now = max(float(now_s), self._last_now_s)
        self._last_now_s = now
        return now

    def _play_time_s(self, now_s: float) -> float:
        paused_s = self._paused_total_s
        if self._paused_since_s is not None:
            paused_s += now_s - self._paused_since_s
        return now_s - self._t0_s - paused_s
