"""Rerun's viewer on a recording, at a given time: on screen, or as a screenshot.

A recording's layout cannot place the time cursor (`execute.view.layout`), so
``hubo-view --open`` starts Rerun's viewer itself (``rerun.experimental.ViewerClient``),
opens the file and moves the cursor to the time asked for: by default a failed run's
failure (the time of its ``events/failure``). ``--screenshot`` does the same in a
headless viewer and saves the picture; that needs a Vulkan driver (a GPU's, or Mesa's
software ``lavapipe``: Debian's ``mesa-vulkan-drivers``).
"""

from __future__ import annotations

import shutil
import sys
import time
from pathlib import Path

from execute.view.output import require_rerun
from execute.view.recording import TIMELINE
from robot.errors import HuboLadderError

__all__ = ["LOAD_TIMEOUT_S", "failure_time", "open_in_viewer"]

#: How long the viewer may take to load a recording [s].
LOAD_TIMEOUT_S = 120.0
#: A screenshot is taken this long after the cursor moved [s] (the frame to render).
SETTLE_S = 2.0


def failure_time(path: str | Path) -> float | None:
    """The time of a recording's first ``events/failure`` [s], None if it has none."""
    import pyarrow as pa
    from rerun.chunk import RrdReader

    times = []
    for chunk in RrdReader(path).stream():
        if chunk.entity_path == "/events/failure" and TIMELINE in chunk.timeline_names:
            column = chunk.to_record_batch().column(TIMELINE).cast(pa.int64())
            times += [ns * 1e-9 for ns in column.to_pylist()]
    return min(times) if times else None


def _executable() -> str:
    """The ``rerun`` program of this environment (it comes with ``rerun-sdk``)."""
    exe = shutil.which("rerun") or str(Path(sys.executable).with_name("rerun"))
    if not Path(exe).exists():
        raise HuboLadderError("Rerun's viewer (the rerun program of rerun-sdk) is not "
                              "installed: pip install -e '.[view]'")
    return exe


def open_in_viewer(path: str | Path, at_s: float | None = None,
                   screenshot: str | Path | None = None) -> None:
    """Open ``path`` in Rerun's viewer with the cursor at ``at_s`` [s] (paused); with
    ``screenshot``, in a headless viewer that saves a PNG there and quits.

    Raises:
        HuboLadderError: the viewer cannot start (no display, no graphics adapter) or
            does not load the file in `LOAD_TIMEOUT_S`.
    """
    require_rerun()
    from rerun.experimental import ViewerClient

    recording = Path(path).resolve()
    headless = screenshot is not None
    try:
        client = ViewerClient.spawn(headless=headless, hide_welcome_screen=True,
                                    executable_path=_executable())
    except HuboLadderError:
        raise
    except Exception as exc:  # the viewer is another program: any failure is reported
        hint = ("a headless viewer needs a Vulkan driver (Debian: mesa-vulkan-drivers)"
                if headless else f"without a display: rerun --serve-web {path}, then a "
                "browser")
        raise HuboLadderError(f"Rerun's viewer did not start: {exc}; {hint}") from None
    try:
        _show(client, recording, at_s, screenshot)
    except HuboLadderError:
        raise
    except Exception as exc:
        raise HuboLadderError(f"Rerun's viewer could not show {path}: {exc}") from None
    finally:
        if headless:
            client.quit()


def _show(client, recording: Path, at_s: float | None, screenshot: str | Path | None
          ) -> None:
    """Open the file, wait until it is loaded, move the cursor, take the screenshot."""
    client.open(str(recording))
    deadline = time.monotonic() + LOAD_TIMEOUT_S
    while client.get_state().loading:
        if time.monotonic() > deadline:
            raise HuboLadderError(f"{recording}: Rerun's viewer did not load it in "
                                  f"{LOAD_TIMEOUT_S:.0f} s")
        time.sleep(0.2)
    if at_s is not None:
        client.set_time(TIMELINE, duration=float(at_s), play_state="paused")
    if screenshot is not None:
        time.sleep(SETTLE_S)
        client.save_screenshot(str(Path(screenshot).resolve()))
