"""The ``can`` backend: the Hubo frame protocol over python-can, on two buses.

Each tick (`daemon.loop`):

- ``read_sensors``: drain both buses (non-blocking) and fold the replies of the last
  cycle into a `SensorFrame` with `CyclePlan.decode`. A joint whose board sent no
  encoder reply is flagged ``NO_REPLY`` and keeps its last position (velocity 0): the
  loop goes on, the state shows which board is silent. Status bits and currents come
  round robin (`CyclePlan.housekeeping`) and keep their last value between polls;
  FT / IMU / power likewise keep their last value when a reply is missing.
- ``write_commands``: `CyclePlan.encode` turns references, duties and PWM modes into the
  cycle's frames; the first slot is sent at once, the rest are queued with their send
  times: the plan's offsets (even spacing over the period, HuboCan's scheme), scaled
  into the first ``spread_fraction`` of the period so that the replies to the last
  requests are in before the next tick reads them.
- ``idle``: sends the queued frames at their times (sleeping between slots of
  ``slot_s``), then returns, before the loop's deadline.

Interfaces: anything python-can opens with ``can.Bus(interface=..., channel=...)``:
``socketcan`` (``can0``, ``can1``), ``pcan`` (``PCAN_USBBUS1``, …, with ``bitrate``),
``virtual`` (tests, with `daemon.can.emulator.BoardEmulator` in the same process).

Board commands (ASSUMPTION, command ids of HuboCan's ``can_cmd_id_t``; the byte layouts
after ``[jmc, cmd]`` are unverified against a board, check before use on hardware):
home ``[jmc, 0x11, ch]`` (GOTO_HOME), zero encoder ``[jmc, 0x06, ch]``, control on/off
``[jmc, 0x0E|0x0F]``, reset ``[jmc, 0xFA]`` (INITIALIZE_BOARD), and sensor nulling on the
sensor-instruction id 0x2F: ``[board, 0x81]`` (NULL_SENSOR). ``ch = 0`` means every motor
of the board.
"""

from __future__ import annotations

import logging
import time

import can
import numpy as np

from daemon.backend import BoardCommands, SensorFrame
from daemon.can import protocol as cp
from daemon.can.cycle_plan import CyclePlan
from daemon.structs import NUM_FT, NUM_IMU, BoardCommandType, StatusFlag
from daemon.tables import JointTable, SensorTable, load_joint_table, load_sensor_table
from robot.constants import GRAVITY_M_S2
from robot.errors import InputError
from robot.joints import NUM_JOINTS

__all__ = ["BOARD_CMD_BYTES", "CanBackend", "parse_channels"]

log = logging.getLogger(__name__)

SENSOR_INSTRUCTION_ID = 0x2F
NULL_SENSOR = 0x81
#: Board command → HuboCan command byte (see the module docstring: ASSUMPTION).
BOARD_CMD_BYTES = {
    BoardCommandType.HOME: 0x11,
    BoardCommandType.HOME_ALL: 0x11,
    BoardCommandType.ZERO_ENCODER: 0x06,
    BoardCommandType.CONTROL_ON: 0x0E,
    BoardCommandType.MOTOR_ON: 0x0E,
    BoardCommandType.CONTROL_OFF: 0x0F,
    BoardCommandType.MOTOR_OFF: 0x0F,
    BoardCommandType.RESET: 0xFA,
}


def parse_channels(text: str) -> tuple[str, str]:
    """``"can0,can1"`` → ``("can0", "can1")``: the channels of bus 0 and bus 1."""
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != 2 or not all(parts):
        raise InputError(f"--channels {text!r}: give two channel names, bus 0 then bus 1, "
                         "e.g. can0,can1")
    return parts[0], parts[1]


def _ref_jmc(msg: can.Message) -> int:
    """The board of a position-reference frame (id 0x10 + jmc + 0x100·pair), else −1."""
    low = msg.arbitration_id % cp.PAIR_STRIDE - cp.REF_BASE
    return low if 0 <= low < 0x30 and msg.arbitration_id >= cp.REF_BASE else -1


def _is_pwm(msg: can.Message) -> bool:
    return msg.arbitration_id == cp.CMD_ID and len(msg.data) > 1 and msg.data[1] == cp.CMD_PWM


