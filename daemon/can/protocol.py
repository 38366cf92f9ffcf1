"""The Hubo CAN frame protocol (DRC-Hubo, hubo-facts §4): pure encode and decode.

No I/O here: functions turn numbers into `can.Message` objects and back, one encoder
beside its decoder per frame kind. All ids are standard 11-bit ids.

Given by hubo-facts §4:

| frame | id | payload |
|---|---|---|
| position reference | 0x10 + jmc | 2 × 24-bit sign-magnitude counts (bit 23 = sign), LE, DLC 6 |
| encoder request | 0x01 | ``[jmc, 0x03, ch]`` |
| PWM | 0x01 | ``[jmc, 0x0D, 0x03, d0hi|dir0, d0lo, d1hi|dir1, d1lo]`` |
| encoder reply | 0x60 + jmc | int32 LE per motor |
| status reply | 0x150 + jmc | status bits |
| current reply | 0x1C0 + jmc | |
| FT request / reply | 0x02 / 0x40 + board | moments 0.01 N·m, force 0.1 N |
| tilt / IMU reply | 0x50 + board | |

Our interpretation where the facts are silent (ASSUMPTIONS, to check against a board):

- **Boards with more than two motors** (neck: 3, finger boards: 6) take one reference
  frame per motor pair ``k`` at id ``0x10 + jmc + 0x100·k``; their encoder replies come
  at ``0x60 + jmc + 0x100·k``. Pair 0 is exactly the documented frame.
- **Encoder request** ``[jmc, 0x03, ch]``: ``ch = 0`` asks for every motor; the board
  answers one reply per pair (one request per board keeps ``can1`` under budget).
- **PWM duty**: 10-bit magnitude in **0.1 % units** (0…1000 = 0…100 %), high bits in
  bits 0–1 of the ``hi`` byte, ``dir`` = bit 7 of the ``hi`` byte, set for a negative
  duty. Byte 2 is ``pair << 4 | mask``: ``0x03`` is the documented "both motors of
  pair 0"; mask bit 0/1 puts the first/second motor of the pair in PWM mode, a cleared
  bit returns it to position mode.
- **Status request** ``[jmc, 0x02]``, reply one byte per motor (`BoardStatus` bits).
- **Current request** ``[jmc, 0x04]``, reply int16 LE per motor [0.01 A].
- **Sensor request** on id 0x02: ``[board, kind]``, kind 0 = FT, 1 = tilt/IMU,
  2 = power. FT reply: int16 LE mx, my [0.01 N·m], fz [0.1 N], DLC 6.
- **Tilt/IMU reply** 0x50 + board: int16 LE ax, ay, az [0.01 m/s²], DLC 6; an IMU also
  sends a gyro reply at 0x58 + board: int16 LE wx, wy, wz [0.001 rad/s].
- **Power reply** at 0x40 + 0x0E (the power board's number): uint16 LE V [0.01 V],
  int16 LE I [0.01 A]; P = V·I.

The frames of one whole cycle, planned per bus, are `daemon.can.cycle_plan`'s.
"""

from __future__ import annotations

import enum
import math
import struct

import can
import numpy as np

from daemon.structs import StatusFlag
from robot.errors import HuboLadderError

CMD_ID = 0x01
SENSOR_REQ_ID = 0x02
REF_BASE = 0x10
FT_REPLY_BASE = 0x40
TILT_REPLY_BASE = 0x50
GYRO_REPLY_BASE = 0x58
ENC_REPLY_BASE = 0x60
STATUS_REPLY_BASE = 0x150
CURRENT_REPLY_BASE = 0x1C0
PAIR_STRIDE = 0x100  #: id offset of motor pair k on boards with more than two motors
POWER_BOARD = 0x0E
POWER_REPLY_ID = FT_REPLY_BASE + POWER_BOARD

CMD_STATUS_REQUEST = 0x02
CMD_ENC_REQUEST = 0x03
CMD_CURRENT_REQUEST = 0x04
CMD_PWM = 0x0D

SENSOR_FT = 0
SENSOR_TILT = 1
SENSOR_POWER = 2

MAX_COUNTS = (1 << 23) - 1  #: largest 24-bit sign-magnitude magnitude
MAX_DUTY_TENTHS = 1000  #: 100 % in 0.1 % units
DIR_BIT = 0x80


class ProtocolError(HuboLadderError):
    """A frame cannot be encoded (value out of range) or decoded (wrong id or length)."""


class BoardStatus(enum.IntFlag):
    """Status-reply bits, one byte per motor."""

    HOMED = 0x01
    JAM = 0x02
    PWM_SATURATED = 0x04
    BIG_ERROR = 0x08
    ENCODER_ERROR = 0x10
    DRIVER_FAULT = 0x20
    OVER_CURRENT = 0x40
    CONTROL_ON = 0x80


