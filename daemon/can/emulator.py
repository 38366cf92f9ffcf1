"""A JMC board emulator on python-can's ``virtual`` interface, for tests without hardware.

One thread per bus listens on ``can.Bus(interface="virtual", channel=name)`` and answers
the frames of `daemon.can.protocol` as the DRC-Hubo boards would:

- reference frames set each motor's target; in position mode the encoder follows it
  with a first-order lag (time constant `EmulatorConfig.lag_s`);
- PWM frames put motors in PWM mode and move them at a velocity proportional to the
  duty (`EmulatorConfig.rad_s_per_pct`); a later PWM frame with the motor's mask bit
  cleared returns it to position mode;
- encoder, status and current requests, and FT / tilt / IMU / power requests get their
  replies; sensor values are whatever the test set (`set_ft`, `set_imu`, `set_power`);
- fault injection: `silence` a board and it stops replying (it still accepts references).

It is a plumbing stand-in, not a physics model (the MuJoCo board model is that).
"""

from __future__ import annotations

import logging
import math
import threading
import time
from dataclasses import dataclass

import can
import numpy as np

from daemon.can import protocol as cp
from daemon.structs import FT_NAMES, IMU_NAMES
from daemon.tables import JointTable, SensorTable
from robot.constants import GRAVITY_M_S2

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class EmulatorConfig:
    """Tunables of the emulated boards."""

    lag_s: float = 0.02  #: position-mode time constant [s]
    rad_s_per_pct: float = 0.02  #: PWM mode: joint velocity per % duty [rad/s / %]
    amps_per_pct: float = 0.05  #: PWM mode: motor current per % duty [A / %]
    amps_per_rad: float = 5.0  #: position mode: current per rad of tracking error [A / rad]
    homed: bool = True  #: boards start homed (HOMED status bit)


def default_config() -> EmulatorConfig:
    """The emulator's default tunables."""
    return EmulatorConfig()


