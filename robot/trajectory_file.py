"""The 40-column trajectory file that hubo-read-trajectory played (hubo-facts §1).

One line per setpoint, whitespace-separated radians in ``JOINT_NAMES`` order, no header;
line k is played at time k / rate. The original player read lines with a 1000-byte
``fgets`` and an unchecked ``sscanf``; we check the whole file before anything moves and
report every problem as ``file:line:column: message``.

A name ending in ``.gz`` (``climb.traj.gz``) is the same text gzip-compressed: every
reader and writer here handles it, so every command that takes a ``.traj`` takes a
``.traj.gz``. Values are written rounded to `DECIMALS` places (a microradian, ten times
finer than the encoders resolve): the full 17 digits of a float are noise that neither
the robot nor gzip can use. A DRC climb of 300,000 lines at 200 Hz is about 220 MB with
17 digits (gzip makes it 71 MB); rounded to 6 places and gzipped it is 25 MB (37 MB at 9).
"""

from __future__ import annotations

import gzip
import io
import math
import os
import re
import warnings
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from robot.errors import InputError, TrajectoryFileError
from robot.joints import JOINT_NAMES, NUM_JOINTS
from robot.limits import LIMIT_TOLERANCE_RAD, joint_limits

__all__ = [
    "LIMIT_TOLERANCE_RAD",
    "MAX_CLAMP_TOLERANCE_RAD",
    "MAX_LINE_CHARS",
    "ClampedJoint",
    "format_clamps",
    "format_trajectory",
    "is_gzip_path",
    "parse_trajectory",
    "read_trajectory",
    "read_trajectory_clamped",
    "write_trajectory",
]

#: fgets(buf, 1000) reads at most 999 bytes including the newline: a longer line was
#: split in two and silently misread by the original player.
MAX_LINE_CHARS = 998
#: The largest ``--clamp-limits`` tolerance [rad]: files of the original player overshoot
#: the knee's lower limit by up to 0.07 rad; a larger tolerance would hide real errors.
MAX_CLAMP_TOLERANCE_RAD = 0.1
#: Decimal places written [rad]: a microradian, ten times finer than the Hubo encoders
#: resolve (about 1e-5 rad); the rounding error (at most 5e-7 rad) stays within
#: ``LIMIT_TOLERANCE_RAD`` of a value on a limit.
DECIMALS = 6
#: gzip's level for ``.traj.gz``. On a whole DRC climb (300,000 lines, 92 MB of text):
#: level 6 (gzip's default) 24.7 MB in 5.8 s, level 5 24.9 MB in 3.1 s, level 4 26.3 MB
#: in 1.8 s (CPU seconds on the development VM, 2026-11-27).
GZIP_LEVEL = 5


def is_gzip_path(path: str | os.PathLike) -> bool:
    """True for a name ending in ``.gz`` (written compressed)."""
    return str(path).lower().endswith(".gz")


@dataclass(frozen=True)
class ClampedJoint:
    """What ``--clamp-limits`` changed on one joint of a file.

    Attributes:
        joint: the joint (column name).
        lines: the 1-based lines whose value was moved onto the limit.
        max_overshoot_rad: the largest distance beyond the limit [rad].
        worst_line: the line of that largest overshoot.
        worst_value_rad: the value found there [rad].
        limit_rad: the limit it was clamped to [rad].
    """

    joint: str
    lines: tuple[int, ...]
    max_overshoot_rad: float
    worst_line: int
    worst_value_rad: float
    limit_rad: float

    def __str__(self) -> str:
        side = "below its lower" if self.worst_value_rad < self.limit_rad else "above its upper"
        n = len(self.lines)
        return (f"{self.joint}: {n} line{'s' if n != 1 else ''} clamped ({_ranges(self.lines)}); "
                f"largest overshoot {self.max_overshoot_rad:.4g} rad at line "
                f"{self.worst_line} ({self.worst_value_rad:.6g} rad, {side} limit "
                f"{self.limit_rad:.4g} rad)")