def board_status_to_flags(status: int) -> StatusFlag:
    """Map a status-reply byte to the `StatusFlag` bits of the state struct."""
    s = BoardStatus(status)
    flags = StatusFlag.OK
    if not s & BoardStatus.HOMED:
        flags |= StatusFlag.NOT_HOMED
    for bit, flag in (
        (BoardStatus.JAM, StatusFlag.JAM),
        (BoardStatus.PWM_SATURATED, StatusFlag.PWM_SATURATED),
        (BoardStatus.BIG_ERROR, StatusFlag.BIG_ERROR),
        (BoardStatus.ENCODER_ERROR, StatusFlag.ENCODER_ERROR),
        (BoardStatus.DRIVER_FAULT, StatusFlag.DRIVER_FAULT),
        (BoardStatus.OVER_CURRENT, StatusFlag.OVER_CURRENT),
    ):
        if s & bit:
            flags |= flag
    if s & (BoardStatus.JAM | BoardStatus.DRIVER_FAULT | BoardStatus.OVER_CURRENT):
        flags |= StatusFlag.TRIPPED
    return flags


def message(arbitration_id: int, data: bytes | bytearray) -> can.Message:
    """A standard-id (11-bit) frame."""
    return can.Message(arbitration_id=arbitration_id, data=data, is_extended_id=False)


def _expect(msg: can.Message, base: int, span: int, what: str) -> int:
    off = msg.arbitration_id - base
    if not 0 <= off < span:
        raise ProtocolError(f"{what}: unexpected id {msg.arbitration_id:#x}")
    return off


# ---------------------------------------------------------------- sign-magnitude


def to_sign_magnitude(counts: np.ndarray) -> np.ndarray:
    """int counts → 24-bit sign-magnitude words (bit 23 = sign), vectorised.

    Raises:
        ProtocolError: a magnitude above 2²³ − 1.
    """
    c = np.asarray(counts, dtype=np.int64)
    mag = np.abs(c)
    if np.any(mag > MAX_COUNTS):
        bad = c[mag > MAX_COUNTS]
        raise ProtocolError(f"encoder count out of 24-bit range ±{MAX_COUNTS}: {bad}")
    return (mag | ((c < 0).astype(np.int64) << 23)).astype(np.uint32)


def from_sign_magnitude(word: int) -> int:
    """One 24-bit sign-magnitude word → count (``0x800000`` decodes to 0). Scalar: a
    reference frame holds two words, where numpy's per-call cost would dominate."""
    mag = word & MAX_COUNTS
    return -mag if word & (1 << 23) else mag


# ---------------------------------------------------------------- joint frames


def encode_ref(jmc: int, counts: tuple[int, int], pair: int = 0) -> can.Message:
    """Position reference of one motor pair: id 0x10 + jmc (+ 0x100·pair), DLC 6."""
    words = to_sign_magnitude(np.asarray(counts, dtype=np.int64).reshape(2))
    data = words.astype("<u4").view(np.uint8).reshape(2, 4)[:, :3].tobytes()
    return message(REF_BASE + jmc + PAIR_STRIDE * pair, data)


def decode_ref(msg: can.Message) -> tuple[int, int, tuple[int, int]]:
    """Position reference → (jmc, pair, (count0, count1))."""
    off = msg.arbitration_id - REF_BASE
    pair, jmc = divmod(off, PAIR_STRIDE)
    if not (0 <= jmc < 0x30 and 0 <= pair < 4) or msg.dlc != 6:
        raise ProtocolError(f"not a reference frame: id {msg.arbitration_id:#x} dlc {msg.dlc}")
    b = msg.data
    return jmc, pair, (from_sign_magnitude(b[0] | b[1] << 8 | b[2] << 16),
                       from_sign_magnitude(b[3] | b[4] << 8 | b[5] << 16))


def encode_enc_request(jmc: int, ch: int = 0) -> can.Message:
    """Encoder request ``[jmc, 0x03, ch]`` on id 0x01 (ch 0: every motor)."""
    return message(CMD_ID, bytes([jmc, CMD_ENC_REQUEST, ch]))


def encode_status_request(jmc: int) -> can.Message:
    """Status request ``[jmc, 0x02]`` on id 0x01."""
    return message(CMD_ID, bytes([jmc, CMD_STATUS_REQUEST]))


def encode_current_request(jmc: int) -> can.Message:
    """Current request ``[jmc, 0x04]`` on id 0x01."""
    return message(CMD_ID, bytes([jmc, CMD_CURRENT_REQUEST]))


