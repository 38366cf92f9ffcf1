"""Joint and sensor tables (hubo-ach's ``joint.table`` and ``sensor.table``).

Both are whitespace-separated text, one row per joint or sensor, ``#`` starts a comment
line. They are parsed and validated once, at load; every problem is reported as
``FILE:LINE: column 'x': message`` in a `TableError` (an `InputError`: CLI exit code 2).

``joint.table`` columns:

| column | meaning |
|---|---|
| name | joint name of `robot.joints.JOINT_NAMES` |
| motNo | motor channel on its board, 0 … numMot−1 |
| refEnc | encoder count at the joint's zero [counts] |
| drive, driven | pulley teeth (drive / driven is the belt ratio) |
| harm | harmonic-drive ratio |
| enc | encoder counts per motor revolution |
| dir | +1 or −1: sign between encoder and joint angle |
| jmc | board number, 0 … 0x2F (its reference frame id is 0x10 + jmc) |
| active | 1 if the joint is driven |
| can | bus: 0 = ``can0``, 1 = ``can1`` |
| numMot | motors on the board, 1 … 8 |
| kp, kd, maxPWM | default PWM gains [%/rad], [%/(rad/s)], [%] |
| zeroed | 1 if the encoder needs no homing |

Encoder to joint angle (hubo-facts §3)::

    rad = dir · (enc − refEnc) · drive / driven / harm / enc_res · 2π

``sensor.table`` columns: ``name can active board x-sign y-sign z-sign``; the name says
the kind: FT (`daemon.structs.FT_NAMES`), IMU/tilt (`daemon.structs.IMU_NAMES`) or
``POWER``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from daemon.structs import FT_NAMES, IMU_NAMES
from robot.errors import InputError
from robot.joints import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS

TABLE_DIR = Path(__file__).with_name("tables")
JOINT_COLUMNS = (
    "name motNo refEnc drive driven harm enc dir jmc active can numMot kp kd maxPWM zeroed"
).split()
SENSOR_COLUMNS = "name can active board x-sign y-sign z-sign".split()
SENSOR_NAMES = FT_NAMES + IMU_NAMES + ("POWER",)
MAX_JMC = 0x2F  #: largest board number (reference frame id 0x10 + jmc stays below 0x40)
NUM_CAN = 2  #: buses: can0, can1
MAX_MOTORS = 8


class TableError(InputError):
    """A joint or sensor table failed validation; carries every problem found."""

    def __init__(self, problems: list[str]):
        self.problems = problems
        super().__init__("\n".join(problems))


@dataclass(frozen=True)
class JointParams:
    """One row of ``joint.table``; see the module docstring for the columns."""

    name: str
    mot_no: int
    ref_enc: int  # [counts]
    drive: float
    driven: float
    harm: float
    enc: float  # [counts / motor revolution]
    dir: int  # ±1
    jmc: int
    active: bool
    can: int
    num_mot: int
    kp: float  # [% duty / rad]
    kd: float  # [% duty / (rad/s)]
    max_pwm: float  # [%]
    zeroed: bool

    @property
    def index(self) -> int:
        """Column of this joint in the 40-column order."""
        return JOINT_INDEX[self.name]

    @property
    def rad_per_count(self) -> float:
        """Joint angle of one encoder count, sign included [rad/count]."""
        return self.dir * self.drive / self.driven / self.harm / self.enc * 2.0 * math.pi


@dataclass(frozen=True)
class SensorParams:
    """One row of ``sensor.table``."""

    name: str
    can: int
    active: bool
    board: int
    sign: tuple[int, int, int]  # x, y, z axis signs

    @property
    def kind(self) -> str:
        """``"ft"``, ``"imu"`` or ``"power"``."""
        if self.name in FT_NAMES:
            return "ft"
        return "imu" if self.name in IMU_NAMES else "power"


@dataclass(frozen=True)
class JointTable:
    """The 40 joints, in `robot.joints.JOINT_NAMES` order, with vectorised conversions."""

    joints: tuple[JointParams, ...]
    path: str = "<memory>"

    def __post_init__(self) -> None:
        scale = np.array([j.rad_per_count for j in self.joints])
        offset = np.array([j.ref_enc for j in self.joints], dtype=np.int64)
        object.__setattr__(self, "_scale", scale)
        object.__setattr__(self, "_offset", offset)

    def __getitem__(self, name: str) -> JointParams:
        return self.joints[JOINT_INDEX[name]]

    def __len__(self) -> int:
        return len(self.joints)

    def __repr__(self) -> str:
        return f"JointTable({self.path!r}, {len(self.joints)} joints, {len(self.boards())} boards)"

    @property
    def rad_per_count(self) -> np.ndarray:
        """Per joint [rad/count], sign included; shape (40,)."""
        return self._scale.copy()

    def enc_to_rad(self, counts: np.ndarray, index: np.ndarray | None = None) -> np.ndarray:
        """Encoder counts → joint angles [rad].

        Args:
            counts: counts of all 40 joints, or of the joints in ``index``.
            index: joint indices that ``counts`` belongs to; None for all, in order.
        """
        sl = slice(None) if index is None else index
        return (np.asarray(counts, dtype=np.int64) - self._offset[sl]) * self._scale[sl]

    def rad_to_enc(self, rad: np.ndarray, index: np.ndarray | None = None) -> np.ndarray:
        """Joint angles [rad] → encoder counts (rounded to the nearest count, int64)."""
        sl = slice(None) if index is None else index
        counts = np.rint(np.asarray(rad, dtype=float) / self._scale[sl]).astype(np.int64)
        return counts + self._offset[sl]

    def boards(self) -> dict[tuple[int, int], tuple[int, ...]]:
        """(can, jmc) → joint indices ordered by motor channel (missing channels: −1)."""
        out: dict[tuple[int, int], list[int]] = {}
        for j in self.joints:
            chans = out.setdefault((j.can, j.jmc), [-1] * j.num_mot)
            chans[j.mot_no] = j.index
        return {k: tuple(v) for k, v in sorted(out.items())}

    def default_gains(self) -> dict[str, np.ndarray]:
        """The table's PWM gains: ``kp``, ``kd``, ``max_pwm`` arrays, shape (40,)."""
        return {
            "kp": np.array([j.kp for j in self.joints]),
            "kd": np.array([j.kd for j in self.joints]),
            "max_pwm": np.array([j.max_pwm for j in self.joints]),
        }