def _ranges(lines: tuple[int, ...], most: int = 6) -> str:
    """``3-9, 40-44, 51`` for sorted line numbers; the first ``most`` runs."""
    runs: list[list[int]] = []
    for n in lines:
        if runs and n == runs[-1][1] + 1:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    shown = [f"{a}" if a == b else f"{a}-{b}" for a, b in runs[:most]]
    more = f", ... {len(runs) - most} more run(s)" if len(runs) > most else ""
    return ("line " if len(lines) == 1 else "lines ") + ", ".join(shown) + more


def format_clamps(source: str, clamps: tuple[ClampedJoint, ...], tol_rad: float) -> str:
    """The per-joint report of a clamped read, one line per joint."""
    head = (f"{source}: --clamp-limits {tol_rad:g} rad: {sum(len(c.lines) for c in clamps)} "
            f"value(s) on {len(clamps)} joint(s) moved onto their limit")
    return "\n".join([head] + [f"  {c}" for c in clamps])


def format_trajectory(q_rad: np.ndarray) -> str:
    """Text of a trajectory: one line per row, '\\n' endings, each value rounded to
    `DECIMALS` places and written in the shortest form that reads back as that value
    (so writing what was read gives the same text)."""
    q_rad = np.asarray(q_rad, dtype=float)
    if q_rad.ndim != 2 or q_rad.shape[1] != NUM_JOINTS:
        raise ValueError(f"expected an (N, {NUM_JOINTS}) array, got shape {q_rad.shape}")
    if not np.all(np.isfinite(q_rad)):
        raise ValueError("trajectory contains NaN or inf")
    # k / 10**9 is correctly rounded, so repr gives at most 9 decimals; + 0.0 drops "-0.0"
    q_rad = np.round(q_rad, DECIMALS) + 0.0
    lines = []
    for row in q_rad.tolist():
        line = " ".join(map(repr, row))
        assert len(line) <= MAX_LINE_CHARS, "a formatted line cannot exceed the reader's buffer"
        lines.append(line)
    return "\n".join(lines) + "\n"


def write_trajectory(path: str | os.PathLike, q_rad: np.ndarray) -> None:
    """Write ``q_rad`` (N, 40) so that hubo-read-trajectory and ``read_trajectory`` read it
    back to within half a microradian (`DECIMALS`), and what was read writes back bit for
    bit. Written to a temporary file and renamed, so a crash leaves no half file.
    A name ending in ``.gz`` is written gzip-compressed (no name or time in the header, so
    the same trajectory gives the same bytes); ``gunzip`` gives the plain file.
    """
    path = Path(path)
    data = format_trajectory(q_rad).encode("ascii")
    if is_gzip_path(path):
        data = gzip.compress(data, compresslevel=GZIP_LEVEL, mtime=0)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_bytes(data)
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
    return _parse(text, source, rate_hz, robot, check_speed, 0.0)[0]


def _check_clamp_tolerance(tol_rad: float) -> float:
    try:
        tol = float(tol_rad)
    except (TypeError, ValueError):
        tol = math.nan
    if not (math.isfinite(tol) and 0.0 <= tol <= MAX_CLAMP_TOLERANCE_RAD):
        raise InputError(f"--clamp-limits {tol_rad}: allowed 0 to {MAX_CLAMP_TOLERANCE_RAD:g} "
                         "rad")
    return tol


#: Any character but digits, signs, points, exponents, spaces, tabs and newlines.
_NOT_PLAIN = re.compile(r"[^0-9eE+\-. \t\n]")


def _parse_plain(text: str, limits, rate_hz: float, check_speed: bool) -> np.ndarray | None:
    """The whole file read by numpy at once, when it is plainly good: only numbers and
    blanks, 40 values on every line, none past a limit (nor a step past a speed limit,
    if checked). None otherwise: `_parse` then reads it line by line and names every
    problem. A DRC climb of 300,000 lines: 1.5 s instead of 9."""
    if _NOT_PLAIN.search(text) or max(map(len, text.split("\n"))) > MAX_LINE_CHARS:
        return None
    lines = text.count("\n") + (not text.endswith("\n"))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # numpy warns on a file with no data
            q = np.loadtxt(io.StringIO(text), comments=None, ndmin=2)
    except ValueError:
        return None
    tol = LIMIT_TOLERANCE_RAD
    if q.shape != (lines, NUM_JOINTS) or not np.isfinite(q).all() \
            or (q < limits.lower_rad - tol).any() or (q > limits.upper_rad + tol).any():
        return None
    if check_speed and len(q) > 1 and (np.abs(np.diff(q, axis=0)) * rate_hz
                                       > limits.velocity_max_rad_s + 1e-9).any():
        return None
    return q


