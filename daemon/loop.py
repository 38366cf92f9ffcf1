"""The daemon's 200 Hz loop: channels in, one control law, a backend out, state and log.

Every 5 ms tick, at an absolute deadline ``t0 + k·period`` (``CLOCK_MONOTONIC`` [ns]):

1. ``backend.step(dt)``: the boards have run for ``dt`` since the last tick with the
   commands then in force (the MuJoCo backend integrates the physics here; real boards
   need nothing);
2. ``backend.read_sensors()``: encoders, velocities, currents, status, FT, IMU, power;
3. board commands (``board-cmd``) and gain sets (``pwm-gains``) newer than the last one
   handled are carried out;
4. the reference: the newest ``ref`` sample (its neck joints overridden by ``ref-neck``),
   or a hold, see below;
5. the per-joint control law, `daemon.joint_control.JointController`, the same object
   ``validate-plan`` runs in lock-step (`execute.validate.simulate`);
6. ``backend.write_commands(...)``: references, PWM duties and modes to the boards;
7. the state: written to the ``state`` channel and appended to the state log;
8. ``backend.idle(next_deadline)`` (the CAN backend spreads its sends here), then sleep
   until the next deadline.

Overruns. When a tick's work ends after the next deadline, the loop does not run the
missed ticks back to back (hubo-ach did): it skips to the first deadline still in the
future and adds the number of skipped deadlines to ``state["overruns"]``. The backend's
next ``step`` covers the whole gap, so simulated time keeps pace with the wall clock.

Holds. A joint keeps its last sent reference (mode DIRECT with ``r = f``, exactly still):

- *watchdog*: the newest ``ref`` sample is older than ``watchdog_s`` while its
  ``playing`` flag is set (a player that died or hangs); compliance stays as last asked;
- *no reference*: nothing was written on ``ref`` since the daemon started (samples left
  from before start-up are ignored, so a stale reference never moves the robot);
- *a malformed sample* (non-finite reference, mode outside 0..3): refused and logged.

Limits. A joint whose commanded reference lies beyond its limits keeps its previous
accepted reference (the control law rejects it, `JointController`); the other joints of
the sample are followed. This holds for every writer (player, console, a script on the
channel). Each such sample is logged once with the joints, values and allowed ranges,
and counted in ``state["refs_rejected"]``; the joints carry ``REF_REJECTED`` in their
status while the sample stands.

Gates. A joint's references are ignored (it holds its gate reference, rigid) while it is
not homed, for ``home_ignore_s`` after a home command (3 s), for ``startup_ignore_s``
after start-up (0.8 s, hubo-facts §3) and while its control is off (then its board
drives zero PWM duty: limp). The state reports such joints with ``NOT_HOMED``.

Board commands are latest-value samples: two written within one tick, only the newer is
seen. Writers (``hubo-console``) wait for the next ticks before sending another.

Size: the tick's steps (backend, reference gates, control law, commands, state,
log, watchdog) share the loop's state each 5 ms, and are kept in the order they run.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from daemon.backend import Backend, BoardCommands, SensorFrame
from daemon.channels import Channel, open_channel
from daemon.control_modes import RefMode
from daemon.joint_control import JointController
from daemon.pwm import PwmGainError, PwmGains, default_drc_gains
from daemon.state_log import LOG_DTYPE, StateLogWriter
from daemon.structs import (
    STATE_DTYPE,
    BoardCommandType,
    StatusFlag,
)
from robot.constants import DAEMON_RATE_HZ
from robot.errors import InputError
from robot.joints import JOINT_INDEX, JOINT_NAMES, NECK_AND_WAIST, NUM_JOINTS
from robot.pwm_gains import PWM_COMMAND_LIMIT_PCT

__all__ = [
    "DaemonChannels",
    "DaemonLoop",
    "LoopConfig",
    "LoopStats",
    "default_config",
    "set_realtime_priority",
    "sleep_until_ns",
]

log = logging.getLogger(__name__)

NECK_JOINTS = np.array([JOINT_INDEX[n] for n in NECK_AND_WAIST[:3]])  # NKY, NK1, NK2
_MODES = np.array([m.value for m in RefMode])
_GAIN_FIELDS = ("kp", "kd", "max_pwm_pct")  # SET_GAINS dvalues[0..2], params[0] bit 0..2


@dataclass(frozen=True)
class LoopConfig:
    """Tunables of the loop.

    Attributes:
        rate_hz: loop rate [Hz] (hubo-ach: 200).
        watchdog_s: a ``ref`` sample older than this while ``playing`` holds [s].
        home_ignore_s: references ignored after a home command [s] (hubo-ach: 3).
        startup_ignore_s: references ignored after start-up [s] (hubo-ach: 0.8).
        status_period_s: how often the status callback runs [s].
    """

    rate_hz: float = DAEMON_RATE_HZ
    watchdog_s: float = 0.2
    home_ignore_s: float = 3.0
    startup_ignore_s: float = 0.8
    status_period_s: float = 1.0

    def __post_init__(self) -> None:
        for name in ("rate_hz", "watchdog_s", "status_period_s"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name} = {v!r}: must be > 0")
        for name in ("home_ignore_s", "startup_ignore_s"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise InputError(f"{name} = {v!r}: must be >= 0 [s]")

    @property
    def period_ns(self) -> int:
        """One tick [ns]."""
        return round(1e9 / self.rate_hz)


def default_config() -> LoopConfig:
    """200 Hz, 0.2 s watchdog, hubo-ach's 3 s / 0.8 s reference gates."""
    return LoopConfig()


