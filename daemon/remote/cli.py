"""``hubo-bridge``: the daemon's channels over the network, on zenoh with mutual TLS.

    hubo-bridge certs DIR [--robot-name robot] --operator NAME ... [--host HOST ...]
    hubo-bridge robot --tls-dir DIR [--name robot] --allow-writer NAME ...
                      [--listen tls/0.0.0.0:7447] [--instance NAME] [--robot R]
                      [--rate-hz 10] [--max-delay-s 0.1] [--duration-s S]
    hubo-bridge operator --tls-dir DIR --name NAME --connect tls/HOST:PORT
                      [--instance NAME] (-c "CMD; CMD" | --mirror LOCAL) [--duration-s S]

``robot`` runs beside ``hubo-daemon``: it publishes the state at ``--rate-hz`` (allowed
1 to 200 Hz) and takes references, board commands, neck keys and the player's pause and
stop from the operators named by ``--allow-writer`` (their certificates' names), through
the checks of the local tools. ``operator -c`` sends commands: ``homeAll``, ``home J``,
``reset J``, ``iniSensors``, ``kp|kd|maxPWM J V``, ``neck KEYS``, ``pause``, ``stop``;
``operator --mirror LOCAL`` mirrors the robot's channels into local instance LOCAL
(``hubo-read --instance LOCAL`` shows the robot; ``play-trajectory --instance LOCAL``
plays to it). ``certs`` makes a certificate authority and the certificates.

Exit codes: 0 done, 1 failed (no robot, the daemon did not answer), 2 refused (a bad
option, a command the robot refused).
"""

from __future__ import annotations

import argparse
import logging
import signal
import sys
import threading
from typing import TYPE_CHECKING

from robot.errors import InputError, run_cli

__all__ = ["add_operator_options", "main", "operator_endpoint_and_tls"]

if TYPE_CHECKING:
    from daemon.remote.session_config import TlsFiles

PROG = "hubo-bridge"
FIRST_STATE_TIMEOUT_S = 5.0  #: the operator waits this long for the robot's first state [s]


def _add_tls_options(p: argparse.ArgumentParser, name_default: str | None, name_help: str,
                     required: bool) -> None:
    """``--tls-dir`` and ``--name``: a node's TLS files, as ``hubo-bridge certs`` wrote them."""
    p.add_argument("--tls-dir", required=required,
                   help="directory of ca.pem, NAME.pem, NAME.key")
    p.add_argument("--name", default=name_default, required=required and name_default is None,
                   help=name_help)


def add_operator_options(p: argparse.ArgumentParser, connect_flag: str = "--connect",
                         required: bool = True) -> None:
    """The operator side's options: the robot bridge's endpoint (``connect_flag``) and this
    operator's certificate (``--tls-dir``, ``--name``). ``hubo-bridge operator`` and
    ``hubo-init --bridge`` take them; read them back with `operator_endpoint_and_tls`.

    Args:
        p: the parser.
        connect_flag: the endpoint's option name.
        required: whether argparse requires them (False: the caller checks).
    """
    p.add_argument(connect_flag, required=required, metavar="tls/HOST:PORT",
                   help="the robot bridge's endpoint")
    _add_tls_options(p, None, "this operator's certificate name", required)