class CanBackend:
    """Hubo boards on two CAN buses (see the module docstring).

    Args:
        interface: python-can interface: ``socketcan``, ``pcan``, ``virtual``, …
        channels: channel of bus 0 and of bus 1.
        joints: joint table; the bundled DRC-Hubo table when None.
        sensors: sensor table; the bundled one when None.
        period_s: the loop's period [s].
        spread_fraction: share of the period the sends are spread over.
        slot_s: granularity of the spread [s].
        bitrate: bus bit rate [bit/s], passed to interfaces that take one (pcan).
        buses: already open buses ``{0: bus, 1: bus}`` (tests); ``interface`` unused then.

    Raises:
        InputError: a bus cannot be opened (the message names interface and channel).
    """

    name = "can"
    homes_to_zero = True

    def __init__(self, interface: str = "socketcan", channels: tuple[str, str] = ("can0", "can1"),
                 joints: JointTable | None = None, sensors: SensorTable | None = None,
                 period_s: float = 0.005, spread_fraction: float = 0.6,
                 slot_s: float = 0.0005, bitrate: int = 1_000_000,
                 buses: dict[int, can.BusABC] | None = None):
        self.joints = joints or load_joint_table()
        self.sensors = sensors or load_sensor_table()
        self.plan = CyclePlan(self.joints, self.sensors, period_s, bitrate)
        self.period_s = period_s
        self.spread_fraction = spread_fraction
        self.slot_ns = max(int(slot_s * 1e9), 1)
        self._own_buses = buses is None
        if buses is None:
            buses = {}
            for b, ch in enumerate(channels):
                kwargs = {"bitrate": bitrate} if interface == "pcan" else {}
                try:
                    buses[b] = can.Bus(interface=interface, channel=ch, **kwargs)
                except (can.CanError, OSError, ValueError, ImportError) as exc:
                    for bus in buses.values():
                        bus.shutdown()
                    raise InputError(f"cannot open CAN bus {b}: interface {interface!r} "
                                     f"channel {ch!r}: {exc}") from None
        self.buses = buses
        self._tx_offsets_ns = {
            b: [int(f.offset_s * spread_fraction * 1e9) for f in p.tx_frames]
            for b, p in self.plan.buses.items()
        }
        self._queue: list[tuple[int, int, can.Message]] = []  # (send_ns, bus, msg), sorted
        self._cycle = 0
        self._pos = np.zeros(NUM_JOINTS)
        self._last_read_ns: int | None = None
        self._status = np.zeros(NUM_JOINTS, np.uint32)
        self._cur = np.zeros(NUM_JOINTS)
        self._ft = np.zeros((NUM_FT, 3))
        self._imu = np.zeros((NUM_IMU, 6))
        self._imu[:, 2] = GRAVITY_M_S2
        self._power = np.zeros(3)
        self._seen = np.zeros(NUM_JOINTS, bool)
        self.no_reply_ticks = np.zeros(NUM_JOINTS, np.int64)  # per joint, since start
        self.tx_errors = 0
        self.frames_sent = 0

    def zeroed_at_start(self) -> np.ndarray:
        z = np.zeros(NUM_JOINTS, bool)
        for j in self.joints.joints:
            z[j.index] = bool(j.zeroed)
        return z

    # ------------------------------------------------------------------ tick
    def step(self, dt_s: float) -> None:
        pass  # real boards run by themselves

    def _drain(self) -> list[tuple[int, can.Message]]:
        got = []
        for b, bus in self.buses.items():
            while True:
                try:
                    m = bus.recv(timeout=0.0)
                except can.CanError as exc:
                    log.warning("can%d: receive failed: %s", b, exc)
                    break
                if m is None:
                    break
                got.append((b, m))
        return got

    def read_sensors(self) -> SensorFrame:
        self._flush_queue()  # anything not sent in the last period goes now
        now = time.monotonic_ns()
        dt = self.period_s if self._last_read_ns is None else (now - self._last_read_ns) * 1e-9
        self._last_read_ns = now
        r = self.plan.decode(self._drain())
        got = r.got_enc
        vel = np.zeros(NUM_JOINTS)
        fresh = got & self._seen
        if dt > 0:
            vel[fresh] = (r.pos_rad[fresh] - self._pos[fresh]) / dt
        self._pos[got] = r.pos_rad[got]
        self._seen |= got
        replied = r.status != int(StatusFlag.NO_REPLY)
        self._status[replied] = r.status[replied]
        cur_ok = np.isfinite(r.current_a)
        self._cur[cur_ok] = r.current_a[cur_ok]
        for arr, new in ((self._ft, r.ft), (self._imu, r.imu)):
            ok = np.isfinite(new)
            arr[ok] = new[ok]
        if np.isfinite(r.power).all():
            self._power[:] = r.power
        status = self._status & ~np.uint32(StatusFlag.NOT_HOMED)  # the loop owns homing
        status = np.where(got, status, status | np.uint32(StatusFlag.NO_REPLY))
        self.no_reply_ticks += ~got
        tripped = (status & int(StatusFlag.TRIPPED)) != 0
        return SensorFrame(self._pos.copy(), vel, self._cur.copy(), status.astype(np.uint32),
                           got & ~tripped, self._ft.copy(), self._imu.copy(),
                           self._power.copy())

    def write_commands(self, cmd: BoardCommands) -> None:
        frames = self.plan.encode(cmd.ref_rad, cmd.duty_pct, cmd.pwm)
        start = time.monotonic_ns()
        used = {b: len(ms) for b, ms in frames.items()}
        hk = self.plan.housekeeping(self._cycle, used)
        self._cycle += 1
        queue = []
        for b, msgs in frames.items():
            offsets = self._tx_offsets_ns[b]
            i = 0
            last_ref_jmc = -1
            for m in msgs:
                if _is_pwm(m) and m.data[0] == last_ref_jmc:
                    off = offsets[i - 1]  # extra PWM frame of a mixed pair: with its ref
                else:
                    off = offsets[min(i, len(offsets) - 1)]
                    i += 1
                last_ref_jmc = _ref_jmc(m)
                queue.append((start + off, b, m))
            tail = offsets[-1] if offsets else 0
            for m in hk.get(b, []):
                queue.append((start + tail, b, m))
        queue.sort(key=lambda x: x[0])
        self._queue = queue
        self._send_due(start)

    def _send(self, b: int, m: can.Message) -> None:
        try:
            self.buses[b].send(m, timeout=0.0)
            self.frames_sent += 1
        except can.CanError as exc:
            self.tx_errors += 1
            if self.tx_errors in (1, 10, 100) or self.tx_errors % 1000 == 0:
                log.warning("can%d: send failed (%d so far): %s", b, self.tx_errors, exc)

    def _send_due(self, now_ns: int) -> None:
        q = self._queue
        k = 0
        while k < len(q) and q[k][0] <= now_ns + self.slot_ns:
            self._send(q[k][1], q[k][2])
            k += 1
        del q[:k]

    def _flush_queue(self) -> None:
        for _, b, m in self._queue:
            self._send(b, m)
        self._queue = []

    def idle(self, until_ns: int) -> None:
        while self._queue:
            t = self._queue[0][0]
            if t >= until_ns:
                return
            d = t - time.monotonic_ns()
            if d > self.slot_ns // 4:
                time.sleep(d * 1e-9)
            self._send_due(time.monotonic_ns())

    # ------------------------------------------------------------------ commands
    def _boards_of(self, joint: int) -> list[tuple[int, int, int]]:
        """(bus, jmc, channel) of ``joint``, or of every board (channel 0) for −1."""
        if joint < 0:
            return [(b, jmc, 0) for (b, jmc) in self.joints.boards()]
        j = self.joints.joints[joint]
        return [(j.can, j.jmc, j.mot_no + 1)]

    def board_command(self, kind: BoardCommandType, joint: int) -> None:
        if kind is BoardCommandType.INIT_SENSORS:
            for s in self.sensors.sensors:
                if s.active and s.kind in ("ft", "imu"):
                    self._send(s.can, can.Message(arbitration_id=SENSOR_INSTRUCTION_ID,
                                                  data=bytes([s.board, NULL_SENSOR]),
                                                  is_extended_id=False))
            return
        code = BOARD_CMD_BYTES.get(kind)
        if code is None:
            return
        for b, jmc, ch in self._boards_of(joint):
            self._send(b, can.Message(arbitration_id=cp.CMD_ID, data=bytes([jmc, code, ch]),
                                      is_extended_id=False))

    def close(self) -> None:
        if self._own_buses:
            for bus in self.buses.values():
                bus.shutdown()
            self._own_buses = False