@dataclass
class DaemonChannels:
    """The five channels of one daemon instance."""

    ref: Channel
    ref_neck: Channel
    board_cmd: Channel
    pwm_gains: Channel
    state: Channel

    @classmethod
    def open(cls, instance: str = "default", in_process: bool = False,
             writer_id: int | None = None) -> DaemonChannels:
        """Open (creating if needed) the channels of daemon ``instance``."""
        def ch(name: str) -> Channel:
            return open_channel(name, instance, writer_id=writer_id, in_process=in_process)

        return cls(ch("ref"), ch("ref-neck"), ch("board-cmd"), ch("pwm-gains"), ch("state"))

    def close(self) -> None:
        for c in (self.ref, self.ref_neck, self.board_cmd, self.pwm_gains, self.state):
            c.close()


@dataclass
class LoopStats:
    """Counters of a run (also in every state record)."""

    ticks: int = 0
    overruns: int = 0
    watchdog_trips: int = 0
    cmds_done: int = 0
    cmds_refused: int = 0
    refs_rejected: int = 0  # ref samples with a joint beyond its limits
    gains_version: int = 0
    max_late_ns: int = 0
    starts_ns: list[int] = field(default_factory=list)  # with record_starts


def set_realtime_priority(priority: int) -> str | None:
    """Ask for ``SCHED_FIFO`` at ``priority`` (1..99) for this process.

    Returns:
        None when granted, else why not (no privilege, unsupported OS).
    """
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except (OSError, AttributeError, ValueError) as exc:
        return str(exc)
    return None


def sleep_until_ns(t_ns: int) -> None:
    """Sleep until ``CLOCK_MONOTONIC`` reaches ``t_ns`` [ns]."""
    while True:
        d = t_ns - time.monotonic_ns()
        if d <= 0:
            return
        time.sleep(d * 1e-9)


