"""One exception hierarchy for the whole project.

`HuboLadderError` is the root. `InputError` (and subclasses) means the user gave us
something we refuse: CLIs exit with code 2 and print the message, which names the file,
line, column or field and the allowed range.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable


class HuboLadderError(Exception):
    """Base class of every error this project raises on purpose."""


class InputError(HuboLadderError):
    """Bad user input: a spec, a file, a flag or a gain. CLI exit code 2."""


class TrajectoryFileError(InputError):
    """A 40-column trajectory file failed validation; carries every problem found."""

    def __init__(self, path: str, problems: list[str]):
        self.path = path
        self.problems = problems
        shown = problems[:20]
        more = f"\n... and {len(problems) - len(shown)} more" if len(problems) > len(shown) else ""
        super().__init__("\n".join(shown) + more)


class LadderSpecError(InputError):
    """A ladder spec failed validation."""


def parse_finite(text: str, what: str) -> float:
    """``text`` as a finite float, or an `InputError` naming ``what`` it was meant to be."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(f"{what} {text!r} is not a number (finite numbers only)")
    return value


class RobotModelError(HuboLadderError):
    """The robot description is inconsistent (a bug in a parameter table)."""


def run_cli(prog: str, job: Callable[[], int]) -> int:
    """Run a command's body; a project error becomes a one-line message on stderr and an
    exit code: 2 for bad input, 1 when the job ran and failed. Tracebacks are for bugs."""
    try:
        return job()
    except InputError as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 2
    except HuboLadderError as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 1
