"""The 40-column trajectory file that hubo-read-trajectory played (hubo-facts §1).

One line per setpoint, whitespace-separated radians in ``JOINT_NAMES`` order, no header;
line k is played at time k / rate. The original player read lines with a 1000-byte
``fgets`` and an unchecked ``sscanf``; we check the whole file before anything moves and
report every problem as ``file:line:column: message``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from robot.errors import TrajectoryFileError
from robot.joints import JOINT_NAMES, NUM_JOINTS
from robot.limits import joint_limits

#: fgets(buf, 1000) reads at most 999 bytes including the newline: a longer line was
#: split in two and silently misread by the original player.
MAX_LINE_CHARS = 998
#: Tolerance on the joint limits for values written by a float formatter [rad].
LIMIT_TOLERANCE_RAD = 1e-9


def format_trajectory(q_rad: np.ndarray) -> str:
    """Text of a trajectory: one line per row, shortest exact float repr, '\\n' endings."""
    q_rad = np.asarray(q_rad, dtype=float)
    if q_rad.ndim != 2 or q_rad.shape[1] != NUM_JOINTS:
        raise ValueError(f"expected an (N, {NUM_JOINTS}) array, got shape {q_rad.shape}")
    if not np.all(np.isfinite(q_rad)):
        raise ValueError("trajectory contains NaN or inf")
    lines = []
    for row in q_rad:
        line = " ".join(repr(float(v)) for v in row)
        assert len(line) <= MAX_LINE_CHARS, "a formatted line cannot exceed the reader's buffer"
        lines.append(line)
    return "\n".join(lines) + "\n"


def write_trajectory(path: str | os.PathLike, q_rad: np.ndarray) -> None:
    """Write ``q_rad`` (N, 40) so that hubo-read-trajectory and ``read_trajectory`` read it
    back bit for bit. Written to a temporary file and renamed, so a crash leaves no half file.
    """
    path = Path(path)
    text = format_trajectory(q_rad)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def _token_columns(line: str) -> list[tuple[int, str]]:
    """(1-based character column, token) for each whitespace-separated token."""
    out, i, n = [], 0, len(line)
    while i < n:
        while i < n and line[i].isspace():
            i += 1
        if i >= n:
            break
        j = i
        while j < n and not line[j].isspace():
            j += 1
        out.append((i + 1, line[i:j]))
        i = j
    return out


def parse_trajectory(text: str, source: str, rate_hz: float, robot: str = "drc-hubo",
                     check_speed: bool = True) -> np.ndarray:
    """Parse and validate trajectory text; returns an (N, 40) array [rad].

    Args:
        text: the file contents.
        source: the file name used in messages.
        rate_hz: playback rate, for the speed check (line k plays at k / rate_hz).
        robot: robot whose joint limits and speed limits apply.
        check_speed: also refuse steps faster than each joint's maximum speed.

    Raises:
        TrajectoryFileError: with every problem found, as ``source:line:column: message``.
    """
    limits = joint_limits(robot)
    problems: list[str] = []
    rows: list[np.ndarray] = []
    row_lines: list[int] = []
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()  # the final newline ends the last line; it is not an empty line
    if not lines:
        raise TrajectoryFileError(source, [f"{source}:1:1: the file has no trajectory lines"])
    for lineno, raw in enumerate(lines, start=1):
        line = raw.rstrip("\r")
        where = f"{source}:{lineno}"
        if len(line) > MAX_LINE_CHARS:
            problems.append(f"{where}:{MAX_LINE_CHARS + 1}: line is {len(line)} characters; "
                            f"hubo-read-trajectory reads at most {MAX_LINE_CHARS} per line")
            continue
        tokens = _token_columns(line)
        if not tokens:
            problems.append(f"{where}:1: empty line; every line must hold {NUM_JOINTS} values")
            continue
        values = np.empty(NUM_JOINTS)
        ok = True
        for k, (col, tok) in enumerate(tokens[:NUM_JOINTS]):
            try:
                v = float(tok)
            except ValueError:
                joint = JOINT_NAMES[k]
                hint = " (a header line of joint names is not allowed)" if tok in JOINT_NAMES \
                    else ""
                problems.append(f"{where}:{col}: column {k + 1} ({joint}): {tok!r} is not a "
                                f"number{hint}")
                ok = False
                break
            if not math.isfinite(v):
                problems.append(f"{where}:{col}: column {k + 1} ({JOINT_NAMES[k]}): {tok} is "
                                "not finite")
                ok = False
                continue
            lo, hi = limits.lower_rad[k], limits.upper_rad[k]
            if v < lo - LIMIT_TOLERANCE_RAD or v > hi + LIMIT_TOLERANCE_RAD:
                problems.append(f"{where}:{col}: column {k + 1} ({JOINT_NAMES[k]}): {v:.6g} rad "
                                f"is outside the joint limits [{lo:.4g}, {hi:.4g}] rad")
                ok = False
            values[k] = v
        if ok and len(tokens) != NUM_JOINTS:
            col = tokens[-1][0] if len(tokens) < NUM_JOINTS else tokens[NUM_JOINTS][0]
            problems.append(f"{where}:{col}: {len(tokens)} columns; expected {NUM_JOINTS}")
            ok = False
        if ok:
            rows.append(values)
            row_lines.append(lineno)
    if check_speed and len(rows) > 1 and not problems:
        q = np.vstack(rows)
        speed = np.abs(np.diff(q, axis=0)) * rate_hz
        bad = np.argwhere(speed > limits.velocity_max_rad_s + 1e-9)
        for r, k in bad[:50]:
            col = _token_columns(lines[row_lines[r + 1] - 1])[k][0]
            problems.append(
                f"{source}:{row_lines[r + 1]}:{col}: column {k + 1} ({JOINT_NAMES[k]}): step "
                f"of {q[r + 1, k] - q[r, k]:+.4g} rad from the previous line is "
                f"{speed[r, k]:.3g} rad/s at {rate_hz:g} Hz; the limit is "
                f"{limits.velocity_max_rad_s[k]:g} rad/s")
    if problems:
        raise TrajectoryFileError(source, problems)
    return np.vstack(rows)


def read_trajectory(path: str | os.PathLike, rate_hz: float, robot: str = "drc-hubo",
                    check_speed: bool = True) -> np.ndarray:
    """Read and validate a 40-column file; see ``parse_trajectory``."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise TrajectoryFileError(str(path), [f"{path}: cannot read: {exc.strerror}"]) from None
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise TrajectoryFileError(str(path), [f"{path}:{line}: non-ASCII byte"]) from None
    return parse_trajectory(text, str(path), rate_hz, robot, check_speed)
