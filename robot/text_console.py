"""A Rich console that prints text verbatim, for every command that shows user text.

Rich reads ``:name:`` as an emoji code and ``[...]`` as markup, and colours numbers and
paths: a message ``file.traj:100:12`` printed by a default console reads ``file.traj💯12``,
and ``[0, 2.61]`` may lose its brackets. `text_console` turns all three off. A command
that wants colour builds `rich.text.Text` objects with an explicit style, which never
parse their content.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # rich is imported by the commands only
    from rich.console import Console

__all__ = ["text_console"]


def text_console(*, stderr: bool = False, **kwargs: Any) -> Console:
    """A `rich.console.Console` with emoji codes, markup and highlighting off.

    Args:
        stderr: write to stderr instead of stdout.
        **kwargs: more `rich.console.Console` arguments (``width``, ``file``, ...).
    """
    from rich.console import Console

    return Console(stderr=stderr, emoji=False, markup=False, highlight=False, **kwargs)