@dataclass(frozen=True)
class SensorTable:
    """The rows of ``sensor.table``, by name."""

    sensors: tuple[SensorParams, ...]
    path: str = "<memory>"

    def __getitem__(self, name: str) -> SensorParams:
        for s in self.sensors:
            if s.name == name:
                return s
        raise KeyError(f"no sensor '{name}'; known: {[s.name for s in self.sensors]}")

    def of_kind(self, kind: str) -> tuple[SensorParams, ...]:
        """Sensors of one kind (``"ft"``, ``"imu"``, ``"power"``)."""
        return tuple(s for s in self.sensors if s.kind == kind)


# ---------------------------------------------------------------- parsing


class _Rows:
    """Split a table file into rows and collect problems with file:line context."""

    def __init__(self, path: str, text: str, columns: list[str]):
        self.path = path
        self.columns = columns
        self.problems: list[str] = []
        self.rows: list[tuple[int, list[str]]] = []
        for lineno, line in enumerate(text.splitlines(), start=1):
            stripped = line.strip()
            if not stripped or stripped.startswith("#"):
                continue
            tokens = stripped.split()
            if len(tokens) != len(columns):
                self.problems.append(
                    f"{path}:{lineno}: column '{columns[min(len(tokens), len(columns) - 1)]}': "
                    f"expected {len(columns)} columns ({' '.join(columns)}), got {len(tokens)}"
                )
                continue
            self.rows.append((lineno, tokens))

    def error(self, lineno: int, column: str, message: str) -> None:
        self.problems.append(f"{self.path}:{lineno}: column '{column}': {message}")

    def new_name(self, lineno: int, name: str, kind: str, valid: tuple, found: dict) -> bool:
        """True if ``name`` is valid and not seen yet (``found``: name → (line, …))."""
        if name not in valid:
            self.error(lineno, "name", f"unknown {kind} '{name}'; valid: {' '.join(valid)}")
            return False
        if name in found:
            first = found[name][0]
            self.error(lineno, "name", f"duplicate {kind} '{name}' (first on line {first})")
            return False
        return True

    def number(self, lineno: int, tokens: list[str], column: str, integer: bool = False):
        """The token of ``column`` as a number, or None (problem recorded)."""
        tok = tokens[self.columns.index(column)]
        try:
            value = int(tok, 0) if integer else float(tok)
        except ValueError:
            kind = "an integer" if integer else "a number"
            self.error(lineno, column, f"'{tok}' is not {kind}")
            return None
        if not integer and not math.isfinite(value):
            self.error(lineno, column, f"'{tok}' is not finite")
            return None
        return value

    def ranged(self, lineno, tokens, column, lo, hi, integer=True, allowed=None):
        value = self.number(lineno, tokens, column, integer)
        if value is None:
            return None
        if allowed is not None and value not in allowed:
            self.error(lineno, column, f"{value} not in {sorted(allowed)}")
            return None
        if allowed is None and not lo <= value <= hi:
            shown = (f"{hi:#x}" if column == "jmc" else hi) if hi is not None else hi
            self.error(lineno, column, f"{value} out of range [{lo}, {shown}]")
            return None
        return value


