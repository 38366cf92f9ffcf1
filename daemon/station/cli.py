"""``hubo-init``: the operator's web page (the thesis's hubo-init GUI).

    hubo-init [--instance NAME] [--robot R] [--host 127.0.0.1] [--port 8080]
              [--rate-hz 10] [--camera none|sim] [--ladder drc] [--camera-fps 4]
              [--bridge tls/HOST:PORT --tls-dir DIR --name NAME]

Serves one page (nicegui) that shows every joint's position, reference, error, mode and
board state (faults red, warnings amber), the F/T sensors, IMUs and battery, refreshed
from the daemon's ``state`` channel ``--rate-hz`` times a second; buttons to home all,
home or reset one joint, initialise the sensors, pause and stop the player; a line for
any hubo-console command (goto, comp, kp, kd, maxPWM); hubo-neck's keys. Every refusal is
shown with its reason. ``--camera sim`` renders the head camera of a sim daemon (started
with the same ``--ladder`` and ``--robot``) ``--camera-fps`` times a second.

``--bridge`` serves the same page on the operator's computer for a robot behind
``hubo-bridge robot``: the state comes from the bridge, and every button, key and command
goes through it, answered by the robot's local tools (the bridge refuses goto, comp and
status over the network). ``--tls-dir`` and ``--name`` are hubo-bridge operator's: this
operator's certificate, which the robot must list with ``--allow-writer``.

Open http://HOST:PORT/ in a browser. Ctrl-C or SIGTERM stops the server.

Exit codes: 0 stopped, 1 failed (no robot bridge to connect to, or failed while
running), 2 bad input (an option out of its range, named with the range; a bad option
combination): nothing is served.
"""

from __future__ import annotations

import argparse
import logging
import sys
from typing import TYPE_CHECKING

from daemon.console import add_daemon_options
from daemon.remote.cli import add_operator_options, operator_endpoint_and_tls
from robot.errors import InputError, parse_finite, run_cli

if TYPE_CHECKING:
    from daemon.remote.session_config import TlsFiles
    from daemon.station.link import StationLink

__all__ = ["CAMERA_FPS_RANGE_HZ", "RATE_RANGE_HZ", "main"]

#: Allowed page refresh rates [Hz]: slower hides a fault for over a second; faster sends
#: the 40 rows to every browser more often than an operator can read them.
RATE_RANGE_HZ = (1.0, 20.0)
#: Allowed head camera rates [Hz]: each frame is a MuJoCo render on a shared CPU.
CAMERA_FPS_RANGE_HZ = (1.0, 10.0)
PORT_RANGE = (1, 65535)
#: How long the server keeps a browser's page (its chosen joint, its log) while the
#: browser's connection is down [s]; past it the browser reloads a new page. NiceGUI's 3 s
#: default rebuilt pages on a busy operator computer and lost the operator's choices.
RECONNECT_TIMEOUT_S = 30.0
#: Messages the server keeps to resend after a dropped connection. At the 20 Hz page rate
#: (about 4 messages a refresh) NiceGUI's 1000 covered 12 s: a slow browser that had not
#: acknowledged them got a reloaded page instead.
MESSAGE_HISTORY = 10_000


