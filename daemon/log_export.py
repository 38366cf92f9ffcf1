"""``hubo-log-mcap``: a state log (`daemon.state_log`) as an MCAP file of ROS 2 messages.

    hubo-log-mcap LOG -o OUT.mcap [--rate HZ]

Foxglove Studio opens the file as is, and ``ros2 bag info OUT.mcap`` / ``ros2 bag play``
read it (rosbag2's MCAP storage): every channel carries CDR messages of a standard ROS 2
type, and its schema is the type's concatenated message definition, as rosbag2 writes it.

Topics (only those the log has data for; nothing is made up):

- ``/joint_states`` (``sensor_msgs/msg/JointState``): the 40 joints in
  `robot.joints.JOINT_NAMES` order, ``position`` = encoder position ``pos`` [rad],
  ``velocity`` = ``vel`` [rad/s]. ``effort`` is empty: the log has motor currents [A] but
  no torque, nor the torque constants and gear ratios that would turn one into the other.
- ``/joint_references`` (``sensor_msgs/msg/JointState``): ``position`` = the reference
  sent to the boards, ``ref`` [rad].
- ``/imu``, ``/imu/RFT_TILT``, ``/imu/LFT_TILT`` (``sensor_msgs/msg/Imu``): the body IMU
  and the foot tilt sensors (`daemon.structs.IMU_NAMES`): ``linear_acceleration`` [m/s²]
  and ``angular_velocity`` [rad/s]. The log has no orientation: ``orientation`` is all
  zeros and ``orientation_covariance[0] = -1``, the ROS convention for "not provided". A
  foot tilt sensor's rates are marked the same way unless they were measured (the CAN
  boards send none; the simulated sensors do: `_tilt_rates_measured`).
- ``/ft/RFFT``, ``/ft/LFFT``, ``/ft/RHFT``, ``/ft/LHFT`` (``geometry_msgs/msg/WrenchStamped``,
  `daemon.structs.FT_NAMES`): ``torque.x = mx``, ``torque.y = my`` [N·m], ``force.z = fz``
  [N]. The sensors measure only these three axes; ``force.x``, ``force.y`` and
  ``torque.z`` are NaN (a wrench has no covariance to say "not measured" with).
- ``/player`` (``diagnostic_msgs/msg/DiagnosticArray``), daemon logs only: the player's
  state as the daemon saw it each tick: ``playing``, ``watchdog`` (stale reference,
  holding: level WARN) and ``ref_age_ms``. The log does not record the player's line in
  its trajectory file, so no line index is exported.

Times: the header stamp and the MCAP log time are the log's ``time_s`` (daemon time since
start [s]) to the nanosecond; the file therefore starts near 1970-01-01 00:00:00 in
Foxglove's clock. Every record is exported unless ``--rate HZ`` keeps the first record of
each 1/HZ s period.

Exit codes: 0 written, 1 the mcap packages are missing, 2 bad input (nothing written).
"""

from __future__ import annotations

import argparse
import importlib.util
import logging
import math
import os
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from daemon.state_log import read_log_meta, read_state_log
from daemon.structs import FT_NAMES, IMU_NAMES, NUM_FT, NUM_IMU
from robot.constants import DAEMON_RATE_HZ
from robot.errors import HuboLadderError, InputError, run_cli
from robot.joints import JOINT_NAMES, NUM_JOINTS
from robot.output_path import writable_output

__all__ = ["ExportResult", "export_mcap", "main", "msgdef"]

log = logging.getLogger(__name__)

JOINT_STATE = "sensor_msgs/msg/JointState"
IMU = "sensor_msgs/msg/Imu"
WRENCH_STAMPED = "geometry_msgs/msg/WrenchStamped"
DIAGNOSTIC_ARRAY = "diagnostic_msgs/msg/DiagnosticArray"

#: Message definitions of the ROS 2 types used, as in their ``.msg`` files (comments and
#: default values left out), keyed as rosbag2 names them after ``MSG:``.
_MSG_TEXT = {
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec\n",
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id\n",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z\n",
    "geometry_msgs/Quaternion": "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
    "geometry_msgs/Wrench": "geometry_msgs/Vector3 force\ngeometry_msgs/Vector3 torque\n",
    "geometry_msgs/WrenchStamped": "std_msgs/Header header\ngeometry_msgs/Wrench wrench\n",
    "sensor_msgs/JointState": ("std_msgs/Header header\nstring[] name\nfloat64[] position\n"
                               "float64[] velocity\nfloat64[] effort\n"),
    "sensor_msgs/Imu": ("std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n"
                        "float64[9] orientation_covariance\n"
                        "geometry_msgs/Vector3 angular_velocity\n"
                        "float64[9] angular_velocity_covariance\n"
                        "geometry_msgs/Vector3 linear_acceleration\n"
                        "float64[9] linear_acceleration_covariance\n"),
    "diagnostic_msgs/KeyValue": "string key\nstring value\n",
    "diagnostic_msgs/DiagnosticStatus": ("byte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte STALE=3\n"
                                         "byte level\nstring name\nstring message\n"
                                         "string hardware_id\n"
                                         "diagnostic_msgs/KeyValue[] values\n"),
    "diagnostic_msgs/DiagnosticArray": ("std_msgs/Header header\n"
                                        "diagnostic_msgs/DiagnosticStatus[] status\n"),
}
_SEPARATOR = "=" * 80 + "\n"