def _parse(text: str, source: str, rate_hz: float, robot: str, check_speed: bool,
           clamp_tol_rad: float, check_limits: bool = True
           ) -> tuple[np.ndarray, tuple[ClampedJoint, ...]]:
    """`parse_trajectory`, clamping values within ``clamp_tol_rad`` beyond a limit, or
    reading them as they are if not ``check_limits`` (joint positions unbounded)."""
    limits = joint_limits(robot)
    if not check_limits:
        unbounded = np.full(NUM_JOINTS, np.inf)
        limits = replace(limits, lower_rad=-unbounded, upper_rad=unbounded)
    plain = _parse_plain(text, limits, rate_hz, check_speed)
    if plain is not None:  # nothing to report, nothing to clamp
        return plain, ()
    clamped: dict[int, list[tuple[int, float, float, float]]] = {}
    problems: list[str] = []
    rows: list[np.ndarray] = []
    row_lines: list[int] = []
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()  # the final newline ends the last line; it is not an empty line
    if not lines:
        raise TrajectoryFileError(source, [f"{source}:1:1: the file has no trajectory lines"])
    for lineno, raw in enumerate(lines, start=1):
        values = _parse_line(raw.rstrip("\r"), f"{source}:{lineno}", lineno, limits,
                             clamp_tol_rad, clamped, problems)
        if values is not None:
            rows.append(values)
            row_lines.append(lineno)
    if check_speed and len(rows) > 1 and not problems:
        problems += _speed_problems(np.vstack(rows), row_lines, lines, source, rate_hz, limits)
    if problems:
        raise TrajectoryFileError(source, problems)
    return np.vstack(rows), _clamp_report(clamped)


def _parse_line(line: str, where: str, lineno: int, limits, clamp_tol_rad: float,
                clamped: dict[int, list[tuple[int, float, float, float]]],
                problems: list[str]) -> np.ndarray | None:
    """One line's 40 values [rad], or None if it has a problem (appended to
    ``problems`` as ``FILE:LINE:COLUMN: ...``). A value within ``clamp_tol_rad`` beyond
    a limit is moved onto it and recorded in ``clamped`` per joint as (line, overshoot,
    value, limit)."""
    tol = max(LIMIT_TOLERANCE_RAD, clamp_tol_rad)
    if len(line) > MAX_LINE_CHARS:
        problems.append(f"{where}:{MAX_LINE_CHARS + 1}: line is {len(line)} characters; "
                        f"hubo-read-trajectory reads at most {MAX_LINE_CHARS} per line")
        return None
    tokens = _token_columns(line)
    if not tokens:
        problems.append(f"{where}:1: empty line; every line must hold {NUM_JOINTS} values")
        return None
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
            return None
        if not math.isfinite(v):
            problems.append(f"{where}:{col}: column {k + 1} ({JOINT_NAMES[k]}): {tok} is "
                            "not finite")
            ok = False
            continue
        lo, hi = limits.lower_rad[k], limits.upper_rad[k]
        if v < lo - tol or v > hi + tol:
            hint = "" if tol <= LIMIT_TOLERANCE_RAD else \
                f" by more than the --clamp-limits tolerance {clamp_tol_rad:g} rad"
            problems.append(f"{where}:{col}: column {k + 1} ({JOINT_NAMES[k]}): {v:.6g} rad "
                            f"is outside the joint limits [{lo:.4g}, {hi:.4g}] rad{hint}")
            ok = False
        elif clamp_tol_rad > 0.0 and (v < lo - LIMIT_TOLERANCE_RAD
                                      or v > hi + LIMIT_TOLERANCE_RAD):
            limit = lo if v < lo else hi
            clamped.setdefault(k, []).append((lineno, abs(v - limit), v, limit))
            v = limit
        values[k] = v
    if ok and len(tokens) != NUM_JOINTS:
        col = tokens[-1][0] if len(tokens) < NUM_JOINTS else tokens[NUM_JOINTS][0]
        problems.append(f"{where}:{col}: {len(tokens)} columns; expected {NUM_JOINTS}")
        ok = False
    return values if ok else None


