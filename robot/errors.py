"""One exception hierarchy for the whole project.

`HuboLadderError` is the root. `InputError` (and subclasses) means the user gave us
something we refuse: CLIs exit with code 2 and print the message, which names the file,
line, column or field and the allowed range.
"""

from __future__ import annotations


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


class RobotModelError(HuboLadderError):
    """The robot description is inconsistent (a bug in a parameter table)."""
