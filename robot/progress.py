"""Progress with an ETA for the long commands (plan-ladder, check-plan, validate-plan,
batch-eval).

On a terminal it is a live Rich bar (description, bar, done/total, elapsed, time left).
Anywhere else (a log file, CI, ``| tee``) a live bar would print nothing useful or fill the
log with control codes, so it writes plain lines: one when the work starts, then at most
one every `PLAIN_INTERVAL_S`, then one when it ends::

    check-plan: lines 41,000/314,467 (13%), 0:40 elapsed, about 4:27 left

The ETA is the elapsed time scaled by what remains; a new phase (``update(restart=True)``)
measures its rate from where it starts.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import IO, Any

__all__ = ["PLAIN_INTERVAL_S", "ProgressReporter", "format_duration"]

#: The most often a plain (non-terminal) progress line is written [s].
PLAIN_INTERVAL_S = 10.0


def format_duration(seconds: float) -> str:
    """``0:07``, ``4:27``, ``1:02:05`` for a duration [s]."""
    s = max(0, int(round(seconds)))
    h, rest = divmod(s, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


def _is_terminal(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed file
        return False


def _count(done: float, total: float) -> str:
    return f"{done:,.0f}/{total:,.0f}" if total > 0 else f"{done:,.0f}"


class ProgressReporter:
    """One task's progress: ``update(done)`` as it goes, `finish` when it ends.

    Args:
        prog: the command, at the start of every plain line.
        label: what is counted (``lines``, ``simulated s``, ``steps``).
        total: the amount of work (may change with ``update(total=...)``).
        stream: where to write; stderr by default.
        live: a live bar (True) or plain lines (False); None: a bar when ``stream`` and
            stdout are both terminals (``cmd | tee log`` or ``cmd 2>&1 | tee`` gets lines).
        interval_s: the least time between two plain lines [s].
        show: ``show(done, total)`` → the counted part of a line, ``1,200/9,000`` by
            default.
        clock: the time source [s] (tests pass a fake one).
        console: the Rich console of the live bar (the command's own, so that its log
            lines print above the bar); a `text_console` on ``stream`` if None.
    """

    def __init__(self, prog: str, label: str, total: float, *, stream: IO[str] | None = None,
                 live: bool | None = None, interval_s: float = PLAIN_INTERVAL_S,
                 show: Callable[[float, float], str] = _count,
                 clock: Callable[[], float] = time.monotonic, console: Any = None) -> None:
        self.prog, self.label, self.total = prog, label, float(total)
        self.stream = stream if stream is not None else sys.stderr
        self.live = (_is_terminal(self.stream) and _is_terminal(sys.stdout)) if live is None \
            else live
        self.interval_s, self.show, self.clock = interval_s, show, clock
        self._console = console
        self.done = 0.0
        self.note = ""
        self._t0 = clock()
        self._base = (self._t0, 0.0)  # (time, done) the rate is measured from
        self._last_line = -float("inf")
        self._bar: Any = None
        self._task: Any = None
        self._finished = False
        if self.live:
            self._start_bar()
        else:
            self._write_line(self.status())

    # -- the two modes ------------------------------------------------------------------

    def _start_bar(self) -> None:
        from rich.progress import (
            BarColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        from robot.text_console import text_console

        console = self._console or text_console(file=self.stream)
        self._bar = Progress(TextColumn("{task.description}"), BarColumn(),
                             TextColumn("{task.fields[count]}"), TimeElapsedColumn(),
                             TextColumn("left"), TimeRemainingColumn(), console=console,
                             transient=False)
        self._bar.start()
        self._task = self._bar.add_task(self._description(), total=self.total or None,
                                        count=self.show(0, self.total))

    def _description(self) -> str:
        return f"{self.label}: {self.note}" if self.note else self.label

    def _write_line(self, state: str) -> None:
        self.stream.write(f"{self.prog}: {state}\n")
        self.stream.flush()
        self._last_line = self.clock()

    # -- what the caller uses ------------------------------------------------------------

    def eta_s(self) -> float | None:
        """Seconds left at the rate since the start (or the phase); None before a rate."""
        if self.total <= 0:
            return None
        t1, d1 = self._base
        rate = (self.done - d1) / max(self.clock() - t1, 1e-9)
        if rate <= 0:
            return None
        return max(0.0, self.total - self.done) / rate

    def status(self) -> str:
        """``lines 1,200/9,000 (13%), 0:40 elapsed, about 4:27 left``."""
        parts = [f"{self.label} {self.show(self.done, self.total)}"]
        if self.total > 0:
            parts[0] += f" ({100.0 * min(self.done / self.total, 1.0):.0f}%)"
        if self.note:
            parts[0] += f", {self.note}"
        parts.append(f"{format_duration(self.clock() - self._t0)} elapsed")
        eta = self.eta_s()
        if eta is not None:
            parts.append(f"about {format_duration(eta)} left")
        return ", ".join(parts)

    def update(self, done: float, *, total: float | None = None, note: str | None = None,
               restart: bool = False) -> None:
        """Record progress: ``done`` of the total so far; an optional new total or note;
        ``restart``: a new phase starts here (the ETA forgets the rate before it)."""
        if self._finished:
            return
        if restart:
            self._base = (self.clock(), float(done))
            if self.live:
                self._bar.reset(self._task, completed=float(done))
        self.done = float(done)
        if total is not None:
            self.total = float(total)
        if note is not None:
            self.note = note
        if self.live:
            self._bar.update(self._task, completed=self.done, total=self.total or None,
                             description=self._description(),
                             count=self.show(self.done, self.total))
        elif self.clock() - self._last_line >= self.interval_s:
            self._write_line(self.status())

    def finish(self, note: str = "done") -> None:
        """End the bar (or write the last plain line) with ``note``."""
        if self._finished:
            return
        self._finished = True
        if self.live:
            self._bar.update(self._task, description=f"{self.label}: {note}")
            self._bar.stop()
        else:
            self._write_line(f"{note}, {format_duration(self.clock() - self._t0)}")

    def __enter__(self) -> ProgressReporter:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.finish("done" if exc_type is None else "stopped")