def parse_joint_table(text: str, path: str = "<string>") -> JointTable:
    """Parse and validate ``joint.table`` text (all 40 joints required).

    Raises:
        TableError: with every problem as ``FILE:LINE: column 'x': message``.
    """
    rows = _Rows(path, text, JOINT_COLUMNS)
    found: dict[str, tuple[int, JointParams]] = {}
    channels: dict[tuple[int, int, int], tuple[int, str]] = {}
    board_motors: dict[tuple[int, int], tuple[int, int]] = {}
    for lineno, tok in rows.rows:
        name = tok[0]
        if not rows.new_name(lineno, name, "joint", JOINT_NAMES, found):
            continue
        v = _joint_values(rows, lineno, tok)
        if v is None or not _claim_motor(rows, lineno, name, v, channels, board_motors):
            continue
        found[name] = (lineno, _joint_params(name, v))
    missing = [n for n in JOINT_NAMES if n not in found]
    if missing and not rows.problems:
        last = rows.rows[-1][0] if rows.rows else 0
        rows.error(last, "name", f"missing joints: {' '.join(missing)}")
    if rows.problems:
        raise TableError(rows.problems)
    assert len(found) == NUM_JOINTS
    return JointTable(tuple(found[n][1] for n in JOINT_NAMES), path)


def _joint_values(rows: _Rows, lineno: int, tok: list[str]) -> dict | None:
    """A joint row's columns, each checked against its range; None if any is bad (each
    problem is recorded in ``rows``)."""
    inf = math.inf
    v = {
        "motNo": rows.ranged(lineno, tok, "motNo", 0, MAX_MOTORS - 1),
        "refEnc": rows.ranged(lineno, tok, "refEnc", -(1 << 31), (1 << 31) - 1),
        "drive": rows.ranged(lineno, tok, "drive", 1e-9, inf, integer=False),
        "driven": rows.ranged(lineno, tok, "driven", 1e-9, inf, integer=False),
        "harm": rows.ranged(lineno, tok, "harm", 1e-9, inf, integer=False),
        "enc": rows.ranged(lineno, tok, "enc", 1, inf, integer=False),
        "dir": rows.ranged(lineno, tok, "dir", 0, 0, allowed={-1, 1}),
        "jmc": rows.ranged(lineno, tok, "jmc", 0, MAX_JMC),
        "active": rows.ranged(lineno, tok, "active", 0, 0, allowed={0, 1}),
        "can": rows.ranged(lineno, tok, "can", 0, NUM_CAN - 1),
        "numMot": rows.ranged(lineno, tok, "numMot", 1, MAX_MOTORS),
        "kp": rows.ranged(lineno, tok, "kp", 0, inf, integer=False),
        "kd": rows.ranged(lineno, tok, "kd", 0, inf, integer=False),
        "maxPWM": rows.ranged(lineno, tok, "maxPWM", 0, 100, integer=False),
        "zeroed": rows.ranged(lineno, tok, "zeroed", 0, 0, allowed={0, 1}),
    }
    return None if any(x is None for x in v.values()) else v


