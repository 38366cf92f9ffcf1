"""What the operator's page shows of one state sample: a row per joint and per sensor.

The thesis traces most climbing failures to "improper initialization of the joints", so
a joint's board state is graded at a glance (`Severity`): a fault stops the joint or the
climb (tripped, silent, jammed, over current, ...), a warning needs the operator (not
homed, a reference refused beyond the joint's limits, PWM saturated, ...). Plain numpy:
the page (`daemon.station.page`) only lays these rows out.
"""

from __future__ import annotations

import enum
from typing import NamedTuple

import numpy as np

from daemon.control_modes import RefMode
from daemon.structs import FT_NAMES, IMU_NAMES, StatusFlag
from robot.joints import JOINT_NAMES

__all__ = ["FAULT_FLAGS", "WARNING_FLAGS", "JointRow", "SensorRow", "Severity", "joint_rows",
           "sensor_rows", "severity_of", "summary_line"]


class Severity(enum.IntEnum):
    """How a joint's board state is coloured: worse is larger."""

    OK = 0
    WARNING = 1
    FAULT = 2


#: Board states that stop the joint: red.
FAULT_FLAGS = (StatusFlag.NO_REPLY | StatusFlag.TRIPPED | StatusFlag.JAM
               | StatusFlag.BIG_ERROR | StatusFlag.ENCODER_ERROR | StatusFlag.DRIVER_FAULT
               | StatusFlag.OVER_CURRENT | StatusFlag.TEMPERATURE)
#: Board states the operator must act on or watch: amber.
WARNING_FLAGS = (StatusFlag.NOT_HOMED | StatusFlag.REF_REJECTED | StatusFlag.PWM_SATURATED
                 | StatusFlag.LIMIT_SWITCH)


class JointRow(NamedTuple):
    """One joint as the page shows it. Angles [rad]."""

    name: str
    pos_rad: float
    ref_rad: float  # the reference the daemon sent to the board
    error_rad: float  # ref − pos
    mode: str  # "position" or "PWM", with the reference mode of the newest ref sample
    board: str  # the status flags' names, "OK" when none; "off" when not active
    severity: Severity


class SensorRow(NamedTuple):
    """One sensor: its name and its readings as (label, value, unit) triples."""

    name: str
    readings: tuple[tuple[str, float, str], ...]


def severity_of(status: int, active: bool) -> Severity:
    """The colour of a joint whose status bits are ``status`` and whose board is
    ``active`` (a board that is not active drives nothing: a fault)."""
    if not active or status & int(FAULT_FLAGS):
        return Severity.FAULT
    if status & int(WARNING_FLAGS):
        return Severity.WARNING
    return Severity.OK


def _flag_names(status: int) -> str:
    flags = StatusFlag(status)
    return " ".join(f.name for f in StatusFlag if f and f in flags) or "OK"


def joint_rows(state: np.ndarray, ref_mode: np.ndarray | None = None) -> list[JointRow]:
    """A row per joint, in trajectory-file order.

    Args:
        state: a ``state`` channel sample.
        ref_mode: the ``mode`` array (`RefMode` per joint) of the newest ``ref`` sample
            the daemon follows, or None when there is none (the daemon holds).
    """
    rows = []
    for j, name in enumerate(JOINT_NAMES):
        status, active = int(state["status"][j]), bool(state["active"][j])
        kind = "PWM" if state["comply"][j] else "position"
        mode = kind if ref_mode is None else f"{kind} {RefMode(int(ref_mode[j])).name}"
        board = _flag_names(status) if active else f"off {_flag_names(status)}"
        pos, ref = float(state["pos"][j]), float(state["ref"][j])
        rows.append(JointRow(name, pos, ref, ref - pos, mode, board,
                             severity_of(status, active)))
    return rows


def sensor_rows(state: np.ndarray) -> list[SensorRow]:
    """The four F/T sensors, the IMU and the two foot tilt sensors, and the battery."""
    rows = []
    for i, name in enumerate(FT_NAMES):
        ft = state["ft"][i]
        rows.append(SensorRow(name, (("mx", float(ft["mx"]), "N·m"),
                                     ("my", float(ft["my"]), "N·m"),
                                     ("fz", float(ft["fz"]), "N"))))
    for i, name in enumerate(IMU_NAMES):
        imu = state["imu"][i]
        rows.append(SensorRow(name, tuple((f, float(imu[f]), "m/s²") for f in ("ax", "ay", "az"))
                              + tuple((f, float(imu[f]), "rad/s") for f in ("wx", "wy", "wz"))))
    power = state["power"]
    rows.append(SensorRow("battery", (("V", float(power["V"]), "V"), ("I", float(power["I"]), "A"),
                                      ("P", float(power["P"]), "W"))))
    return rows


def summary_line(state: np.ndarray, age_s: float) -> str:
    """The daemon's clock and counters, and how old the sample is [s]."""
    status = np.asarray(state["status"])
    faults = sum(severity_of(int(s), bool(a)) is Severity.FAULT
                 for s, a in zip(status, state["active"], strict=True))
    homed = int(np.sum(state["zeroed"]))
    return (f"t {float(state['time_s']):.1f} s  tick {int(state['tick'])}  "
            f"overruns {int(state['overruns'])}  homed {homed}/{len(status)}  "
            f"faults {faults}  refs rejected {int(state['refs_rejected'])}  "
            f"sample age {age_s * 1e3:.0f} ms")
