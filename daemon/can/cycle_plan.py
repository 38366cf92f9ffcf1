"""One 5 ms CAN cycle per bus, planned from the joint and sensor tables.

`CyclePlan` lists the frames of one control cycle on each bus (`daemon.can.protocol`'s
frame kinds), checks them against the bus's bit budget, and encodes the cycle's
references and PWM duties and decodes its replies, vectorised over the 40 joints: the
CAN backend (`daemon.can.backend`) runs it every tick.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import can
import numpy as np

from daemon.can.protocol import (
    CMD_ID,
    CURRENT_REPLY_BASE,
    ENC_REPLY_BASE,
    FT_REPLY_BASE,
    GYRO_REPLY_BASE,
    PAIR_STRIDE,
    POWER_REPLY_ID,
    REF_BASE,
    SENSOR_FT,
    SENSOR_POWER,
    SENSOR_REQ_ID,
    SENSOR_TILT,
    STATUS_REPLY_BASE,
    TILT_REPLY_BASE,
    board_status_to_flags,
    decode_current_reply,
    decode_ft_reply,
    decode_imu_reply,
    decode_power_reply,
    decode_status_reply,
    encode_current_request,
    encode_enc_request,
    encode_pwm,
    encode_sensor_request,
    encode_status_request,
    message,
    to_sign_magnitude,
)
from daemon.structs import FT_NAMES, IMU_NAMES, NUM_FT, NUM_IMU, StatusFlag
from daemon.tables import JointTable, SensorTable
from robot.joints import NUM_JOINTS

__all__ = ["FRAME_BITS", "BusPlan", "CyclePlan", "CycleReadings", "PlannedFrame"]

FRAME_BITS = 108  #: HuboCan's budget per frame (8 data bytes, before bit stuffing)


@dataclass(frozen=True)
class PlannedFrame:
    """One frame of a cycle: sent by us (``tx``, with a send offset) or expected back."""

    kind: str  # "ref", "enc_req", "ft_req", "tilt_req", "power_req", or "*_reply"
    arbitration_id: int
    board: int
    tx: bool
    offset_s: float = 0.0  # send time after the cycle start [s]; replies: 0


@dataclass
class BusPlan:
    """The frames of one bus in one cycle and its load."""

    can: int
    frames: list[PlannedFrame] = field(default_factory=list)
    period_s: float = 0.005
    bitrate: float = 1e6

    @property
    def load(self) -> float:
        """Bus load fraction: frames × 108 bits / (bitrate × period)."""
        return len(self.frames) * FRAME_BITS / (self.bitrate * self.period_s)

    @property
    def tx_frames(self) -> list[PlannedFrame]:
        return [f for f in self.frames if f.tx]


@dataclass
class CycleReadings:
    """What one cycle's replies said (NaN / False where nothing came back)."""

    enc: np.ndarray  # (40,) int64 counts
    pos_rad: np.ndarray  # (40,)
    got_enc: np.ndarray  # (40,) bool
    status: np.ndarray  # (40,) uint32 StatusFlag bits (NO_REPLY where no reply)
    current_a: np.ndarray  # (40,)
    ft: np.ndarray  # (4, 3): mx [N·m], my [N·m], fz [N]
    imu: np.ndarray  # (3, 6): ax ay az [m/s²], wx wy wz [rad/s]
    power: np.ndarray  # (3,): V [V], I [A], P [W]
    unknown: int = 0  # frames we did not expect


def _pair_joints(chans: tuple[int, ...], pair: int) -> list[int]:
    """The two joints (indices into the 40) of a board's motor pair; −1 for a pair of
    one motor."""
    return (list(chans[2 * pair : 2 * pair + 2]) + [-1])[:2]


