"""How a recording opens: the views, and where the time cursor plays.

A Rerun blueprint (sent with the recording) lays out a 3D view of ``/world``, the text
events, and one plot per time series group; the time panel is on the ``time`` timeline
at real speed. A run that failed opens with the seconds before the failure selected and
playing in a loop (Rerun's blueprint has no "current time", so a looped selection is how
a recording says where to look).
"""

from __future__ import annotations

from collections.abc import Sequence

import rerun.blueprint as rrb
from rerun.encodings import AbsoluteTimeRange, TimeInt

from execute.view.recording import TIMELINE

__all__ = ["BEFORE_FAILURE_S", "blueprint"]

#: A failed run opens looping over this long before its failure [s] ...
BEFORE_FAILURE_S = 7.0
#: ... and this long after it [s].
AFTER_FAILURE_S = 0.5


def blueprint(series: Sequence[tuple[str, str]], failure_s: float | None = None
              ) -> rrb.Blueprint:
    """The layout: the 3D climb on the left; the events and the plots on the right.

    Args:
        series: (entity path, title) of each time-series plot.
        failure_s: the failure's time [s], if the run failed.
    """
    right = [rrb.TextLogView(origin="/events", name="events")]
    right += [rrb.TimeSeriesView(origin=path, name=title) for path, title in series]
    panel = rrb.TimePanel(timeline=TIMELINE, playback_speed=1.0)
    if failure_s is not None:
        lo = max(0.0, failure_s - BEFORE_FAILURE_S)
        panel = rrb.TimePanel(timeline=TIMELINE, playback_speed=1.0, play_state="playing",
                              loop_mode="selection",
                              time_selection=AbsoluteTimeRange(
                                  TimeInt(seconds=lo),
                                  TimeInt(seconds=failure_s + AFTER_FAILURE_S)))
    return rrb.Blueprint(
        rrb.Horizontal(rrb.Spatial3DView(origin="/world", name="climb"),
                       rrb.Vertical(*right), column_shares=[3, 2]),
        panel, collapse_panels=False)