def _speed_problems(q: np.ndarray, row_lines: list[int], lines: list[str], source: str,
                    rate_hz: float, limits) -> list[str]:
    """The first 50 steps between consecutive lines faster than a joint's velocity limit
    at ``rate_hz``, each named ``FILE:LINE:COLUMN``."""
    problems = []
    speed = np.abs(np.diff(q, axis=0)) * rate_hz
    bad = np.argwhere(speed > limits.velocity_max_rad_s + 1e-9)
    for r, k in bad[:50]:
        col = _token_columns(lines[row_lines[r + 1] - 1])[k][0]
        problems.append(
            f"{source}:{row_lines[r + 1]}:{col}: column {k + 1} ({JOINT_NAMES[k]}): step "
            f"of {q[r + 1, k] - q[r, k]:+.4g} rad from the previous line is "
            f"{speed[r, k]:.3g} rad/s at {rate_hz:g} Hz; the limit is "
            f"{limits.velocity_max_rad_s[k]:g} rad/s")
    return problems


def _clamp_report(clamped: dict[int, list[tuple[int, float, float, float]]]
                  ) -> tuple[ClampedJoint, ...]:
    """Per clamped joint, in column order: the lines it was clamped on and its worst
    overshoot."""
    report = []
    for k in sorted(clamped):
        entries = clamped[k]
        worst = max(entries, key=lambda e: e[1])
        report.append(ClampedJoint(JOINT_NAMES[k], tuple(e[0] for e in entries),
                                   float(worst[1]), worst[0], float(worst[2]),
                                   float(worst[3])))
    return tuple(report)


def read_trajectory(path: str | os.PathLike, rate_hz: float, robot: str = "drc-hubo",
                    check_speed: bool = True, check_limits: bool = True) -> np.ndarray:
    """Read and validate a 40-column file; see ``parse_trajectory``. Without
    ``check_limits``, values beyond a joint's limits are read as they are (check-plan
    reports them itself)."""
    return _parse(_read_text(path), str(path), rate_hz, robot, check_speed, 0.0,
                  check_limits)[0]


def read_trajectory_clamped(path: str | os.PathLike, rate_hz: float, clamp_tol_rad: float,
                            robot: str = "drc-hubo", check_speed: bool = True
                            ) -> tuple[np.ndarray, tuple[ClampedJoint, ...]]:
    """Read a 40-column file, moving values at most ``clamp_tol_rad`` beyond a joint limit
    onto that limit (``play-trajectory --clamp-limits``); farther ones are refused as by
    `read_trajectory`. The speed check runs on the clamped values.

    Args:
        path: the file.
        rate_hz: playback rate [Hz].
        clamp_tol_rad: the tolerance [rad], 0 to `MAX_CLAMP_TOLERANCE_RAD` (0: strict).
        robot: robot whose limits apply.
        check_speed: also refuse steps faster than each joint's maximum speed.

    Returns:
        The (N, 40) array [rad] and, per joint that was clamped, a `ClampedJoint`.

    Raises:
        InputError: a tolerance outside its range.
        TrajectoryFileError: every problem found, as ``file:line:column: message``.
    """
    tol = _check_clamp_tolerance(clamp_tol_rad)
    return _parse(_read_text(path), str(path), rate_hz, robot, check_speed, tol)


def _read_text(path: str | os.PathLike) -> str:
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise TrajectoryFileError(str(path), [f"{path}: cannot read: {exc.strerror}"]) from None
    if raw[:2] == b"\x1f\x8b":  # gzip's magic, whatever the name says
        try:
            raw = gzip.decompress(raw)
        except (OSError, EOFError) as exc:
            raise TrajectoryFileError(str(path), [f"{path}: not a readable gzip file: {exc}"]
                                      ) from None
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise TrajectoryFileError(str(path), [f"{path}:{line}: non-ASCII byte"]) from None
    return text
