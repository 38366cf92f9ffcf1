"""Fixed-layout structs of the five daemon channels (the role of hubo-ach's C structs).

Every struct is a packed numpy structured dtype (``align=False``: no padding, native
little-endian on every machine we run on), so one sample is one contiguous block of bytes
that can be copied into shared memory as is. Per-joint arrays are indexed in
`robot.joints.JOINT_NAMES` order (the 40 columns of the trajectory file).

Every struct starts with the same header:

| field | type | meaning |
|---|---|---|
| ``writer_id`` | u4 | who wrote the sample (set by the channel writer) |
| ``seq`` | u8 | per-writer sample counter, 1 for the first write |
| ``time_ns`` | i8 | ``CLOCK_MONOTONIC`` at write [ns]; orders samples from all writers |

`daemon.channels` stamps the header on every write. "Newest from anyone" is the sample
with the largest ``(time_ns, seq, writer_id)``.

Sizes (bytes, checked by the tests):

| channel | dtype | size |
|---|---|---|
| ``ref`` | `REF_DTYPE` | 741 |
| ``ref-neck`` | `REF_DTYPE` (only the neck entries are used) | 741 |
| ``board-cmd`` | `BOARD_CMD_DTYPE` | 76 |
| ``pwm-gains`` | `PWM_GAINS_DTYPE` | 1300 |
| ``state`` | `STATE_DTYPE` | 2200 |
"""

from __future__ import annotations

import enum

import numpy as np

from robot.joints import NUM_JOINTS

NUM_FT = 4  #: FT sensors: right foot, left foot, right hand, left hand.
NUM_IMU = 3  #: IMU / tilt sensors: body IMU, right foot tilt, left foot tilt.

#: Which FT sensor sits where (index into ``state["ft"]``).
FT_NAMES = ("RFFT", "LFFT", "RHFT", "LHFT")
#: Which IMU sits where (index into ``state["imu"]``).
IMU_NAMES = ("IMU", "RFT_TILT", "LFT_TILT")


class RefMode(enum.IntEnum):
    """Reference mode of a joint in the ``ref`` struct (hubo-facts §3)."""

    FILTER = 0  #: f = (f·(L−1) + r) / L, L = 40 per 5 ms tick
    DIRECT = 1  #: f = r
    COMPLIANT = 2  #: f = pos
    ENC_FILTER = 3  #: f = (pos·(L−1) + r) / L


class BoardCommandType(enum.IntEnum):
    """Command type of the ``board-cmd`` struct."""

    NONE = 0
    HOME = 1  #: home ``joint``: move to the limit switch, zero the encoder
    HOME_ALL = 2  #: home every joint
    INIT_SENSORS = 3  #: zero FT and IMU offsets (robot must hang still)
    CONTROL_ON = 4  #: enable position control of ``joint``'s board
    CONTROL_OFF = 5  #: disable it
    RESET = 6  #: reset ``joint``'s board (clears TRIPPED)
    SET_GAINS = 7  #: ``dvalues[:3]`` = kp, kd, max_pwm for ``joint``
    ZERO_ENCODER = 8  #: set the encoder of ``joint`` to zero where it stands
    MOTOR_ON = 9  #: power ``joint``'s motor driver
    MOTOR_OFF = 10  #: cut it


class StatusFlag(enum.IntFlag):
    """Per-joint status bits in ``state["status"]``."""

    OK = 0
    NO_REPLY = 1 << 0  #: the board did not answer this cycle
    TRIPPED = 1 << 1  #: the board stopped itself (saturation, over-current)
    NOT_HOMED = 1 << 2  #: encoder not zeroed; references are ignored
    JAM = 1 << 3  #: motor jammed
    PWM_SATURATED = 1 << 4  #: duty hit max_pwm
    BIG_ERROR = 1 << 5  #: |ref − pos| above the board's limit
    ENCODER_ERROR = 1 << 6
    DRIVER_FAULT = 1 << 7
    OVER_CURRENT = 1 << 8
    TEMPERATURE = 1 << 9
    LIMIT_SWITCH = 1 << 10
    COMPLIANT = 1 << 11  #: the joint is in PWM mode
    REF_REJECTED = 1 << 12  #: its commanded reference is beyond its limits: previous one held


HEADER_FIELDS: list[tuple] = [
    ("writer_id", "<u4"),
    ("seq", "<u8"),
    ("time_ns", "<i8"),
]