#: Fields a log must have, with their shape: without them there is nothing to export.
_REQUIRED = {"time_s": (), "pos": (NUM_JOINTS,)}
_PLAYER_FIELDS = ("playing", "watchdog", "ref_age_ms")
_NOT_PROVIDED = [-1.0] + [0.0] * 8  # covariance of an Imu part the sensor does not give
_UNKNOWN = [0.0] * 9  # covariance of a given part: unknown (ROS convention)
_DIAG_OK, _DIAG_WARN = 0, 1


def msgdef(datatype: str) -> str:
    """The concatenated message definition of ``datatype`` (``pkg/msg/Type``): its own
    text, then each type it uses, once, after a separator line and ``MSG: pkg/Type`` (the
    schema text rosbag2 stores in an MCAP file)."""
    top = datatype.replace("/msg/", "/")
    order: list[str] = []

    def visit(name: str) -> None:
        for line in _MSG_TEXT[name].splitlines():
            ftype = line.split()[0].split("[")[0]
            if "/" in ftype and ftype not in order:
                order.append(ftype)
                visit(ftype)

    visit(top)
    return _MSG_TEXT[top] + "".join(f"{_SEPARATOR}MSG: {n}\n{_MSG_TEXT[n]}" for n in order)


@dataclass(frozen=True)
class ExportResult:
    """What `export_mcap` wrote.

    Attributes:
        path: the MCAP file.
        records: log records exported (after ``rate_hz`` decimation).
        duration_s: time from the first to the last exported record [s].
        messages: topic → (ROS 2 type, messages written).
        size_bytes: file size [bytes].
    """

    path: Path
    records: int
    duration_s: float
    messages: dict[str, tuple[str, int]]
    size_bytes: int

    def summary(self) -> str:
        """Lines for the CLI: the file, its size and span, then one line per topic."""
        head = (f"wrote {self.path}: {self.records} records, {self.duration_s:.3f} s, "
                f"{self.size_bytes / 1e6:.2f} MB")
        width = max(len(t) for t in self.messages)
        return "\n".join([head] + [f"  {t:<{width}}  {kind:<36} {n:>8} messages"
                                   for t, (kind, n) in self.messages.items()])


def require_mcap() -> None:
    """Raise a `HuboLadderError` that says how to install the MCAP writer, if missing."""
    for module, package in (("mcap", "mcap"), ("mcap_ros2", "mcap-ros2-support")):
        if importlib.util.find_spec(module) is None:
            raise HuboLadderError(f"MCAP export needs the {package} package: pip install -e "
                                  "'.[ros]' (make install does)")


def check_output(path: str | os.PathLike, log_path: str | os.PathLike) -> Path:
    """``path`` if an MCAP file can be written there: a ``.mcap`` name, in a folder that
    exists, not the log itself."""
    out = writable_output(path, ".mcap", "the MCAP export")
    if out.exists() and out.resolve() == Path(log_path).resolve():
        raise InputError(f"{out}: is the log being exported; name another file")
    return out


def check_rate(rate_hz: float | None) -> None:
    """Refuse a ``--rate`` that is not in (0, the daemon's rate] [Hz]."""
    if rate_hz is not None and not (math.isfinite(rate_hz) and 0 < rate_hz <= DAEMON_RATE_HZ):
        raise InputError(f"--rate {rate_hz:g}: must be in (0, {DAEMON_RATE_HZ:g}] Hz "
                         "(the daemon's rate)")


