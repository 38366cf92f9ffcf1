"""The ``*.plan.json`` sidecar of a trajectory: which limbs hold what on every line.

Written by ``plan-ladder``, read by ``validate-plan``, ``play-trajectory`` and
``check-plan``. Line numbers are 1-based and inclusive, like the trajectory file's.

`read_sidecar` checks every field once, at the edge, and names the field of any problem
(``segments[3].first_line: expected an integer ≥ 1, got 'x'``). The ladder spec inside
is kept as the mapping of its file layout; ``ladders.loader.sidecar_ladder`` parses it
with the spec's own rules (this package may not import ``ladders``).

Versions: 2 is this layout. Version 1 grew fields without changing its number, so a
version-1 file is refused with a message that says to plan again.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robot.errors import InputError
from robot.joints import ARM_JOINTS, JOINT_NAMES
from robot.vocabulary import (
    ARM_MODES,
    LIMBS,
    HoldTarget,
    HoldTargetError,
    HoldTargetKind,
    Limb,
    SegmentPhase,
    Side,
)

FORMAT = "hubo-ladder-plan"
VERSION = 2


class SidecarError(InputError):
    """A plan sidecar is malformed."""


@dataclass(frozen=True)
class HoldRecord:
    """One hold in contact: what it holds and where the limb frame must be [m]."""

    target: str  # "floor", "rung_3", "rail_left", ... (`hold_target` parses it)
    position_m: tuple[float, float, float]

    @property
    def hold_target(self) -> HoldTarget:
        return HoldTarget.parse(self.target)


@dataclass(frozen=True)
class Segment:
    """A stretch of lines produced by one primitive (or one phase of it).

    Attributes:
        primitive: thesis primitive name (``moveLHand`` ...), or ``dwell``.
        phase: ``body`` (every hold kept), ``limb`` (moving limbs in the air),
            ``grasp``/``release`` (fingers closing/opening) or ``dwell``.
        rung: rung the feet stand on or step to.
        first_line, last_line: 1-based inclusive lines.
        holds: limb → hold kept in contact during the segment.
        moving_limbs: limbs in the air.
    """

    primitive: str
    phase: str
    rung: int
    first_line: int
    last_line: int
    holds: dict[str, HoldRecord]
    moving_limbs: tuple[str, ...] = ()


def feedforward_rows(line_count: int, every_lines: int) -> int:
    """Rows of an `ArmFeedforward` sampled every ``every_lines`` that cover lines
    1..line_count: the last row is at or past the last line."""
    return (line_count - 2) // every_lines + 2 if line_count > 1 else 1


def hand_holding_lines(segments: Sequence[Segment], line_count: int, arm: str) -> np.ndarray:
    """Lines on which the ``arm`` ("left"/"right") hand holds a rail, bool (line_count,)."""
    held = np.zeros(line_count, dtype=bool)
    for seg in segments:
        hold = seg.holds.get(Limb.hand(arm))
        if hold is not None and hold.hold_target.kind is HoldTargetKind.RAIL:
            held[seg.first_line - 1:seg.last_line] = True
    return held


@dataclass(frozen=True, eq=False)
class ArmFeedforward:
    """Joint torques the compliant arms must give so that the robot carries its load the
    way the plan's torque LP shares it between hands and feet.

    A PWM arm that tracks its reference gives almost no torque (its duty is kp times a
    small error), so the position-controlled legs would take the whole load; the player
    sends these torques as the arm's feed-forward duty (hubo-ach's ``pwm_command``).

    Attributes:
        every_lines: sample spacing [lines]; row k belongs to line ``1 + k·every_lines``
            and the player interpolates linearly between rows.
        joints: the arm joints of the columns (names of `robot.joints.ARM_JOINTS`).
        torque_nm: (rows, len(joints)) joint torques [N·m]; an arm whose hand holds
            nothing has its own gravity torques.
    """

    every_lines: int
    joints: tuple[str, ...]
    torque_nm: np.ndarray

    def rows_for(self, line_count: int) -> int:
        """Rows that cover lines 1..line_count (`feedforward_rows`)."""
        return feedforward_rows(line_count, self.every_lines)

    def to_json(self) -> dict[str, Any]:
        return {"every_lines": self.every_lines, "joints": list(self.joints),
                "torque_nm": [[round(float(v), 3) for v in row] for row in self.torque_nm]}


@dataclass(frozen=True)
class PlanSidecar:
    robot: str
    ladder: dict[str, Any]  # the full ladder spec, as in its YAML file
    rate_hz: float
    line_count: int
    segments: tuple[Segment, ...]
    arm_modes: dict[str, list[tuple[int, int, str]]]  # "left"/"right" → runs
    final_holds: dict[str, HoldRecord]
    seed: int = 0
    metrics: dict[str, Any] = field(default_factory=dict)
    timings_s: dict[str, float] = field(default_factory=dict)
    planner_version: str = ""
    joint_order: tuple[str, ...] = JOINT_NAMES
    arm_feedforward: ArmFeedforward | None = None

    def segment_at(self, line: int) -> Segment:
        for seg in self.segments:
            if seg.first_line <= line <= seg.last_line:
                return seg
        raise KeyError(line)

    def to_json(self) -> dict[str, Any]:
        d = asdict(self)
        d = {"format": FORMAT, "version": VERSION, **d}
        d["joint_order"] = list(self.joint_order)
        if self.arm_feedforward is None:
            del d["arm_feedforward"]
        else:
            d["arm_feedforward"] = self.arm_feedforward.to_json()
        return d


def sidecar_path(traj_path: str | os.PathLike) -> Path:
    """``climb.traj`` and ``climb.traj.gz`` → ``climb.plan.json``."""
    p = Path(traj_path)
    for suffix in (".traj", ".traj.gz"):
        if p.name.endswith(suffix) and len(p.name) > len(suffix):
            return p.with_name(p.name.removesuffix(suffix) + ".plan.json")
    return p.with_name(p.name + ".plan.json")


def segment_of_lines(sidecar: PlanSidecar, where: str) -> np.ndarray:
    """The index of the segment each line (0-based) belongs to, shape (line_count,).

    Raises:
        InputError: a line no segment covers; ``where`` names the file.
    """
    index = np.full(sidecar.line_count, -1)
    for k, seg in enumerate(sidecar.segments):
        index[seg.first_line - 1:seg.last_line] = k
    missing = np.flatnonzero(index < 0)
    if len(missing):
        raise InputError(f"{where}: field 'segments' does not cover line {missing[0] + 1}")
    return index


def check_line_count(traj_path: str | os.PathLike, lines: int, sidecar: PlanSidecar) -> None:
    """Refuse a trajectory of ``lines`` lines whose sidecar counts another number.

    Raises:
        InputError: naming the file, its line count and the sidecar's.
    """
    if lines != sidecar.line_count:
        raise InputError(f"{traj_path}:{lines}: the file has {lines} lines, its sidecar "
                         f"{sidecar_path(traj_path)} says {sidecar.line_count}")


def write_sidecar(path: str | os.PathLike, sidecar: PlanSidecar) -> None:
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(sidecar.to_json(), indent=1))
    tmp.replace(path)


def _need(d: dict, key: str, where: str) -> Any:
    if key not in d:
        raise SidecarError(f"{where}: missing field '{key}'")
    return d[key]


def _int(value: Any, where: str, minimum: int | None = None) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or \
            (minimum is not None and value < minimum):
        at_least = "" if minimum is None else f" ≥ {minimum}"
        raise SidecarError(f"{where}: expected an integer{at_least}, got {value!r}")
    return value


def _number(value: Any, where: str, positive: bool = False) -> float:
    ok = isinstance(value, int | float) and not isinstance(value, bool) and \
        np.isfinite(value) and (value > 0 or not positive)
    if not ok:
        raise SidecarError(f"{where}: expected a {'positive' if positive else 'finite'} "
                           f"number, got {value!r}")
    return float(value)


def _text(value: Any, where: str) -> str:
    if not isinstance(value, str):
        raise SidecarError(f"{where}: expected a string, got {value!r}")
    return value


def _mapping(value: Any, where: str) -> dict:
    if not isinstance(value, dict):
        raise SidecarError(f"{where}: expected a mapping, got {value!r}")
    return value


def _list(value: Any, where: str) -> list:
    if not isinstance(value, list):
        raise SidecarError(f"{where}: expected a list, got {value!r}")
    return value


def _hold(d: Any, where: str) -> HoldRecord:
    if not isinstance(d, dict) or set(d) != {"target", "position_m"}:
        raise SidecarError(f"{where}: a hold needs exactly 'target' and 'position_m'")
    target = _text(d["target"], f"{where}.target")
    try:
        HoldTarget.parse(target)
    except HoldTargetError as exc:
        raise SidecarError(f"{where}.target: {exc}") from None
    pos = d["position_m"]
    if not (isinstance(pos, list) and len(pos) == 3 and all(isinstance(v, int | float)
                                                           for v in pos)):
        raise SidecarError(f"{where}.position_m: expected 3 numbers [m], got {pos!r}")
    return HoldRecord(target, tuple(float(v) for v in pos))


def _holds(d: Any, where: str) -> dict[str, HoldRecord]:
    if not isinstance(d, dict):
        raise SidecarError(f"{where}: expected a mapping limb → hold")
    for limb in d:
        if limb not in LIMBS:
            raise SidecarError(f"{where}: unknown limb {limb!r}; limbs are {', '.join(LIMBS)}")
    return {limb: _hold(h, f"{where}.{limb}") for limb, h in d.items()}


def _segment(s: Any, where: str, line_count: int) -> Segment:
    s = _mapping(s, where)
    first = _int(_need(s, "first_line", where), f"{where}.first_line", 1)
    last = _int(_need(s, "last_line", where), f"{where}.last_line", 1)
    if not first <= last <= line_count:
        raise SidecarError(f"{where}: lines {first}..{last} are outside 1..{line_count}")
    phase = _text(_need(s, "phase", where), f"{where}.phase")
    if phase not in tuple(SegmentPhase):
        raise SidecarError(f"{where}.phase: expected one of "
                           f"{', '.join(SegmentPhase)}, got {phase!r}")
    moving = _list(s.get("moving_limbs", []), f"{where}.moving_limbs")
    for i, limb in enumerate(moving):
        if limb not in LIMBS:
            raise SidecarError(f"{where}.moving_limbs[{i}]: unknown limb {limb!r}; limbs "
                               f"are {', '.join(LIMBS)}")
    return Segment(_text(_need(s, "primitive", where), f"{where}.primitive"), phase,
                   _int(_need(s, "rung", where), f"{where}.rung"), first, last,
                   _holds(_need(s, "holds", where), f"{where}.holds"), tuple(moving))


def _runs(runs: Any, where: str, line_count: int) -> list[tuple[int, int, str]]:
    if not isinstance(runs, list) or not runs:
        raise SidecarError(f"{where}: expected a non-empty list of [first, last, mode] runs")
    out, expect = [], 1
    for i, run in enumerate(runs):
        ok = isinstance(run, list) and len(run) == 3 and isinstance(run[0], int) and \
            isinstance(run[1], int) and run[2] in ARM_MODES
        if not ok:
            raise SidecarError(f"{where}[{i}]: expected [first_line, last_line, "
                               f"'position'|'pwm'], got {run!r}")
        if run[0] != expect or run[1] < run[0]:
            raise SidecarError(f"{where}[{i}]: runs must cover lines 1..{line_count} in "
                               f"order without gaps; expected a run starting at {expect}")
        out.append((run[0], run[1], run[2]))
        expect = run[1] + 1
    if expect != line_count + 1:
        raise SidecarError(f"{where}: runs end at line {expect - 1}, the file has {line_count}")
    return out


def _feedforward(d: Any, where: str, line_count: int) -> ArmFeedforward | None:
    if d is None:
        return None
    if not isinstance(d, dict) or set(d) != {"every_lines", "joints", "torque_nm"}:
        raise SidecarError(f"{where}: expected 'every_lines', 'joints' and 'torque_nm'")
    every, joints = d["every_lines"], d["joints"]
    if not isinstance(every, int) or isinstance(every, bool) or every < 1:
        raise SidecarError(f"{where}.every_lines: expected an integer >= 1, got {every!r}")
    arm = {n for side in ARM_JOINTS.values() for n in side}
    if not isinstance(joints, list) or not joints or any(j not in arm for j in joints) \
            or len(set(joints)) != len(joints):
        raise SidecarError(f"{where}.joints: expected distinct arm joint names "
                           f"({' '.join(sorted(arm))}), got {joints!r}")
    rows = feedforward_rows(line_count, every)
    try:
        torque = np.array(d["torque_nm"], dtype=float)
    except (TypeError, ValueError):
        torque = None
    if torque is None or torque.shape != (rows, len(joints)) or not np.isfinite(torque).all():
        raise SidecarError(f"{where}.torque_nm: expected {rows} rows of {len(joints)} finite "
                           f"torques [N·m] (lines 1..{line_count} every {every})")
    torque.setflags(write=False)
    return ArmFeedforward(every, tuple(joints), torque)


def _json_document(path: Path) -> Any:
    """The file's JSON value; a byte that is not UTF-8 or a syntax error is reported at
    its line and column."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise SidecarError(f"{path}: cannot read: {exc.strerror}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise SidecarError(f"{path}:{line}:{column}: byte 0x{raw[exc.start]:02x} is not "
                           f"UTF-8 text") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise SidecarError(f"{path}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}") from None