def _claim_motor(rows: _Rows, lineno: int, name: str, v: dict,
                 channels: dict[tuple[int, int, int], tuple[int, str]],
                 board_motors: dict[tuple[int, int], tuple[int, int]]) -> bool:
    """Whether the joint's board motor (can, jmc, motNo) exists, is not another joint's,
    and its board's motor count agrees with the board's earlier rows; if so, record it
    in ``channels`` and ``board_motors``."""
    if v["motNo"] >= v["numMot"]:
        rows.error(lineno, "motNo", f"{v['motNo']} but the board has numMot={v['numMot']}")
        return False
    board = (v["can"], v["jmc"])
    chan = board + (v["motNo"],)
    if chan in channels:
        first, other = channels[chan]
        rows.error(
            lineno,
            "motNo",
            f"can{board[0]} jmc {board[1]:#x} motor {v['motNo']} already used by "
            f"{other} (line {first})",
        )
        return False
    if board in board_motors and board_motors[board][1] != v["numMot"]:
        rows.error(
            lineno,
            "numMot",
            f"{v['numMot']} but line {board_motors[board][0]} gives this board "
            f"numMot={board_motors[board][1]}",
        )
        return False
    channels[chan] = (lineno, name)
    board_motors.setdefault(board, (lineno, v["numMot"]))
    return True


def _joint_params(name: str, v: dict) -> JointParams:
    """The checked columns of a joint row as its `JointParams`."""
    return JointParams(
        name=name, mot_no=v["motNo"], ref_enc=v["refEnc"], drive=v["drive"],
        driven=v["driven"], harm=v["harm"], enc=v["enc"], dir=v["dir"], jmc=v["jmc"],
        active=bool(v["active"]), can=v["can"], num_mot=v["numMot"], kp=v["kp"],
        kd=v["kd"], max_pwm=v["maxPWM"], zeroed=bool(v["zeroed"]))


def parse_sensor_table(text: str, path: str = "<string>") -> SensorTable:
    """Parse and validate ``sensor.table`` text.

    Raises:
        TableError: with every problem as ``FILE:LINE: column 'x': message``.
    """
    rows = _Rows(path, text, SENSOR_COLUMNS)
    found: dict[str, tuple[int, SensorParams]] = {}
    for lineno, tok in rows.rows:
        name = tok[0]
        if not rows.new_name(lineno, name, "sensor", SENSOR_NAMES, found):
            continue
        can = rows.ranged(lineno, tok, "can", 0, NUM_CAN - 1)
        active = rows.ranged(lineno, tok, "active", 0, 0, allowed={0, 1})
        board = rows.ranged(lineno, tok, "board", 0, 0x0F)
        signs = [rows.ranged(lineno, tok, c, 0, 0, allowed={-1, 1}) for c in SENSOR_COLUMNS[4:]]
        if None in (can, active, board) or None in signs:
            continue
        found[name] = (lineno, SensorParams(name, can, bool(active), board, tuple(signs)))
    if rows.problems:
        raise TableError(rows.problems)
    return SensorTable(tuple(p for _, p in found.values()), path)


def load_joint_table(path: str | Path | None = None, robot: str = "drc-hubo") -> JointTable:
    """Load ``joint.table`` from ``path``, or the shipped one of ``robot``.

    Raises:
        TableError: bad contents; InputError: the file cannot be read.
    """
    path = Path(path) if path is not None else TABLE_DIR / robot / "joint.table"
    return parse_joint_table(_read(path), str(path))


def load_sensor_table(path: str | Path | None = None, robot: str = "drc-hubo") -> SensorTable:
    """Load ``sensor.table`` from ``path``, or the shipped one of ``robot``."""
    path = Path(path) if path is not None else TABLE_DIR / robot / "sensor.table"
    return parse_sensor_table(_read(path), str(path))


def _read(path: Path) -> str:
    try:
        return path.read_text()
    except OSError as e:
        raise InputError(f"{path}: cannot read table: {e.strerror}") from e
