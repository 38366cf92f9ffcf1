"""How a recording opens: the views, and where the time cursor plays.

A Rerun blueprint (sent with the recording) lays out a 3D view of ``/world``, the text
events, and one plot per time series group; the time panel is on the ``time`` timeline
at real speed.

Rerun's blueprint has no "current time": a viewer that opens a file follows it to its
last time. A failed run's recording ends at its failure (`execute.view.run_recording`,
`execute.view.result_view`), so it opens there; the blueprint also selects the seconds
before the failure, and play loops over them.
"""

from __future__ import annotations

from collections.abc import Sequence

import rerun.blueprint as rrb
from rerun.encodings import AbsoluteTimeRange, TimeInt

from execute.view.recording import TIMELINE

__all__ = ["AFTER_FAILURE_S", "BEFORE_FAILURE_S", "blueprint"]

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
    loop = {}
    if failure_s is not None:
        lo = max(0.0, failure_s - BEFORE_FAILURE_S)
        loop = {"loop_mode": "selection", "time_selection": AbsoluteTimeRange(
            TimeInt(seconds=lo), TimeInt(seconds=failure_s + AFTER_FAILURE_S))}
    return rrb.Blueprint(
        rrb.Horizontal(rrb.Spatial3DView(origin="/world", name="climb"),
                       rrb.Vertical(*right), column_shares=[3, 2]),
        rrb.TimePanel(timeline=TIMELINE, playback_speed=1.0, **loop), collapse_panels=False)
