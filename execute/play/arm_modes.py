"""The arms' position/PWM mode on every line of a trajectory.

A sidecar gives each arm's modes as run-length runs ``(first_line, last_line, mode)``
(`robot.plan_sidecar`); `ArmModeSchedule` checks that they cover the file exactly once
and expands them into one flag per line, which the player (`execute.play.player`) reads
each tick. ``-c``/``-cl``/``-cr`` override an arm's schedule in the player.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from robot.errors import InputError
from robot.vocabulary import ARM_MODES, SIDES

__all__ = ["ArmModeSchedule", "ModeScheduleError"]

ARMS = SIDES


class ModeScheduleError(InputError):
    """A per-arm mode schedule is malformed: names the arm, the run and the problem."""



@dataclass(frozen=True, eq=False)
class ArmModeSchedule:
    """Per-arm PWM/position mode of every line of a trajectory.

    Attributes:
        pwm_by_line: arm → bool array (num_lines,), True where the arm is in PWM mode.
    """

    pwm_by_line: Mapping[str, np.ndarray]

    @property
    def num_lines(self) -> int:
        """Number of trajectory lines covered."""
        return len(next(iter(self.pwm_by_line.values())))

    @classmethod
    def all_position(cls, num_lines: int) -> ArmModeSchedule:
        """Both arms in position mode on every line."""
        return cls.from_runs({}, num_lines)

    @classmethod
    def from_runs(
        cls,
        runs: Mapping[str, Sequence[tuple[int, int, str]]],
        num_lines: int,
    ) -> ArmModeSchedule:
        """Builds the schedule from the sidecar's run-length lists.

        Args:
            runs: ``{"left": [(1, 120, "position"), (121, 400, "pwm"), ...], "right": ...}``;
                1-based inclusive line numbers, in order, covering 1..num_lines exactly once.
                An arm that is absent is in position mode throughout.
            num_lines: lines in the trajectory.

        Raises:
            ModeScheduleError: unknown arm or mode, a malformed run, a gap, an overlap, or
                a run outside 1..num_lines; every problem is listed.
        """
        problems: list[str] = []
        unknown = sorted(set(runs) - set(ARMS))
        if unknown:
            problems.append(f"unknown arm(s) {unknown}; allowed: {', '.join(ARMS)}")
        table = {}
        for arm in ARMS:
            pwm = np.zeros(num_lines, dtype=bool)
            if arm in runs:
                problems += _fill_runs(arm, runs[arm], num_lines, pwm)
            pwm.setflags(write=False)
            table[arm] = pwm
        if problems:
            raise ModeScheduleError("mode schedule: " + "\n".join(problems))
        return cls(MappingProxyType(table))

    def to_runs(self) -> dict[str, list[tuple[int, int, str]]]:
        """The run-length form again (1-based inclusive lines), e.g. for a sidecar."""
        out = {}
        for arm, pwm in self.pwm_by_line.items():
            edges = np.flatnonzero(np.diff(pwm.astype(np.int8))) + 1
            starts = np.concatenate([[0], edges])
            ends = np.concatenate([edges, [len(pwm)]])
            out[arm] = [
                (int(a) + 1, int(b), ARM_MODES[int(pwm[a])])
                for a, b in zip(starts, ends, strict=True)
            ]
        return out


def _fill_runs(
    arm: str, runs: Iterable[tuple[int, int, str]], num_lines: int, pwm: np.ndarray
) -> list[str]:
    """Set ``pwm`` from one arm's runs; the problems found (a malformed run, an unknown
    mode, a gap or an overlap), each naming the arm and the run."""
    problems: list[str] = []
    expected = 1
    for n, run in enumerate(runs, start=1):
        where = f"{arm} run {n} {run!r}"
        try:
            first, last, mode = run
        except (TypeError, ValueError):
            problems.append(f"{where}: expected (first_line, last_line, mode)")
            continue
        if not all(
            isinstance(v, int | np.integer) and not isinstance(v, bool) for v in (first, last)
        ):
            problems.append(f"{where}: line numbers must be integers")
            continue
        if mode not in ARM_MODES:
            problems.append(f"{where}: mode {mode!r} is not one of {', '.join(ARM_MODES)}")
        if not 1 <= first <= last <= num_lines:
            problems.append(f"{where}: needs 1 <= first_line <= last_line <= {num_lines}")
            continue
        if first < expected:
            problems.append(f"{where}: overlaps lines already covered up to {expected - 1}")
        elif first > expected:
            problems.append(f"{where}: lines {expected}..{first - 1} are not covered")
        pwm[first - 1 : last] = mode == "pwm"
        expected = max(expected, last + 1)
    if expected <= num_lines:
        problems.append(f"{arm}: lines {expected}..{num_lines} are not covered")
    return problems