def read_sidecar(path: str | os.PathLike) -> PlanSidecar:
    """Read and validate a sidecar. Raises `SidecarError` naming the file and the field
    (``FILE: segments[2].holds.left_hand.target: ...``)."""
    path = Path(path)
    d = _json_document(path)
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise SidecarError(f"{path}: not a {FORMAT} file (field 'format')")
    version = d.get("version")
    if version == 1:
        raise SidecarError(f"{path}: field 'version' is 1, a layout that changed without "
                           f"its number; this reader reads version {VERSION}: plan again "
                           f"with plan-ladder")
    if version != VERSION:
        raise SidecarError(f"{path}: field 'version' is {version!r}; this reader "
                           f"reads version {VERSION}")
    where = f"{path}:"
    n = _int(_need(d, "line_count", where), f"{where} line_count", 1)
    if _list(_need(d, "joint_order", where), f"{where} joint_order") != list(JOINT_NAMES):
        raise SidecarError(f"{path}: field 'joint_order' is not the 40-column order")
    segments = tuple(_segment(s, f"{where} segments[{i}]", n)
                     for i, s in enumerate(_list(_need(d, "segments", where),
                                                 f"{where} segments")))
    arm_modes = _mapping(_need(d, "arm_modes", where), f"{where} arm_modes")
    return PlanSidecar(
        robot=_text(_need(d, "robot", where), f"{where} robot"),
        ladder=_mapping(_need(d, "ladder", where), f"{where} ladder"),
        rate_hz=_number(_need(d, "rate_hz", where), f"{where} rate_hz", positive=True),
        line_count=n, segments=segments,
        arm_modes={arm: _runs(arm_modes.get(arm), f"{where} arm_modes.{arm}", n)
                   for arm in map(str, Side)},
        final_holds=_holds(_need(d, "final_holds", where), f"{where} final_holds"),
        seed=_int(d.get("seed", 0), f"{where} seed"),
        metrics=_mapping(d.get("metrics", {}), f"{where} metrics"),
        timings_s=_mapping(d.get("timings_s", {}), f"{where} timings_s"),
        planner_version=_text(d.get("planner_version", ""), f"{where} planner_version"),
        arm_feedforward=_feedforward(d.get("arm_feedforward"), f"{where} arm_feedforward", n))
