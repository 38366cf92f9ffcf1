"""Where a recording goes: a ``.rrd`` file, or a web viewer served from this process.

A file opens in Rerun's viewer with no network (``rerun FILE.rrd``; on a machine without
a display, ``rerun --serve-web FILE.rrd`` serves the web viewer over HTTP). Serving starts
Rerun's gRPC server and its web viewer on this machine and keeps the process alive until
Ctrl-C.

Rerun (``rerun-sdk``) is the optional extra ``view``; without it, a one-line error says
how to install it, before any long computation.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import quote

from robot.errors import HuboLadderError
from robot.output_path import writable_output

if TYPE_CHECKING:
    import rerun as rr

__all__ = ["APPLICATION_ID", "WEB_PORT", "check_output", "open_file", "require_rerun",
           "serve"]

APPLICATION_ID = "hubo-ladder"
#: The web viewer's default HTTP port (Rerun's).
WEB_PORT = 9090


def require_rerun() -> None:
    """Raise a `HuboLadderError` that says how to install Rerun, if it is missing."""
    if importlib.util.find_spec("rerun") is None:
        raise HuboLadderError("recordings need the rerun-sdk package: pip install -e "
                              "'.[view]' (make install does)")


def check_output(path: str | Path) -> Path:
    """``path`` if a recording can be written there: Rerun installed, a ``.rrd`` name in
    a folder that exists (checked before a long run, not after)."""
    require_rerun()
    return writable_output(path, ".rrd", "a recording")


def _stream() -> rr.RecordingStream:
    """A new recording on the ``time`` timeline only (no wall-clock ``log_time``)."""
    import rerun as rr

    rec = rr.RecordingStream(APPLICATION_ID)
    rec.set_log_time_enabled(False)
    return rec


def open_file(path: str | Path) -> rr.RecordingStream:
    """A recording stream that writes ``path`` (`check_output`)."""
    out = check_output(path)
    rec = _stream()
    rec.save(out)
    return rec


def serve(web_port: int = WEB_PORT) -> tuple[rr.RecordingStream, str]:
    """A recording stream served to a web viewer: (stream, the viewer's address)."""
    require_rerun()
    import rerun as rr

    rec = _stream()
    grpc = rec.serve_grpc()
    rr.serve_web_viewer(web_port=web_port, open_browser=False, connect_to=grpc)
    return rec, f"http://localhost:{web_port}/?url={quote(grpc, safe='')}"