def load_log(path: str | os.PathLike) -> tuple[np.ndarray, dict]:
    """The records and header meta of a state log, checked for what an export needs:
    ``time_s`` and ``pos`` fields, at least one record, finite non-negative times that
    never go back.

    Raises:
        InputError: the file is missing, not a state log, or fails a check (named).
    """
    path = Path(path)
    records = read_state_log(path)
    meta = read_log_meta(path)
    names = records.dtype.names or ()
    for field, shape in _REQUIRED.items():
        if field not in names or records.dtype[field].shape != shape:
            raise InputError(f"{path}: no {field!r} field of shape {shape} in its records")
    if len(records) == 0:
        raise InputError(f"{path}: has no complete record")
    t_s = records["time_s"]
    bad = np.flatnonzero(~np.isfinite(t_s) | (t_s < 0))
    if bad.size:
        raise InputError(f"{path}: record {bad[0]} has time_s {t_s[bad[0]]!r} "
                         "(finite and >= 0 only)")
    back = np.flatnonzero(np.diff(t_s) < 0)
    if back.size:
        k = back[0] + 1
        raise InputError(f"{path}: record {k} goes back in time ({t_s[k]:.6f} s after "
                         f"{t_s[k - 1]:.6f} s)")
    return records, meta


def decimate(t_s: np.ndarray, rate_hz: float | None) -> np.ndarray:
    """Indices of the records to keep: all of them, or the first record of each period of
    1/``rate_hz`` s counted from the first record (robust to dropped ticks)."""
    if rate_hz is None:
        return np.arange(len(t_s))
    period = np.floor((t_s - t_s[0]) * rate_hz + 1e-9).astype(np.int64)
    return np.flatnonzero(np.r_[True, period[1:] != period[:-1]])


def _has(records: np.ndarray, field: str, shape: tuple) -> bool:
    names = records.dtype.names or ()
    return field in names and records.dtype[field].shape == shape


def _tilt_rates_measured(records: np.ndarray, meta: dict, k: int) -> bool:
    """Whether IMU ``k``'s angular rates are measurements: always for the body IMU; for a
    foot tilt sensor, in simulation, not on CAN (the boards send no rates, the state
    keeps zeros), and when the log does not say, if any rate is not exactly zero."""
    if IMU_NAMES[k] == "IMU":
        return True
    backend = meta.get("backend")
    if backend in ("sim", "can"):
        return backend == "sim"
    imu = records["imu"][:, k]
    return bool(np.any((imu["wx"] != 0) | (imu["wy"] != 0) | (imu["wz"] != 0)))


