"""The daemon's state log: one fixed-layout record per 5 ms tick, in a file the user names.

File layout (little-endian):

====================  =============================================================
bytes                 what
====================  =============================================================
8                     magic ``b"HUBOLOG1"``
4                     length L of the header text [bytes] (uint32)
L                     header text, a Python literal ``{"descr": …, "meta": {…}}`` (as .npy)
record_size × n       the records, back to back, ``dtype.itemsize`` bytes each
====================  =============================================================

A writer appends records through a buffered file and flushes about once a second, so a
daemon killed mid-run leaves a readable file; `read_state_log` drops a trailing partial
record. The record dtype is `LOG_DTYPE` for the daemon (every field of
`daemon.structs.STATE_DTYPE` plus what the loop decided that tick) and
`daemon.structs.STATE_DTYPE` for ``hubo-read --log``; the header says which.

Plots read it as a numpy structured array: ``log = read_state_log(path)``, then
``log["time_s"]``, ``log["pos"][:, JOINT_INDEX["LSP"]]``, ``log["comply"]``, …
"""

from __future__ import annotations

import ast
import os
import struct
from pathlib import Path

import numpy as np
from numpy.lib.format import descr_to_dtype, dtype_to_descr

from daemon.structs import STATE_DTYPE
from robot.errors import InputError
from robot.joints import NUM_JOINTS

__all__ = ["LOG_DTYPE", "StateLogError", "StateLogWriter", "read_state_log", "read_log_meta"]

MAGIC = b"HUBOLOG1"
_LEN = struct.Struct("<I")

#: One record of the daemon's log: the state struct plus the loop's decisions.
LOG_DTYPE = np.dtype(
    STATE_DTYPE.descr
    + [
        ("tick_start_ns", "<i8"),  # CLOCK_MONOTONIC when the tick started [ns]
        ("late_ns", "<i8"),  # tick start minus its deadline [ns]
        ("ref_cmd", "<f8", (NUM_JOINTS,)),  # reference commanded on the ref channel [rad]
        ("mode_cmd", "u1", (NUM_JOINTS,)),  # RefMode used this tick
        ("comply_cmd", "u1", (NUM_JOINTS,)),  # compliance asked for this tick
        ("gated", "u1", (NUM_JOINTS,)),  # 1: references ignored (not homed, homing, off)
        ("watchdog", "u1"),  # 1: stale reference while playing, holding
        ("playing", "u1"),  # the ref sample's playing flag
        ("ref_age_ms", "<f4"),  # age of the newest ref sample [ms]; −1 none
        ("cmds_done", "<u4"),  # board commands carried out since start
        ("cmds_refused", "<u4"),  # board commands / gain sets refused since start
        ("gains_version", "<u4"),  # accepted gain changes since start
        ("latched", "u1", (2,)),  # sim only: grasp latch of the left, right hand
    ]
)


class StateLogError(InputError):
    """A state log cannot be read (not a log, truncated header)."""


class StateLogWriter:
    """Appends records to a state log file.

    Args:
        path: the file; created or truncated.
        dtype: record dtype (`LOG_DTYPE` for the daemon).
        meta: free-form JSON-able facts for the header (backend, instance, rate…).
        flush_every: records between flushes (200: about once a second at 200 Hz).
    """

    def __init__(self, path: str | os.PathLike, dtype: np.dtype = LOG_DTYPE,
                 meta: dict | None = None, flush_every: int = 200):
        self.path = Path(path)
        self.dtype = np.dtype(dtype)
        header = repr({"descr": dtype_to_descr(self.dtype), "meta": dict(meta or {})}).encode()
        self._f = open(self.path, "wb", buffering=1 << 16)  # noqa: SIM115 - closed in close()
        self._f.write(MAGIC + _LEN.pack(len(header)) + header)
        self._flush_every = max(int(flush_every), 1)
        self._pending = 0
        self.records = 0

    def append(self, record: np.ndarray) -> None:
        """Append one record (a 0-d array of the log's dtype)."""
        if record.dtype != self.dtype:
            record = np.asarray(record, dtype=self.dtype)
        self._f.write(record.tobytes())
        self.records += 1
        self._pending += 1
        if self._pending >= self._flush_every:
            self._f.flush()
            self._pending = 0

    def close(self) -> None:
        """Flush and close; idempotent."""
        if not self._f.closed:
            self._f.flush()
            self._f.close()

    def __enter__(self) -> StateLogWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _read_header(f, path: Path) -> tuple[np.dtype, dict, int]:
    head = f.read(len(MAGIC) + _LEN.size)
    if len(head) < len(MAGIC) + _LEN.size or head[: len(MAGIC)] != MAGIC:
        raise StateLogError(f"{path}: not a hubo-ladder state log (bad magic)")
    (n,) = _LEN.unpack(head[len(MAGIC):])
    text = f.read(n)
    if len(text) != n:
        raise StateLogError(f"{path}: truncated header")
    try:
        header = ast.literal_eval(text.decode())
        dtype = descr_to_dtype(header["descr"])
    except (ValueError, KeyError, TypeError, SyntaxError, UnicodeDecodeError) as exc:
        raise StateLogError(f"{path}: unreadable header: {exc}") from None
    return dtype, header.get("meta", {}), len(head) + n


def read_log_meta(path: str | os.PathLike) -> dict:
    """The ``meta`` dict of a log's header."""
    path = Path(path)
    with open(path, "rb") as f:
        return _read_header(f, path)[1]


def read_state_log(path: str | os.PathLike) -> np.ndarray:
    """All complete records of a state log, as a 1-d structured array.

    Raises:
        StateLogError: not a state log.
    """
    path = Path(path)
    try:
        f = open(path, "rb")  # noqa: SIM115
    except OSError as exc:
        raise StateLogError(f"{path}: cannot read: {exc.strerror}") from None
    with f:
        dtype, _, offset = _read_header(f, path)
        size = path.stat().st_size - offset
    count = max(size, 0) // dtype.itemsize
    return np.fromfile(path, dtype=dtype, count=count, offset=offset)