class CyclePlan:
    """The frames of one control cycle per bus, from the joint and sensor tables.

    Per bus and cycle: one reference frame per motor pair, one encoder request per
    board and its replies (one per pair), then the sensor requests and replies. The frames
    we send are spread evenly over the period (HuboCan's scheme, no blocking polls).
    Status and current are polled round robin in the spare time (`housekeeping`).

    Args:
        joints: the joint table.
        sensors: the sensor table.
        period_s: cycle period [s].
        bitrate: bus bit rate [bit/s].
    """

    def __init__(
        self,
        joints: JointTable,
        sensors: SensorTable,
        period_s: float = 0.005,
        bitrate: float = 1e6,
    ):
        self.joints = joints
        self.sensors = sensors
        self.period_s = period_s
        self.buses: dict[int, BusPlan] = {}
        boards = joints.boards()
        # Reference frames: one row per (bus, board, pair); index array into the 40 joints.
        self._ref_rows = [(bus, jmc, pair) for (bus, jmc), chans in boards.items()
                          for pair in range((len(chans) + 1) // 2)]
        self._ref_index = np.array([_pair_joints(boards[(bus, jmc)], pair)
                                    for bus, jmc, pair in self._ref_rows],
                                   dtype=np.int64)  # (F, 2), −1 = none
        self._ref_valid = self._ref_index >= 0
        self._ref_ids = [REF_BASE + jmc + PAIR_STRIDE * pair for _, jmc, pair in self._ref_rows]
        # Reply lookup: (bus, arbitration id) → the joints (or the sensor) it reports
        self._enc_slot: dict[tuple[int, int], tuple[int, ...]] = {
            (bus, ENC_REPLY_BASE + jmc + PAIR_STRIDE * pair): tuple(chans[2 * pair : 2 * pair + 2])
            for (bus, jmc), chans in boards.items() for pair in range((len(chans) + 1) // 2)}
        self._status_slot = {
            (bus, STATUS_REPLY_BASE + jmc): chans for (bus, jmc), chans in boards.items()
        }
        self._current_slot = {
            (bus, CURRENT_REPLY_BASE + jmc): chans for (bus, jmc), chans in boards.items()
        }
        self._sensor_slot: dict[tuple[int, int], tuple[str, int]] = {}
        self._tx_slots: dict[int, list[int | can.Message]] = {}  # ref row index or message
        self._housekeeping: dict[int, list[can.Message]] = {}
        for bus in sorted({b for b, _ in boards} | {s.can for s in sensors.sensors}):
            self._plan_bus(bus, boards, period_s, bitrate)
        self._ref_bus = np.array([bus for bus, _, _ in self._ref_rows])
        self._scale = joints.rad_per_count
        self._offset = np.array([j.ref_enc for j in joints.joints], dtype=np.int64)

    def _plan_bus(self, bus: int, boards: dict, period_s: float, bitrate: float) -> None:
        """One bus's cycle: per board its reference frames, encoder request and replies,
        then its active sensors' requests and replies; the frames sent are spread evenly
        over the period. Also the board's status and current requests, for
        `housekeeping`."""
        slots: list[int | can.Message] = []
        hk: list[can.Message] = []
        tx: list[tuple[str, int, int]] = []
        rx: list[tuple[str, int, int]] = []
        for (b, jmc), chans in boards.items():
            if b != bus:
                continue
            npairs = (len(chans) + 1) // 2
            for pair in range(npairs):
                tx.append(("ref", REF_BASE + jmc + PAIR_STRIDE * pair, jmc))
                slots.append(self._ref_rows.index((bus, jmc, pair)))
            tx.append(("enc_req", CMD_ID, jmc))
            slots.append(encode_enc_request(jmc))
            hk += [encode_status_request(jmc), encode_current_request(jmc)]
            for pair in range(npairs):
                rx.append(("enc_reply", ENC_REPLY_BASE + jmc + PAIR_STRIDE * pair, jmc))
        for s in self.sensors.sensors:
            if s.can == bus and s.active:
                self._plan_sensor(bus, s, tx, rx, slots)
        step = period_s / max(len(tx), 1)
        plan = BusPlan(bus, period_s=period_s, bitrate=bitrate)
        plan.frames = [
            PlannedFrame(kind, fid, board, True, round(i * step, 9))
            for i, (kind, fid, board) in enumerate(tx)
        ] + [PlannedFrame(kind, fid, board, False) for kind, fid, board in rx]
        self.buses[bus] = plan
        self._tx_slots[bus] = slots
        self._housekeeping[bus] = hk

    def _plan_sensor(self, bus: int, s, tx: list, rx: list, slots: list) -> None:
        """A sensor's request (FT, tilt/IMU or power) and its replies (an IMU also sends
        a gyro reply), and where `decode` puts each reply."""
        if s.kind == "ft":
            tx.append(("ft_req", SENSOR_REQ_ID, s.board))
            slots.append(encode_sensor_request(s.board, SENSOR_FT))
            rx.append(("ft_reply", FT_REPLY_BASE + s.board, s.board))
            self._sensor_slot[(bus, FT_REPLY_BASE + s.board)] = ("ft", FT_NAMES.index(s.name))
        elif s.kind == "imu":
            tx.append(("tilt_req", SENSOR_REQ_ID, s.board))
            slots.append(encode_sensor_request(s.board, SENSOR_TILT))
            k = IMU_NAMES.index(s.name)
            rx.append(("tilt_reply", TILT_REPLY_BASE + s.board, s.board))
            self._sensor_slot[(bus, TILT_REPLY_BASE + s.board)] = ("acc", k)
            if s.name == "IMU":
                rx.append(("gyro_reply", GYRO_REPLY_BASE + s.board, s.board))
                self._sensor_slot[(bus, GYRO_REPLY_BASE + s.board)] = ("gyro", k)
        else:
            tx.append(("power_req", SENSOR_REQ_ID, s.board))
            slots.append(encode_sensor_request(s.board, SENSOR_POWER))
            rx.append(("power_reply", POWER_REPLY_ID, s.board))
            self._sensor_slot[(bus, POWER_REPLY_ID)] = ("power", 0)

    def __repr__(self) -> str:
        loads = ", ".join(
            f"can{b}: {len(p.frames)} frames, load {p.load:.0%}" for b, p in self.buses.items()
        )
        return f"CyclePlan({loads})"

    def report(self) -> str:
        """One line per bus: frame counts and load against the 108-bit budget."""
        lines = []
        for b, p in self.buses.items():
            lines.append(
                f"can{b}: {len(p.tx_frames)} sent + {len(p.frames) - len(p.tx_frames)} replies "
                f"= {len(p.frames)} frames × {FRAME_BITS} bits per {p.period_s * 1e3:g} ms "
                f"at {p.bitrate / 1e6:g} Mbit/s: load {p.load:.1%}"
                + ("" if p.load <= 1.0 else "  OVER BUDGET")
            )
        return "\n".join(lines)

    def within_budget(self) -> bool:
        """True if every bus's load is at most 100 %."""
        return all(p.load <= 1.0 for p in self.buses.values())

    @property
    def max_frames(self) -> int:
        """Frames that fit in one period on one bus at 108 bits each."""
        p = next(iter(self.buses.values()))
        return int(p.bitrate * p.period_s // FRAME_BITS)

    def encode(
        self,
        ref_rad: np.ndarray,
        duty_pct: np.ndarray | None = None,
        pwm_mask: np.ndarray | None = None,
    ) -> dict[int, list[can.Message]]:
        """The frames to send this cycle, per bus, in the order of `BusPlan.tx_frames`.

        A motor pair whose joints are all in PWM mode gets a PWM frame in place of its
        reference frame; a pair with one PWM joint (the wrist roll on a finger board) gets
        both, the PWM frame right after the reference frame.

        Args:
            ref_rad: references of the 40 joints [rad].
            duty_pct: duty of the 40 joints [%]; needed with ``pwm_mask``.
            pwm_mask: (40,) bool, True for joints in PWM (compliant) mode.

        Returns:
            bus → messages; send message i at ``tx_frames[i].offset_s`` (extra PWM frames
            of mixed pairs go with their reference frame).
        """
        counts = np.rint(np.asarray(ref_rad, float) / self._scale).astype(np.int64) + self._offset
        pair_counts = np.where(self._ref_valid, counts[self._ref_index], 0)
        words = to_sign_magnitude(pair_counts.ravel())
        payload = words.astype("<u4").view(np.uint8).reshape(-1, 2, 4)[:, :, :3]
        payload = payload.reshape(-1, 6).tobytes()
        pwm_rows: dict[int, tuple[can.Message, bool]] = {}
        if pwm_mask is not None:
            mask = np.asarray(pwm_mask, bool)
            row_mask = self._ref_valid & mask[self._ref_index]
            for i in np.flatnonzero(row_mask.any(axis=1)):
                _, jmc, pair = self._ref_rows[i]
                idx = self._ref_index[i]
                m = int(row_mask[i, 0]) | int(row_mask[i, 1]) << 1
                d = tuple(float(duty_pct[j]) if row_mask[i, k] else 0.0 for k, j in enumerate(idx))
                only_pwm = bool(np.all(row_mask[i] == self._ref_valid[i]))
                pwm_rows[int(i)] = (encode_pwm(jmc, d, pair, m), only_pwm)
        out: dict[int, list[can.Message]] = {}
        for bus, slots in self._tx_slots.items():
            msgs = out[bus] = []
            for slot in slots:
                if not isinstance(slot, int):
                    msgs.append(slot)
                    continue
                pwm = pwm_rows.get(slot)
                if pwm is None or not pwm[1]:
                    msgs.append(message(self._ref_ids[slot], payload[6 * slot : 6 * slot + 6]))
                if pwm is not None:
                    msgs.append(pwm[0])
        return out

    def housekeeping(self, cycle: int, used: dict[int, int] | None = None) -> dict[int, list]:
        """Status and current requests that fit in this cycle's spare bus time.

        Each request costs two frames (request and reply). The requests go round robin over
        every board, so over a few cycles each board's status and current are read.

        Args:
            cycle: cycle counter.
            used: frames per bus already planned this cycle (default: the plan's frames).
        """
        out = {}
        for bus, reqs in self._housekeeping.items():
            n_used = len(self.buses[bus].frames) if used is None else used[bus]
            fit = max(self.max_frames - n_used, 0) // 2
            if reqs and fit:
                start = (cycle * fit) % len(reqs)
                out[bus] = [reqs[(start + k) % len(reqs)] for k in range(min(fit, len(reqs)))]
        return out

    def decode(
        self, frames: dict[int, list[can.Message]] | list[tuple[int, can.Message]]
    ) -> CycleReadings:
        """Fold one cycle's received frames into readings (vectorised where it matters).

        Args:
            frames: bus → received messages, or a list of (bus, message).
        """
        items = (
            [(b, m) for b, ms in frames.items() for m in ms] if isinstance(frames, dict) else frames
        )
        n = NUM_JOINTS
        enc_chunks: list[bytes] = []
        enc_targets: list[int] = []
        r = CycleReadings(
            enc=np.zeros(n, np.int64),
            pos_rad=np.full(n, np.nan),
            got_enc=np.zeros(n, bool),
            status=np.full(n, int(StatusFlag.NO_REPLY), np.uint32),
            current_a=np.full(n, np.nan),
            ft=np.full((NUM_FT, 3), np.nan),
            imu=np.full((NUM_IMU, 6), np.nan),
            power=np.full(3, np.nan),
        )
        for bus, m in items:
            key = (bus, m.arbitration_id)
            slot = self._enc_slot.get(key)
            if slot is not None:
                data = bytes(m.data)
                for k, j in enumerate(slot):
                    if j >= 0 and 4 * k + 4 <= len(data):
                        enc_chunks.append(data[4 * k : 4 * k + 4])
                        enc_targets.append(j)
                continue
            sensor = self._sensor_slot.get(key)
            if sensor is not None:
                kind, k = sensor
                if kind == "ft":
                    r.ft[k] = decode_ft_reply(m)[1]
                elif kind == "acc":
                    r.imu[k, :3] = decode_imu_reply(m)[2]
                elif kind == "gyro":
                    r.imu[k, 3:] = decode_imu_reply(m)[2]
                else:
                    r.power[:] = decode_power_reply(m)
                continue
            chans = self._status_slot.get(key)
            if chans is not None:
                for j, s in zip(chans, decode_status_reply(m)[1], strict=False):
                    if j >= 0:
                        r.status[j] = int(board_status_to_flags(s))
                continue
            chans = self._current_slot.get(key)
            if chans is not None:
                for j, a in zip(chans, decode_current_reply(m)[1], strict=False):
                    if j >= 0:
                        r.current_a[j] = a
                continue
            r.unknown += 1
        if enc_targets:
            idx = np.array(enc_targets)
            counts = np.frombuffer(b"".join(enc_chunks), "<i4").astype(np.int64)
            r.enc[idx] = counts
            r.got_enc[idx] = True
            r.pos_rad[idx] = (counts - self._offset[idx]) * self._scale[idx]
        return r