def _header(sec: int, nanosec: int, frame_id: str = "") -> dict:
    return {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": frame_id}


def _vector(x: float, y: float, z: float) -> dict:
    return {"x": x, "y": y, "z": z}


def _write_all(writer, records: np.ndarray, meta: dict, stamps_ns: np.ndarray) -> dict:
    """Write every topic the records have data for; topic → (type, message count)."""
    schemas: dict[str, object] = {}

    def schema(kind: str):
        if kind not in schemas:
            schemas[kind] = writer.register_msgdef(kind, msgdef(kind))
        return schemas[kind]

    counts: dict[str, tuple[str, int]] = {}
    sec = (stamps_ns // 1_000_000_000).tolist()
    nsec = (stamps_ns % 1_000_000_000).tolist()
    log_ns = stamps_ns.tolist()

    def emit(topic: str, kind: str, build) -> None:
        s = schema(kind)
        for i in range(len(records)):
            writer.write_message(topic, s, build(i, _header(sec[i], nsec[i])),
                                 log_time=log_ns[i], publish_time=log_ns[i], sequence=i)
        counts[topic] = (kind, len(records))

    names = list(JOINT_NAMES)
    pos = records["pos"].tolist()
    vel = records["vel"].tolist() if _has(records, "vel", (NUM_JOINTS,)) else None
    emit("/joint_states", JOINT_STATE, lambda i, h: {
        "header": h, "name": names, "position": pos[i],
        "velocity": vel[i] if vel is not None else [], "effort": []})
    if _has(records, "ref", (NUM_JOINTS,)):
        ref = records["ref"].tolist()
        emit("/joint_references", JOINT_STATE, lambda i, h: {
            "header": h, "name": names, "position": ref[i], "velocity": [], "effort": []})

    if _has(records, "imu", (NUM_IMU,)):
        for k, name in enumerate(IMU_NAMES):
            _emit_imu(emit, records, meta, k, name)
    if _has(records, "ft", (NUM_FT,)):
        for k, name in enumerate(FT_NAMES):
            ft = records["ft"][:, k]
            mx, my, fz = ft["mx"].tolist(), ft["my"].tolist(), ft["fz"].tolist()
            emit(f"/ft/{name}", WRENCH_STAMPED, lambda i, h, name=name, mx=mx, my=my, fz=fz: {
                "header": {**h, "frame_id": name},
                "wrench": {"force": _vector(math.nan, math.nan, fz[i]),
                           "torque": _vector(mx[i], my[i], math.nan)}})
    if all(_has(records, f, ()) for f in _PLAYER_FIELDS):
        _emit_player(emit, records, str(meta.get("instance") or ""))
    return counts


def _emit_imu(emit, records: np.ndarray, meta: dict, k: int, name: str) -> None:
    """One ``sensor_msgs/msg/Imu`` topic for IMU ``k``: acceleration and, when measured,
    angular rates; no orientation."""
    imu = records["imu"][:, k]
    acc = np.stack([imu["ax"], imu["ay"], imu["az"]], axis=1).tolist()
    measured = _tilt_rates_measured(records, meta, k)
    rate = np.stack([imu["wx"], imu["wy"], imu["wz"]], axis=1).tolist() if measured else None
    rate_cov = _UNKNOWN if measured else _NOT_PROVIDED
    topic = "/imu" if name == "IMU" else f"/imu/{name}"
    emit(topic, IMU, lambda i, h: {
        "header": {**h, "frame_id": name},
        "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 0.0},
        "orientation_covariance": _NOT_PROVIDED,
        "angular_velocity": _vector(*rate[i]) if rate is not None else _vector(0.0, 0.0, 0.0),
        "angular_velocity_covariance": rate_cov,
        "linear_acceleration": _vector(*acc[i]),
        "linear_acceleration_covariance": _UNKNOWN})


def _emit_player(emit, records: np.ndarray, instance: str) -> None:
    """``/player``: one DiagnosticStatus per tick with the player's flags as the daemon
    logged them (level WARN while the watchdog holds a stale reference)."""
    playing = records["playing"].astype(bool).tolist()
    watchdog = records["watchdog"].astype(bool).tolist()
    age_ms = records["ref_age_ms"].astype(np.float64).tolist()

    def build(i: int, h: dict) -> dict:
        if watchdog[i]:
            level, text = _DIAG_WARN, "watchdog: stale reference, holding"
        else:
            level, text = _DIAG_OK, "playing" if playing[i] else "not playing"
        values = [{"key": "playing", "value": str(int(playing[i]))},
                  {"key": "watchdog", "value": str(int(watchdog[i]))},
                  {"key": "ref_age_ms", "value": f"{age_ms[i]:.3f}"}]
        return {"header": h, "status": [{"level": level, "name": "hubo-daemon: player",
                                         "message": text, "hardware_id": instance,
                                         "values": values}]}

    emit("/player", DIAGNOSTIC_ARRAY, build)


def export_mcap(log_path: str | os.PathLike, out_path: str | os.PathLike,
                rate_hz: float | None = None) -> ExportResult:
    """Export the state log ``log_path`` to the MCAP file ``out_path`` (topics: module doc).

    Everything is checked before a byte is written; the file is written under a temporary
    name in the same folder and renamed when complete, so a failed export leaves nothing.

    Args:
        log_path: a `daemon.state_log` file (daemon or ``hubo-read --log`` records).
        out_path: the ``.mcap`` file to write (replaced if it exists).
        rate_hz: keep one record per 1/rate_hz s [Hz], in (0, 200]; None: every record.

    Raises:
        InputError: bad log, output name or rate.
        HuboLadderError: the mcap packages are not installed.
    """
    require_mcap()
    check_rate(rate_hz)
    out = check_output(out_path, log_path)
    records, meta = load_log(log_path)
    records = records[decimate(records["time_s"], rate_hz)]
    stamps_ns = np.round(records["time_s"] * 1e9).astype(np.int64)

    from mcap_ros2.writer import Writer

    fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".part", dir=out.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            writer = Writer(f)
            writer.add_metadata("hubo_state_log", {
                "log": Path(log_path).name, "rate_hz": "all" if rate_hz is None else
                f"{rate_hz:g}", **{str(k): str(v) for k, v in meta.items()}})
            counts = _write_all(writer, records, meta, stamps_ns)
            writer.finish()
        os.replace(tmp, out)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    duration_s = float(records["time_s"][-1] - records["time_s"][0])
    log.info("exported %d records (%.3f s) to %s", len(records), duration_s, out)
    return ExportResult(out, len(records), duration_s, counts, out.stat().st_size)


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``hubo-log-mcap``; returns the exit code."""
    p = argparse.ArgumentParser(prog="hubo-log-mcap", description=__doc__.split("\n\n")[0])
    p.add_argument("log", metavar="LOG", help="state log (hubo-daemon --log, hubo-read --log)")
    p.add_argument("-o", "--output", required=True, metavar="OUT.mcap", help="MCAP file")
    p.add_argument("--rate", type=float, metavar="HZ",
                   help="keep one record per 1/HZ s (default: every record)")
    args = p.parse_args(argv)

    def job() -> int:
        start = time.perf_counter()
        result = export_mcap(args.log, args.output, args.rate)
        print(result.summary())
        print(f"  in {time.perf_counter() - start:.2f} s")
        return 0

    return run_cli("hubo-log-mcap", job)


if __name__ == "__main__":
    sys.exit(main())