class _BusSim:
    """The boards of one bus: motor state and the frame handler.

    Cost matters: the emulator shares the GIL with the daemon's loop, and a reply that
    lands after the tick has read the bus counts as a missed reply. So a wake handles
    every frame already queued after one integration step, encoder counts come from one
    vectorised conversion per wake, and the per-board and per-frame lookups are built once
    here.
    """

    def __init__(self, emu: BoardEmulator, bus_no: int, channel: str):
        self.emu = emu
        self.bus_no = bus_no
        self.bus = can.Bus(interface="virtual", channel=channel)
        self.boards = {jmc: ch for (b, jmc), ch in emu.joints.boards().items() if b == bus_no}
        self.sensors = {
            (s.board, s.kind): s for s in emu.sensors.sensors if s.can == bus_no and s.active
        }
        # reference frame id → (motor k of the pair, joint) rows
        self._ref_rows: dict[int, list[tuple[int, int]]] = {}
        for jmc, chans in self.boards.items():
            for pair in range((len(chans) + 1) // 2):
                self._ref_rows[cp.REF_BASE + jmc + cp.PAIR_STRIDE * pair] = [
                    (k, j) for k, j in enumerate(chans[2 * pair : 2 * pair + 2]) if j >= 0
                ]
        self._counts: list[int] | None = None  # this wake's encoder counts, made on first use
        self._refs: dict[int, int] = {}  # joint → count received this wake, not yet applied
        self._idx = emu._bus_joints[bus_no]
        self.last_t = time.monotonic()
        self.thread = threading.Thread(target=self._run, name=f"board-emu-can{bus_no}", daemon=True)

    def _run(self) -> None:
        stop = self.emu._stop
        while not stop.is_set():
            msgs = self._receive()
            replies: list[can.Message] = []
            with self.emu._lock:
                self._advance()
                self._counts = None
                for msg in msgs:
                    try:
                        replies += self._handle(msg)
                    except cp.ProtocolError as e:
                        log.warning("can%d: bad frame %s: %s", self.bus_no, msg, e)
                self._apply_refs()
            for r in replies:
                self.bus.send(r)

    def _receive(self) -> list[can.Message]:
        """Wait for a frame (at most 20 ms), then take every frame already queued."""
        msgs: list[can.Message] = []
        try:
            msg = self.bus.recv(timeout=0.02)
            while msg is not None:
                msgs.append(msg)
                msg = self.bus.recv(timeout=0.0)
        except can.CanError as e:  # pragma: no cover - virtual bus does not fail
            log.warning("can%d: receive failed: %s", self.bus_no, e)
        return msgs

    def _advance(self) -> None:
        """Integrate every motor of this bus up to now."""
        now = time.monotonic()
        dt = now - self.last_t
        self.last_t = now
        if dt <= 0:
            return
        e = self.emu
        cfg = e.config
        idx = self._idx
        pos = e._pos_rad[idx]
        alpha = 1.0 - math.exp(-dt / cfg.lag_s)
        step = np.where(
            e._pwm[idx],
            -e._duty[idx] * cfg.rad_s_per_pct * dt,  # hubo-ach sign
            (e._ref_rad[idx] - pos) * alpha,
        )
        e._pos_rad[idx] = pos + step

    def _silent(self, board: int, sensor: bool = False) -> bool:
        return (self.bus_no, sensor, board) in self.emu._silent

    def _handle(self, msg: can.Message) -> list[can.Message]:
        """The replies to one frame."""
        e = self.emu
        fid = msg.arbitration_id
        if fid == cp.CMD_ID:
            jmc, cmd, fields = cp.decode_command(msg)
            chans = self.boards.get(jmc)
            if chans is None or self._silent(jmc):
                return []
            if cmd == cp.CMD_ENC_REQUEST:
                if self._counts is None:
                    self._counts = e.joints.rad_to_enc(e._pos_rad).tolist()
                counts = self._counts
                return [
                    cp.encode_enc_reply(
                        jmc, [counts[j] if j >= 0 else 0 for j in chans[2 * pair : 2 * pair + 2]],
                        pair,
                    )
                    for pair in range((len(chans) + 1) // 2)
                ]
            if cmd == cp.CMD_PWM:
                two = chans[2 * fields["pair"] : 2 * fields["pair"] + 2]
                for k, j in enumerate(two):
                    if j >= 0:
                        on = bool(fields["mask"] >> k & 1)
                        e._pwm[j] = on
                        e._duty[j] = fields["duty_pct"][k] if on else 0.0
                return []
            if cmd == cp.CMD_STATUS_REQUEST:
                bits = cp.BoardStatus.CONTROL_ON | (cp.BoardStatus.HOMED if e.config.homed else 0)
                return [cp.encode_status_reply(jmc, [int(bits)] * len(chans))]
            if cmd == cp.CMD_CURRENT_REQUEST:
                self._apply_refs()  # the current follows the reference error
                cur = [e.current_of(j) if j >= 0 else 0.0 for j in chans[:4]]
                return [cp.encode_current_reply(jmc, cur)]
            return []
        if fid == cp.SENSOR_REQ_ID:
            board, kind = cp.decode_sensor_request(msg)
            if self._silent(board, sensor=True):
                return []
            return self._sensor_reply(board, kind)
        rows = self._ref_rows.get(fid)
        if rows is not None and msg.dlc == 6:
            _, _, pair_counts = cp.decode_ref(msg)
            for k, j in rows:
                self._refs[j] = pair_counts[k]
        return []

    def _apply_refs(self) -> None:
        """Convert the references received so far this wake in one `enc_to_rad` call (a
        later frame for a joint has replaced an earlier one, as when applied in turn)."""
        if self._refs:
            joints = list(self._refs)
            self.emu._ref_rad[joints] = self.emu.joints.enc_to_rad(list(self._refs.values()),
                                                                   joints)
            self._refs = {}

    def _sensor_reply(self, board: int, kind: int) -> list[can.Message]:
        e = self.emu
        if kind == cp.SENSOR_FT and (board, "ft") in self.sensors:
            k = FT_NAMES.index(self.sensors[(board, "ft")].name)
            return [cp.encode_ft_reply(board, *e._ft[k])]
        if kind == cp.SENSOR_TILT:
            out = []
            for s in self.sensors.values():
                if s.board == board and s.kind == "imu":
                    k = IMU_NAMES.index(s.name)
                    out.append(cp.encode_tilt_reply(board, tuple(e._imu[k, :3])))
                    if s.name == "IMU":
                        out.append(cp.encode_gyro_reply(board, tuple(e._imu[k, 3:])))
            return out
        if kind == cp.SENSOR_POWER and (board, "power") in self.sensors:
            return [cp.encode_power_reply(*e._power)]
        return []


class BoardEmulator:
    """Emulated JMC boards and sensors on virtual CAN buses.

    Args:
        joints: joint table (board assignment and gearing).
        sensors: sensor table.
        channels: bus number → virtual channel name, e.g. ``{0: "t1-can0", 1: "t1-can1"}``;
            use unique names per test.
        config: tunables; `default_config` if None.

    Use as a context manager, or call `start` and `stop`.
    """

    def __init__(
        self,
        joints: JointTable,
        sensors: SensorTable,
        channels: dict[int, str],
        config: EmulatorConfig | None = None,
    ):
        self.joints = joints
        self.sensors = sensors
        self.channels = dict(channels)
        self.config = config or default_config()
        n = len(joints)
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._pos_rad = np.zeros(n)
        self._ref_rad = np.zeros(n)
        self._pwm = np.zeros(n, bool)
        self._duty = np.zeros(n)  # [%]
        self._ft = np.zeros((len(FT_NAMES), 3))
        self._imu = np.zeros((len(IMU_NAMES), 6))
        self._imu[:, 2] = GRAVITY_M_S2
        self._power = (48.0, 5.0)
        self._silent: set[tuple[int, bool, int]] = set()  # (bus, sensor?, board)
        self._bus_joints = {
            b: np.array([j.index for j in joints.joints if j.can == b], dtype=int) for b in channels
        }
        self._sims: list[_BusSim] = []

    # -- life cycle

    def start(self) -> BoardEmulator:
        """Open the virtual buses and start one thread per bus."""
        if self._sims:
            return self
        self._stop.clear()
        self._sims = [_BusSim(self, b, ch) for b, ch in self.channels.items()]
        for s in self._sims:
            s.thread.start()
        log.debug("board emulator started on %s", self.channels)
        return self

    def stop(self) -> None:
        """Stop the threads and shut the buses down; idempotent."""
        self._stop.set()
        for s in self._sims:
            s.thread.join(timeout=2.0)
            s.bus.shutdown()
        self._sims = []

    def __enter__(self) -> BoardEmulator:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    # -- fault injection and sensor values

    def silence(
        self, board: int, can_bus: int | None = None, silent: bool = True, sensor: bool = False
    ) -> None:
        """Make a board stop (or resume) replying.

        Args:
            board: jmc number, or with ``sensor=True`` a sensor board number (the two
                number spaces overlap: sensor requests go to id 0x02).
            can_bus: its bus; None for every bus.
            silent: False resumes replies.
            sensor: ``board`` is a sensor board.
        """
        with self._lock:
            for b in self.channels if can_bus is None else [can_bus]:
                (self._silent.add if silent else self._silent.discard)((b, sensor, board))

    def set_ft(self, name: str, mx: float, my: float, fz: float) -> None:
        """Value an FT sensor reports: moments [N·m], force [N]."""
        with self._lock:
            self._ft[FT_NAMES.index(name)] = (mx, my, fz)

    def set_imu(self, name: str, acc: tuple, rate: tuple = (0.0, 0.0, 0.0)) -> None:
        """Value an IMU / tilt sensor reports: acceleration [m/s²], rate [rad/s]."""
        with self._lock:
            self._imu[IMU_NAMES.index(name)] = tuple(acc) + tuple(rate)

    def set_power(self, volts: float, amps: float) -> None:
        """Bus voltage [V] and current [A] the power board reports."""
        with self._lock:
            self._power = (volts, amps)

    def set_position(self, name: str, rad: float) -> None:
        """Put a joint somewhere (and its reference there too) [rad]."""
        j = self.joints[name].index
        with self._lock:
            self._pos_rad[j] = self._ref_rad[j] = rad

    # -- readouts (for tests)

    def position(self, name: str) -> float:
        """A joint's emulated position [rad]."""
        with self._lock:
            return float(self._pos_rad[self.joints[name].index])

    def current_of(self, j: int) -> float:
        """A joint's motor current [A]."""
        cfg = self.config
        if self._pwm[j]:
            return abs(self._duty[j]) * cfg.amps_per_pct
        return abs(self._ref_rad[j] - self._pos_rad[j]) * cfg.amps_per_rad