def _duty_bytes(duty_pct: float) -> tuple[int, int]:
    tenths = int(round(abs(duty_pct) * 10.0))
    if tenths > MAX_DUTY_TENTHS or math.isnan(duty_pct):
        raise ProtocolError(f"PWM duty {duty_pct} % outside ±100 %")
    hi = (tenths >> 8) & 0x03
    if duty_pct < 0 and tenths:
        hi |= DIR_BIT
    return hi, tenths & 0xFF


def encode_pwm(
    jmc: int, duty_pct: tuple[float, float], pair: int = 0, mask: int = 0x03
) -> can.Message:
    """PWM command ``[jmc, 0x0D, pair<<4|mask, d0hi|dir0, d0lo, d1hi|dir1, d1lo]``.

    Args:
        jmc: board number.
        duty_pct: duty of the pair's two motors [%], ±100, resolution 0.1 %.
        pair: motor pair on the board.
        mask: bit 0/1 puts motor 0/1 of the pair in PWM mode (0x03: both).
    """
    h0, l0 = _duty_bytes(duty_pct[0])
    h1, l1 = _duty_bytes(duty_pct[1])
    return message(CMD_ID, bytes([jmc, CMD_PWM, (pair << 4) | (mask & 0x03), h0, l0, h1, l1]))


def decode_command(msg: can.Message) -> tuple[int, int, dict]:
    """Command frame (id 0x01) → (jmc, cmd, fields).

    Fields: encoder request ``{"ch"}``; PWM ``{"pair", "mask", "duty_pct": (d0, d1)}``;
    others ``{}``.
    """
    if msg.arbitration_id != CMD_ID or msg.dlc < 2:
        raise ProtocolError(f"not a command frame: id {msg.arbitration_id:#x} dlc {msg.dlc}")
    d = bytes(msg.data)
    jmc, cmd = d[0], d[1]
    if cmd == CMD_ENC_REQUEST:
        return jmc, cmd, {"ch": d[2] if len(d) > 2 else 0}
    if cmd == CMD_PWM:
        if len(d) != 7:
            raise ProtocolError(f"PWM frame needs 7 bytes, got {len(d)}")

        def duty(hi: int, lo: int) -> float:
            tenths = (hi & 0x03) << 8 | lo
            return (-tenths if hi & DIR_BIT else tenths) / 10.0

        return jmc, cmd, {
            "pair": d[2] >> 4,
            "mask": d[2] & 0x03,
            "duty_pct": (duty(d[3], d[4]), duty(d[5], d[6])),
        }
    return jmc, cmd, {}


def encode_enc_reply(jmc: int, counts: list[int] | tuple[int, ...], pair: int = 0) -> can.Message:
    """Encoder reply: int32 LE per motor (1 or 2) at id 0x60 + jmc (+ 0x100·pair)."""
    try:
        data = struct.pack(f"<{len(counts)}i", *counts)
    except struct.error as exc:
        raise ProtocolError(f"encoder counts {counts} out of int32 range") from exc
    return message(ENC_REPLY_BASE + jmc + PAIR_STRIDE * pair, data)


def decode_enc_reply(msg: can.Message) -> tuple[int, int, tuple[int, ...]]:
    """Encoder reply → (jmc, pair, counts)."""
    pair, jmc = divmod(msg.arbitration_id - ENC_REPLY_BASE, PAIR_STRIDE)
    if not (0 <= jmc < 0x30 and 0 <= pair < 4) or msg.dlc not in (4, 8):
        raise ProtocolError(f"not an encoder reply: id {msg.arbitration_id:#x} dlc {msg.dlc}")
    return jmc, pair, tuple(int(x) for x in np.frombuffer(bytes(msg.data), "<i4"))


def encode_status_reply(jmc: int, status: list[int] | tuple[int, ...]) -> can.Message:
    """Status reply: one `BoardStatus` byte per motor at id 0x150 + jmc."""
    return message(STATUS_REPLY_BASE + jmc, bytes(status))


def decode_status_reply(msg: can.Message) -> tuple[int, tuple[int, ...]]:
    """Status reply → (jmc, status bytes per motor)."""
    jmc = _expect(msg, STATUS_REPLY_BASE, 0x30, "status reply")
    return jmc, tuple(bytes(msg.data))


def encode_current_reply(jmc: int, current_a: list[float] | tuple[float, ...]) -> can.Message:
    """Current reply: int16 LE per motor [0.01 A] at id 0x1C0 + jmc (≤ 4 motors)."""
    raw = np.clip(np.rint(np.asarray(current_a, float) * 100.0), -32768, 32767)
    return message(CURRENT_REPLY_BASE + jmc, raw.astype("<i2").tobytes())