def _in_range(flag: str, text: str, allowed: tuple[float, float], unit: str) -> float:
    """``text`` as a number within ``allowed`` (both ends included)."""
    value = parse_finite(text, flag)
    if not allowed[0] <= value <= allowed[1]:
        raise InputError(f"{flag} {text} refused: allowed [{allowed[0]:g}, {allowed[1]:g}]"
                         f"{unit}; nothing served")
    return value


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="hubo-init", description=__doc__.split("\n\n")[0])
    add_daemon_options(p, "goto, comp and the neck keys")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to serve on (default 127.0.0.1: this machine only)")
    p.add_argument("--port", default="8080", help="TCP port (default 8080)")
    p.add_argument("--rate-hz", default="10", metavar="HZ",
                   help="state refresh of the page (default 10, allowed [1, 20]) [Hz]")
    p.add_argument("--camera", choices=("none", "sim"), default="none",
                   help="head camera: sim renders a sim daemon's with MuJoCo (default none)")
    p.add_argument("--ladder", default="drc",
                   help="--camera sim: the sim daemon's ladder (name or spec file; drc)")
    p.add_argument("--camera-fps", default="4", metavar="HZ",
                   help="--camera sim: frames a second (default 4, allowed [1, 10]) [Hz]")
    bridge = p.add_argument_group(
        "through hubo-bridge", "the robot's daemon behind `hubo-bridge robot`; --instance "
        "is its instance there, and its bridge's --robot sets the limits")
    add_operator_options(bridge, "--bridge", required=False)
    return p


def _bridge_options(args: argparse.Namespace) -> tuple[str, TlsFiles] | None:
    """The robot bridge's endpoint and this operator's `TlsFiles` with ``--bridge``; None
    without it (the daemon's channels here). Checked before anything is opened.

    Raises:
        InputError: ``--bridge`` without ``--tls-dir`` and ``--name``, or they without it;
            a bad endpoint or a missing TLS file.
    """
    certificate = [f for f, v in (("--tls-dir", args.tls_dir), ("--name", args.name)) if v]
    if args.bridge is None:
        if certificate:
            raise InputError(f"{' and '.join(certificate)} refused without --bridge: they "
                             "name the operator's certificate for the robot bridge; "
                             "nothing served")
        return None
    if len(certificate) < 2:
        raise InputError("--bridge needs --tls-dir and --name (this operator's certificate, "
                         "as hubo-bridge operator takes them); nothing served")
    return operator_endpoint_and_tls(args, "--bridge")


def _open_link(args: argparse.Namespace, bridge: tuple[str, TlsFiles] | None
               ) -> StationLink:
    """The page's state source and command sink: the robot bridge with ``--bridge``
    (`_bridge_options`), else the daemon's channels here.

    Raises:
        HuboLadderError: no robot bridge to connect to.
    """
    if bridge is None:
        from daemon.station.local_link import LocalLink

        return LocalLink(args.instance, args.robot)
    from daemon.station.bridge_link import BridgeLink

    return BridgeLink(*bridge, args.instance)


def _run(args: argparse.Namespace) -> int:
    rate_hz = _in_range("--rate-hz", args.rate_hz, RATE_RANGE_HZ, " Hz")
    fps = _in_range("--camera-fps", args.camera_fps, CAMERA_FPS_RANGE_HZ, " Hz")
    port = _in_range("--port", args.port, PORT_RANGE, "")
    if port != int(port):
        raise InputError(f"--port {args.port} refused: a whole number in [1, 65535]")
    bridge = _bridge_options(args)
    from nicegui import app, ui

    from daemon.station.head_camera import SimHeadCamera
    from daemon.station.page import Station, build_page

    camera = SimHeadCamera(args.ladder, args.robot, fps) if args.camera == "sim" else None
    link = _open_link(args, bridge)
    if camera is not None:
        camera.start(link.latest_state)
    station = Station(link, rate_hz, camera)
    app.on_shutdown(station.close)
    print(f"hubo-init: http://{args.host}:{int(port)}/ for {link.where}, "
          f"{rate_hz:g} Hz, camera {args.camera}", file=sys.stderr, flush=True)
    ui.run(lambda: build_page(station), host=args.host, port=int(port), title="hubo-init",
           reload=False, show=False, show_welcome_message=False, favicon="🪜",
           reconnect_timeout=RECONNECT_TIMEOUT_S, message_history_length=MESSAGE_HISTORY)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``hubo-init``; returns the exit code."""
    args = _parser().parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(name)s: %(message)s")
    return run_cli("hubo-init", lambda: _run(args))


if __name__ == "__main__":
    sys.exit(main())