class DaemonLoop:
    """The 200 Hz loop (see the module docstring).

    Args:
        backend: the boards.
        channels: the instance's channels.
        config: tunables; `default_config` when None.
        gains: initial PWM gains; `daemon.pwm.default_drc_gains` when None.
        controller: the control law; a `JointController` for ``robot`` when None.
        state_log: where to append one record per tick, or None.
        robot: robot name (joint limits of the control law).
        clock_ns: monotonic clock [ns] (tests inject a fake one).
        sleep_until: sleeps until a clock value [ns] (tests inject a fake one).
        record_starts: keep every tick's start time in `LoopStats.starts_ns` (bench).
    """

    def __init__(self, backend: Backend, channels: DaemonChannels,
                 config: LoopConfig | None = None, gains: PwmGains | None = None,
                 controller: JointController | None = None,
                 state_log: StateLogWriter | None = None, robot: str = "drc-hubo",
                 clock_ns: Callable[[], int] = time.monotonic_ns,
                 sleep_until: Callable[[int], None] = sleep_until_ns,
                 record_starts: bool = False):
        self.backend = backend
        self.channels = channels
        self.config = config or default_config()
        self.gains = gains or default_drc_gains()
        self.controller = controller or JointController(robot=robot)
        self.state_log = state_log
        self.clock_ns = clock_ns
        self.sleep_until = sleep_until
        self.record_starts = record_starts
        self.stats = LoopStats()
        self.zeroed = np.array(backend.zeroed_at_start(), dtype=bool)
        self.control_off = np.zeros(NUM_JOINTS, bool)
        self._ignore_until_s = np.zeros(NUM_JOINTS)
        self._hold_ref = np.zeros(NUM_JOINTS)
        self._gated_prev = np.zeros(NUM_JOINTS, bool)
        self._last_comply = np.zeros(NUM_JOINTS, bool)
        self._watchdog = False
        self._bad_ref_ns = 0
        self._ref_key: tuple[int, int, int] | None = None  # the ref sample used this tick
        self._rejected_key: tuple[int, int, int] | None = None
        self._rec = np.zeros((), LOG_DTYPE)
        # the state struct is the first STATE_DTYPE.itemsize bytes of the log record
        self._state = np.ndarray((), STATE_DTYPE, buffer=self._rec.data)
        self._t0_ns: int | None = None
        self._last_cmd_ns = 0
        self._last_gains_ns = 0
        self.last_sensors: SensorFrame | None = None

    @property
    def state(self) -> np.ndarray:
        """The state sample of the last tick (a view: copy it to keep it)."""
        return self._state

    @property
    def holding(self) -> bool:
        """The watchdog holds the joints (stale reference while playing)."""
        return self._watchdog

    # ------------------------------------------------------------------ run
    def start(self, now_ns: int | None = None) -> None:
        """Take the time origin and the first reading; the robot holds where it is."""
        now = self.clock_ns() if now_ns is None else now_ns
        self._t0_ns = now
        self._last_cmd_ns = self._last_gains_ns = now
        sensors = self.backend.read_sensors()
        self.controller.reset(sensors.pos_rad)
        self._hold_ref = self.controller.ref_sent_rad
        self._ignore_until_s[:] = self.config.startup_ignore_s
        self.last_sensors = sensors
        log.info("loop started: %s backend, %g Hz, %d joint(s) not homed", self.backend.name,
                 self.config.rate_hz, int((~self.zeroed).sum()))

    def run(self, stop: threading.Event | None = None, max_ticks: int | None = None,
            on_status: Callable[[DaemonLoop], None] | None = None) -> LoopStats:
        """Run ticks at absolute deadlines until ``stop`` is set or ``max_ticks`` ran.

        Args:
            stop: set it (from a signal handler or another thread) to end the loop.
            max_ticks: end after this many ticks.
            on_status: called about every ``status_period_s`` with the loop.

        Returns:
            The run's counters.
        """
        period = self.config.period_ns
        if self._t0_ns is None:
            self.start()
        deadline = self._t0_ns
        prev_deadline = deadline
        next_status = deadline + round(self.config.status_period_s * 1e9)
        while not (stop is not None and stop.is_set()):
            if max_ticks is not None and self.stats.ticks >= max_ticks:
                break
            start = self.clock_ns()
            self.tick(start, start - deadline, (deadline - prev_deadline) * 1e-9)
            prev_deadline = deadline
            deadline += period
            now = self.clock_ns()
            if now >= deadline:  # overrun: skip to the next future deadline, count misses
                missed = (now - deadline) // period + 1
                deadline += missed * period
                self.stats.overruns += int(missed)
                log.debug("tick %d overran: %d deadline(s) missed", self.stats.ticks, missed)
            if on_status is not None and now >= next_status:
                next_status += round(self.config.status_period_s * 1e9)
                on_status(self)
            self.backend.idle(deadline)
            self.sleep_until(deadline)
        return self.stats

    # ------------------------------------------------------------------ one tick
    def tick(self, start_ns: int, late_ns: int = 0, dt_s: float = 0.0) -> None:
        """One tick (see the module docstring); ``run`` calls it at each deadline.

        Args:
            start_ns: clock at the tick's start [ns].
            late_ns: how late the tick started against its deadline [ns].
            dt_s: time since the previous tick's deadline [s] (0 on the first tick).
        """
        if self._t0_ns is None:
            self.start(start_ns)
        if dt_s > 0:
            self.backend.step(dt_s)
        now_s = (start_ns - self._t0_ns) * 1e-9
        sensors = self.backend.read_sensors()
        self.last_sensors = sensors
        self._poll_commands(now_s)
        ref, mode, comply, feedforward, playing, age_s = self._reference(start_ns)
        prev = self.controller.ref_sent_rad
        if prev is None:
            prev = sensors.pos_rad.copy()
        watchdog = bool(playing and age_s > self.config.watchdog_s)
        if watchdog != self._watchdog:
            self._watchdog = watchdog
            if watchdog:
                self.stats.watchdog_trips += 1
                log.warning("watchdog: the ref channel is %.0f ms old while playing; holding",
                            age_s * 1e3)
            else:
                log.info("watchdog: fresh references again; following them")
        if ref is None or watchdog:
            ref = prev.copy()
            mode = np.full(NUM_JOINTS, RefMode.DIRECT, np.int8)
            comply = self._last_comply.copy() if watchdog else np.zeros(NUM_JOINTS, bool)
            feedforward = None
        else:
            self._last_comply = comply.copy()
        gated = ~self.zeroed | (now_s < self._ignore_until_s) | self.control_off
        newly = gated & ~self._gated_prev
        self._hold_ref[newly] = prev[newly]
        self._gated_prev = gated
        if gated.any():
            ref = np.where(gated, self._hold_ref, ref)
            mode = np.where(gated, RefMode.DIRECT, mode).astype(np.int8)
            comply = comply & ~gated
            if feedforward is not None:
                feedforward = np.where(gated, 0.0, feedforward)
        out = self.controller.tick(ref, mode, comply, sensors.pos_rad, sensors.vel_rad_s,
                                   self.gains, feedforward)
        if out.limit_rejected.any():
            self._count_rejection(ref, out.limit_rejected)
        self.backend.write_commands(BoardCommands.from_output(out, self.control_off))
        self._publish(start_ns, late_ns, now_s, sensors, out, ref, mode, comply, gated,
                      watchdog, playing, age_s)

    def _publish(self, start_ns, late_ns, now_s, sensors, out, ref, mode, comply, gated,
                 watchdog, playing, age_s) -> None:
        st = self.stats
        st.ticks += 1
        st.max_late_ns = max(st.max_late_ns, int(late_ns))
        if self.record_starts:
            st.starts_ns.append(int(start_ns))
        s, r = self._state, self._rec
        s["time_ns"] = start_ns
        s["tick"] = st.ticks
        s["overruns"] = st.overruns
        s["time_s"] = now_s
        s["start_ns"] = self._t0_ns
        s["ref"] = out.ref_sent_rad
        s["pos"] = sensors.pos_rad
        s["vel"] = sensors.vel_rad_s
        s["cur"] = sensors.cur_a
        s["duty"] = out.duty_pct
        s["comply"] = out.pwm
        s["active"] = sensors.active & ~self.control_off
        s["zeroed"] = self.zeroed
        status = sensors.status.astype(np.uint32)
        status = status | np.where(gated & ~self.control_off, int(StatusFlag.NOT_HOMED), 0)
        status = status | np.where(out.pwm, int(StatusFlag.COMPLIANT), 0)
        status = status | np.where(out.duty_saturated, int(StatusFlag.PWM_SATURATED), 0)
        status = status | np.where(out.limit_rejected, int(StatusFlag.REF_REJECTED), 0)
        s["status"] = status
        s["refs_rejected"] = st.refs_rejected
        ft = s["ft"]
        ft["mx"], ft["my"], ft["fz"] = sensors.ft[:, 0], sensors.ft[:, 1], sensors.ft[:, 2]
        imu = s["imu"]
        for i, f in enumerate(("ax", "ay", "az", "wx", "wy", "wz")):
            imu[f] = sensors.imu[:, i]
        p = s["power"]
        p["V"], p["I"], p["P"] = sensors.power
        r["tick_start_ns"] = start_ns
        r["late_ns"] = late_ns
        r["ref_cmd"] = ref
        r["mode_cmd"] = mode
        r["comply_cmd"] = comply
        r["gated"] = gated
        r["watchdog"] = watchdog
        r["playing"] = playing
        r["ref_age_ms"] = age_s * 1e3 if np.isfinite(age_s) else -1.0
        r["cmds_done"] = st.cmds_done
        r["cmds_refused"] = st.cmds_refused
        r["gains_version"] = st.gains_version
        r["latched"] = sensors.latched if sensors.latched is not None else 0
        self.channels.state.write(s)
        if self.state_log is not None:
            self.state_log.append(r)

    # ------------------------------------------------------------------ inputs
    def _reference(self, now_ns: int):
        """(ref, mode, comply, feed-forward, playing, age_s) of the newest valid ``ref``
        sample; the feed-forward duty [%] only on the joints it asks to comply.

        ``ref`` is None when there is no usable sample (none since start-up, or refused).
        """
        s = self.channels.ref.read_latest()
        self._ref_key = None
        if s is None or int(s["time_ns"]) < self._t0_ns:
            return None, None, None, None, False, float("inf")
        self._ref_key = (int(s["time_ns"]), int(s["seq"]), int(s["writer_id"]))
        age_s = (now_ns - int(s["time_ns"])) * 1e-9
        ref = np.array(s["ref"], dtype=float)
        mode = np.array(s["mode"], dtype=np.int8)
        comply = np.array(s["comply"], dtype=bool)
        command = np.array(s["pwm_command"], dtype=float)
        neck = self.channels.ref_neck.read_latest()
        if neck is not None and int(neck["time_ns"]) >= self._t0_ns:
            ref[NECK_JOINTS] = neck["ref"][NECK_JOINTS]
            mode[NECK_JOINTS] = neck["mode"][NECK_JOINTS]
            comply[NECK_JOINTS] = neck["comply"][NECK_JOINTS]
            command[NECK_JOINTS] = neck["pwm_command"][NECK_JOINTS]
        feedforward = np.where(comply, command, 0.0)
        problem = None
        if not np.isfinite(ref).all():
            bad = np.flatnonzero(~np.isfinite(ref))
            problem = f"non-finite reference for {', '.join(JOINT_NAMES[i] for i in bad)}"
        elif not np.isin(mode, _MODES).all():
            bad = np.flatnonzero(~np.isin(mode, _MODES))
            problem = f"reference mode outside 0..3 for {', '.join(JOINT_NAMES[i] for i in bad)}"
        elif not (np.abs(feedforward) <= PWM_COMMAND_LIMIT_PCT).all():
            bad = np.flatnonzero(~(np.abs(feedforward) <= PWM_COMMAND_LIMIT_PCT))
            problem = (f"feed-forward duty outside ±{PWM_COMMAND_LIMIT_PCT:g} % for "
                       f"{', '.join(JOINT_NAMES[i] for i in bad)}")
        if problem is not None:
            if int(s["time_ns"]) != self._bad_ref_ns:
                self._bad_ref_ns = int(s["time_ns"])
                log.error("ref sample from writer %d refused (%s); holding",
                          int(s["writer_id"]), problem)
            return None, None, None, None, bool(s["playing"]), age_s
        return ref, mode, comply, feedforward, bool(s["playing"]), age_s

    def _count_rejection(self, ref: np.ndarray, rejected: np.ndarray) -> None:
        """Count and log a ref sample with joints beyond their limits, once per sample."""
        key = self._ref_key
        if key is None or key == self._rejected_key:
            return
        self._rejected_key = key
        self.stats.refs_rejected += 1
        lim = self.controller.limits
        what = ", ".join(f"{JOINT_NAMES[j]} {ref[j]:.4g} rad (allowed [{lim.lower_rad[j]:.4g}, "
                         f"{lim.upper_rad[j]:.4g}])" for j in np.flatnonzero(rejected))
        log.error("ref sample from writer %d rejected beyond the joint limits: %s; those "
                  "joints hold their previous reference", key[2], what)

    def _poll_commands(self, now_s: float) -> None:
        c = self.channels.board_cmd.read_latest()
        if c is not None and int(c["time_ns"]) > self._last_cmd_ns:
            self._last_cmd_ns = int(c["time_ns"])
            self._board_command(c, now_s)
        g = self.channels.pwm_gains.read_latest()
        if g is not None and int(g["time_ns"]) > self._last_gains_ns:
            self._last_gains_ns = int(g["time_ns"])
            try:
                gains = PwmGains(np.array(g["kp"]), np.array(g["kd"]), np.array(g["max_pwm"]),
                                 np.array(g["pwm_command"]))
            except PwmGainError as exc:
                self._refuse(f"pwm-gains set from writer {int(g['writer_id'])}: {exc}")
            else:
                self.gains = gains
                self.stats.gains_version += 1
                self.stats.cmds_done += 1
                log.info("pwm gains set: %r", gains)

    def _refuse(self, why: str) -> None:
        self.stats.cmds_refused += 1
        log.warning("refused: %s", why)

    def _board_command(self, c: np.ndarray, now_s: float) -> None:
        try:
            kind = BoardCommandType(int(c["type"]))
        except ValueError:
            self._refuse(f"unknown board command type {int(c['type'])}")
            return
        j = int(c["joint"])
        if kind is BoardCommandType.NONE:
            return
        if not -1 <= j < NUM_JOINTS:
            self._refuse(f"{kind.name}: joint {j} is not −1 (all) or 0..{NUM_JOINTS - 1}")
            return
        joints = np.arange(NUM_JOINTS) if j < 0 else np.array([j])
        what = "every joint" if j < 0 else JOINT_NAMES[j]
        if kind is BoardCommandType.SET_GAINS:
            if j < 0:
                self._refuse("SET_GAINS: name one joint")
                return
            mask = int(c["params"][0]) or 0b111
            values = {f: float(c["dvalues"][i]) for i, f in enumerate(_GAIN_FIELDS)
                      if mask >> i & 1}
            try:
                self.gains = self.gains.with_joint(JOINT_NAMES[j], **values)
            except (PwmGainError, InputError) as exc:
                self._refuse(f"SET_GAINS {what}: {exc}")
                return
            self.stats.gains_version += 1
            log.info("gains of %s: kp %g, kd %g, max_pwm %g %%", what, self.gains.kp[j],
                     self.gains.kd[j], self.gains.max_pwm_pct[j])
        elif kind in (BoardCommandType.HOME, BoardCommandType.HOME_ALL):
            if kind is BoardCommandType.HOME_ALL:
                joints, what = np.arange(NUM_JOINTS), "every joint"
            self.backend.board_command(kind, -1 if kind is BoardCommandType.HOME_ALL else j)
            self.zeroed[joints] = True
            self._ignore_until_s[joints] = now_s + self.config.home_ignore_s
            self._gated_prev[joints] = True  # capture the hold reference here, not later
            if self.backend.homes_to_zero:
                self._hold_ref[joints] = 0.0
            else:
                prev = self.controller.ref_sent_rad
                if prev is not None:
                    self._hold_ref[joints] = prev[joints]
            log.info("home %s: references ignored for %g s", what, self.config.home_ignore_s)
        elif kind is BoardCommandType.ZERO_ENCODER:
            self.backend.board_command(kind, j)
            self.zeroed[joints] = True
        elif kind in (BoardCommandType.CONTROL_OFF, BoardCommandType.MOTOR_OFF):
            self.backend.board_command(kind, j)
            self.control_off[joints] = True
            log.info("control off: %s", what)
        elif kind in (BoardCommandType.CONTROL_ON, BoardCommandType.MOTOR_ON):
            self.backend.board_command(kind, j)
            self.control_off[joints] = False
            log.info("control on: %s", what)
        else:  # INIT_SENSORS, RESET
            self.backend.board_command(kind, j)
            log.info("%s: %s", kind.name, what)
        self.stats.cmds_done += 1