def decode_current_reply(msg: can.Message) -> tuple[int, tuple[float, ...]]:
    """Current reply → (jmc, currents [A])."""
    jmc = _expect(msg, CURRENT_REPLY_BASE, 0x30, "current reply")
    return jmc, tuple(float(x) / 100.0 for x in np.frombuffer(bytes(msg.data), "<i2"))


# ---------------------------------------------------------------- sensor frames


def encode_sensor_request(board: int, kind: int) -> can.Message:
    """Sensor request ``[board, kind]`` on id 0x02 (0 FT, 1 tilt/IMU, 2 power)."""
    return message(SENSOR_REQ_ID, bytes([board, kind]))


def decode_sensor_request(msg: can.Message) -> tuple[int, int]:
    """Sensor request → (board, kind)."""
    if msg.arbitration_id != SENSOR_REQ_ID or msg.dlc != 2:
        raise ProtocolError(f"not a sensor request: id {msg.arbitration_id:#x} dlc {msg.dlc}")
    return msg.data[0], msg.data[1]


def _i16(values: tuple[float, ...], scale: float, what: str) -> bytes:
    """Values × scale, rounded half to even, as int16 LE (±32767; NaN is out of range).

    struct, not numpy: the board emulator packs a few values per frame, where numpy's
    per-call cost would dominate.
    """
    scaled = [float(v) * scale for v in values]
    if not all(abs(x) < 32767.5 for x in scaled):  # 32767.5 rounds to 32768
        raise ProtocolError(f"{what} out of int16 range: {values}")
    return struct.pack(f"<{len(scaled)}h", *(round(x) for x in scaled))


def encode_ft_reply(board: int, mx: float, my: float, fz: float) -> can.Message:
    """FT reply at 0x40 + board: mx, my [N·m] in 0.01 N·m, fz [N] in 0.1 N."""
    data = _i16((mx, my), 100.0, "FT moment") + _i16((fz,), 10.0, "FT force")
    return message(FT_REPLY_BASE + board, data)


def decode_ft_reply(msg: can.Message) -> tuple[int, tuple[float, float, float]]:
    """FT reply → (board, (mx [N·m], my [N·m], fz [N]))."""
    board = _expect(msg, FT_REPLY_BASE, 0x10, "FT reply")
    v = np.frombuffer(bytes(msg.data), "<i2")
    return board, (v[0] / 100.0, v[1] / 100.0, v[2] / 10.0)


def encode_tilt_reply(board: int, acc: tuple[float, float, float]) -> can.Message:
    """Tilt/IMU acceleration reply at 0x50 + board: ax, ay, az [m/s²] in 0.01 m/s²."""
    return message(TILT_REPLY_BASE + board, _i16(acc, 100.0, "acceleration"))


def encode_gyro_reply(board: int, rate: tuple[float, float, float]) -> can.Message:
    """IMU gyro reply at 0x58 + board: wx, wy, wz [rad/s] in 0.001 rad/s."""
    return message(GYRO_REPLY_BASE + board, _i16(rate, 1000.0, "angular rate"))


def decode_imu_reply(msg: can.Message) -> tuple[int, str, tuple[float, float, float]]:
    """Tilt or gyro reply → (board, "acc" | "gyro", values [m/s²] or [rad/s])."""
    v = np.frombuffer(bytes(msg.data), "<i2")
    if GYRO_REPLY_BASE <= msg.arbitration_id < GYRO_REPLY_BASE + 8:
        return msg.arbitration_id - GYRO_REPLY_BASE, "gyro", tuple(v / 1000.0)
    board = _expect(msg, TILT_REPLY_BASE, 8, "tilt reply")
    return board, "acc", tuple(v / 100.0)


def encode_power_reply(volts: float, amps: float) -> can.Message:
    """Power reply at 0x4E: V [0.01 V] uint16, I [0.01 A] int16."""
    v = int(round(volts * 100.0))
    if not 0 <= v <= 0xFFFF:
        raise ProtocolError(f"bus voltage {volts} V out of range")
    return message(POWER_REPLY_ID, struct.pack("<H", v) + _i16((amps,), 100.0, "I"))


def decode_power_reply(msg: can.Message) -> tuple[float, float, float]:
    """Power reply → (V [V], I [A], P [W])."""
    if msg.arbitration_id != POWER_REPLY_ID:
        raise ProtocolError(f"not a power reply: id {msg.arbitration_id:#x}")
    b = bytes(msg.data)
    volts = int.from_bytes(b[0:2], "little") / 100.0
    amps = int.from_bytes(b[2:4], "little", signed=True) / 100.0
    return volts, amps, volts * amps