def operator_endpoint_and_tls(args: argparse.Namespace, connect_flag: str = "--connect"
                              ) -> tuple[str, TlsFiles]:
    """The endpoint and the `TlsFiles` of the options of `add_operator_options`.

    Raises:
        InputError: the endpoint is not ``tls/HOST:PORT``, or a TLS file is missing.
    """
    from daemon.remote.session_config import TlsFiles, check_endpoint

    endpoint = check_endpoint(connect_flag, getattr(args, connect_flag.lstrip("-")))
    return endpoint, TlsFiles.from_dir(args.tls_dir, args.name)


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="side", required=True)
    c = sub.add_parser("certs", help="make a CA and the robot's and operators' certificates")
    c.add_argument("directory")
    c.add_argument("--robot-name", default="robot", help="the robot's certificate name")
    c.add_argument("--operator", action="append", required=True, metavar="NAME",
                   help="an operator's certificate name (repeat)")
    c.add_argument("--host", action="append", metavar="HOST",
                   help="a name or address operators dial the robot by (repeat; default "
                        "localhost and 127.0.0.1)")
    for name in ("robot", "operator"):
        s = sub.add_parser(name, help=f"the {name} side")
        s.add_argument("--instance", default="default", help="daemon instance (default)")
        s.add_argument("--duration-s", type=float, help="stop after this long [s]")
        s.add_argument("-v", "--verbose", action="store_true", help="log at INFO")
    r = sub.choices["robot"]
    _add_tls_options(r, "robot", "this node's certificate name (robot)", True)
    r.add_argument("--listen", default="tls/0.0.0.0:7447", help="endpoint, tls/HOST:PORT")
    r.add_argument("--allow-writer", action="append", default=[], metavar="NAME",
                   help="certificate name of an operator that may write (repeat)")
    r.add_argument("--robot", default="drc-hubo", choices=("drc-hubo", "hubo2plus"),
                   help="robot whose joint limits the commands respect (default drc-hubo)")
    r.add_argument("--rate-hz", type=float, default=10.0,
                   help="state publication rate [Hz] (default 10, allowed [1, 200])")
    r.add_argument("--max-delay-s", type=float, default=0.1,
                   help="link allowance [s]: commands sent on a state older than one period "
                        "plus this are dropped (default 0.1, allowed (0, 1])")
    o = sub.choices["operator"]
    add_operator_options(o)
    what = o.add_mutually_exclusive_group(required=True)
    what.add_argument("-c", dest="commands", metavar="CMDS", help="';'-separated commands")
    what.add_argument("--mirror", metavar="LOCAL", help="mirror into local instance LOCAL")
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``hubo-bridge``; returns the exit code."""
    args = _parser().parse_args(argv)
    if getattr(args, "duration_s", None) is not None and not args.duration_s > 0:
        print(f"{PROG}: --duration-s {args.duration_s:g} refused: must be > 0 s",
              file=sys.stderr)
        return 2
    if args.side != "certs":
        logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                            format=f"{PROG} {args.side}: %(message)s")
    job = {"certs": _certs, "robot": _robot, "operator": _operator}[args.side]
    return run_cli(PROG, lambda: job(args))


def _certs(args: argparse.Namespace) -> int:
    from daemon.remote.certs import make_certificates

    hosts = tuple(args.host) if args.host else ("localhost", "127.0.0.1")
    for path in make_certificates(args.directory, args.robot_name, tuple(args.operator), hosts):
        print(path)
    return 0


def _stop_on_signals() -> threading.Event:
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    return stop


def _robot(args: argparse.Namespace) -> int:
    from daemon.remote.robot import RobotBridge, RobotBridgeConfig
    from daemon.remote.session_config import TlsFiles

    config = RobotBridgeConfig(TlsFiles.from_dir(args.tls_dir, args.name), args.listen,
                               tuple(args.allow_writer), args.instance, args.robot,
                               args.rate_hz, args.max_delay_s)
    stop = _stop_on_signals()
    bridge = RobotBridge(config)
    try:
        stats = bridge.run(stop, args.duration_s)
    finally:
        bridge.close()
    print(f"{PROG} robot: {stats.line()}", file=sys.stderr)
    return 0


def _operator(args: argparse.Namespace) -> int:
    from daemon.remote.operator import BridgeOperator, wait_first_state

    _, tls = operator_endpoint_and_tls(args)
    if args.mirror is not None:
        return _mirror(args, tls)
    commands = [c.strip() for c in args.commands.split(";") if c.strip()]
    with BridgeOperator(args.connect, tls, args.instance) as operator:
        wait_first_state(operator, FIRST_STATE_TIMEOUT_S)
        code = 0
        for line in commands:
            code = max(code, run_cli(PROG, lambda line=line: _send(operator, line)))
    return code


def _send(operator, line: str) -> int:
    """Send one ``-c`` command, printing the robot's answer."""
    from daemon.remote.keys import Topic

    verb, _, rest = line.partition(" ")
    if verb.lower() == "neck":
        if not rest.strip():
            raise InputError("neck takes the keys to press, e.g. neck qq")
        for k in rest.strip():
            print(operator.command(Topic.NECK, k))
    elif verb.lower() in ("pause", "stop") and not rest.strip():
        print(operator.command(Topic.PLAYER, verb.lower()))
    else:
        print(operator.command(Topic.CONSOLE, line))
    return 0


def _mirror(args: argparse.Namespace, tls) -> int:
    from daemon.remote.mirror import Mirror
    from daemon.remote.operator import BridgeOperator, wait_first_state

    mirror = Mirror(lambda on_state: BridgeOperator(args.connect, tls, args.instance,
                                                    on_state=on_state), args.mirror)
    stop = _stop_on_signals()
    try:
        wait_first_state(mirror.operator, FIRST_STATE_TIMEOUT_S)
        mirror.run(stop, args.duration_s)
    finally:
        mirror.close()
    print(f"{PROG} operator: mirrored {mirror.operator.states_received} states, sent "
          f"{mirror.refs_sent} refs", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
