"""Where a command may write a file it names: the right suffix, in a folder that exists.

Checked before a long run starts (a simulation, an export), so that a mistyped name is
refused at once with exit 2 rather than after the work is done.
"""

from __future__ import annotations

import os
from pathlib import Path

from robot.errors import InputError

__all__ = ["writable_output"]


def writable_output(path: str | os.PathLike, suffix: str, what: str) -> Path:
    """``path`` if a ``what`` (e.g. "a recording", "the MCAP file") can be written there.

    Raises:
        InputError: the name does not end in ``suffix``, or its folder does not exist.
    """
    out = Path(path)
    if out.suffix != suffix:
        raise InputError(f"{out}: {what} is written as a {suffix} file; name it "
                         f"{out.with_suffix(suffix).name}")
    if not out.parent.is_dir():
        raise InputError(f"{out}: no folder {out.parent} to write {what} in")
    return out