#: ``ref`` and ``ref-neck``: what the player wants. 741 bytes. ``pwm_command`` is the
#: player's feed-forward duty of this tick (a compliant arm's planned load); the daemon
#: adds it to the ``pwm-gains`` constant ``pwm_command`` of the joints it asks to comply.
REF_DTYPE = np.dtype(
    HEADER_FIELDS
    + [
        ("playing", "u1"),  # 1 while a player streams; the daemon watchdog checks staleness
        ("ref", "<f8", (NUM_JOINTS,)),  # [rad]
        ("mode", "u1", (NUM_JOINTS,)),  # RefMode
        ("comply", "u1", (NUM_JOINTS,)),  # 1 = PWM (compliant) mode
        ("pwm_command", "<f8", (NUM_JOINTS,)),  # [%] feed-forward duty, compliant joints
    ],
    align=False,
)

#: ``board-cmd``: one command to the boards. 76 bytes.
BOARD_CMD_DTYPE = np.dtype(
    HEADER_FIELDS
    + [
        ("type", "<u2"),  # BoardCommandType
        ("joint", "<i2"),  # joint index, −1 = all / not applicable
        ("params", "u1", (4,)),  # command-specific flags
        ("ivalues", "<i4", (4,)),
        ("dvalues", "<f8", (4,)),
    ],
    align=False,
)

#: ``pwm-gains``: per-joint PWM (compliance) gains. 1300 bytes.
PWM_GAINS_DTYPE = np.dtype(
    HEADER_FIELDS
    + [
        ("pwm_command", "<f8", (NUM_JOINTS,)),  # feed-forward duty [%]
        ("kp", "<f8", (NUM_JOINTS,)),  # [% duty / rad]
        ("kd", "<f8", (NUM_JOINTS,)),  # [% duty / (rad/s)]
        ("max_pwm", "<f8", (NUM_JOINTS,)),  # duty clamp [%]
    ],
    align=False,
)

FT_DTYPE = np.dtype([("mx", "<f8"), ("my", "<f8"), ("fz", "<f8")], align=False)  # [N·m, N·m, N]
IMU_DTYPE = np.dtype(
    [(f, "<f8") for f in ("ax", "ay", "az", "wx", "wy", "wz")],  # [m/s², rad/s]
    align=False,
)
POWER_DTYPE = np.dtype([("V", "<f8"), ("I", "<f8"), ("P", "<f8")], align=False)  # [V, A, W]

#: ``state``: what the daemon measured. 2200 bytes.
STATE_DTYPE = np.dtype(
    HEADER_FIELDS
    + [
        ("tick", "<u8"),  # 200 Hz ticks since the daemon started
        ("overruns", "<u8"),  # ticks that missed their deadline
        ("time_s", "<f8"),  # daemon time since start [s], at the tick's start
        # CLOCK_MONOTONIC at the daemon's start [ns]: a ref sample stamped before it is
        # stale. (time_ns minus time_s is later by the tick's work: time_ns is the write.)
        ("start_ns", "<i8"),
        ("ref", "<f8", (NUM_JOINTS,)),  # reference sent to the board [rad]
        ("pos", "<f8", (NUM_JOINTS,)),  # [rad]
        ("vel", "<f8", (NUM_JOINTS,)),  # [rad/s]
        ("cur", "<f8", (NUM_JOINTS,)),  # motor current [A]
        ("duty", "<f8", (NUM_JOINTS,)),  # PWM duty [%]
        ("comply", "u1", (NUM_JOINTS,)),
        ("active", "u1", (NUM_JOINTS,)),
        ("zeroed", "u1", (NUM_JOINTS,)),
        ("status", "<u4", (NUM_JOINTS,)),  # StatusFlag bits
        ("ft", FT_DTYPE, (NUM_FT,)),
        ("imu", IMU_DTYPE, (NUM_IMU,)),
        ("power", POWER_DTYPE),
        ("refs_rejected", "<u4"),  # ref samples with a joint beyond its limits, since start
    ],
    align=False,
)

#: Channel name → struct dtype (channel names without the instance namespace).
CHANNEL_DTYPES: dict[str, np.dtype] = {
    "ref": REF_DTYPE,
    "ref-neck": REF_DTYPE,
    "board-cmd": BOARD_CMD_DTYPE,
    "pwm-gains": PWM_GAINS_DTYPE,
    "state": STATE_DTYPE,
}


def new_sample(dtype: np.dtype) -> np.ndarray:
    """A zeroed 0-d sample of ``dtype``; fields are read and written as ``s["ref"][3]``."""
    return np.zeros((), dtype=dtype)


def describe(dtype: np.dtype) -> str:
    """One line per field with offset and size [bytes], for logs and ``hubo-read``."""
    lines = [f"{dtype.itemsize} bytes"]
    for name in dtype.names or ():
        sub, offset = dtype.fields[name][:2]
        base = sub.base if sub.shape else sub
        kind = ",".join(base.names) if base.names else base.str
        shape = f"[{','.join(map(str, sub.shape))}]" if sub.shape else ""
        lines.append(f"  {offset:5d} {sub.itemsize:5d}  {name}: {kind}{shape}")
    return "\n".join(lines)
