"""``hubo-daemon``: the 200 Hz loop between the channels and the boards (CAN or MuJoCo).

    hubo-daemon [--backend sim|can] [--ladder LADDER] [--robot R]
                [--can-interface socketcan --channels can0,can1] [--emulate-boards]
                [--instance NAME] [--log FILE] [--status] [--watchdog-s S] [--homed]
                [--rt-priority N]

At start-up it removes the instance's channel files that no live process holds (a
crashed daemon or player leaves them), refuses to start when another daemon runs on the
same instance, then runs `daemon.loop.DaemonLoop` until SIGINT or SIGTERM: the loop ends
after its current tick, the boards keep the last reference (position held), the log is
flushed. ``--status`` prints one line per second on stderr.

``--emulate-boards`` (with ``--can-interface virtual``) runs
`daemon.can.emulator.BoardEmulator` in the process on the same virtual channels: the
whole CAN path without hardware.

Exit codes: 0 stopped by a signal, 1 failed while running, 2 bad input.
"""

from __future__ import annotations

import argparse
import logging
import signal
import socket
import sys
import threading

import numpy as np

from robot.errors import HuboLadderError, InputError, run_cli

__all__ = ["main", "status_line"]

log = logging.getLogger("hubo-daemon")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="hubo-daemon", description=__doc__.split("\n\n")[0])
    p.add_argument("--backend", choices=("sim", "can"), default="sim",
                   help="MuJoCo board model or real boards over CAN (default sim)")
    p.add_argument("--ladder", default="drc", help="sim: ladder name or spec file (drc)")
    p.add_argument("--robot", default="drc-hubo", help="robot (default drc-hubo)")
    p.add_argument("--can-interface", default="socketcan",
                   help="python-can interface: socketcan, pcan, virtual (default socketcan)")
    p.add_argument("--channels", default="can0,can1", help="bus 0 and bus 1 channels")
    p.add_argument("--bitrate", type=int, default=1_000_000, help="pcan bit rate [bit/s]")
    p.add_argument("--emulate-boards", action="store_true",
                   help="run the board emulator in-process (virtual interface only)")
    p.add_argument("--instance", default="default", help="channel namespace (default)")
    p.add_argument("--log", metavar="FILE", help="append one state record per tick here")
    p.add_argument("--status", action="store_true", help="one status line per second")
    p.add_argument("--watchdog-s", type=float, default=0.2, metavar="S",
                   help="hold when the ref channel is this old while playing (0.2 s)")
    p.add_argument("--rt-priority", type=int, default=0, metavar="N",
                   help="run the loop SCHED_FIFO at priority N (1..99; 0: normal, default)")
    p.add_argument("--homed", action="store_true",
                   help="sim: start with every joint homed (skip homeAll)")
    p.add_argument("-v", "--verbose", action="store_true", help="log at INFO level")
    return p


def status_line(loop) -> str:
    """One line: ticks, overruns, watchdog, homing, compliance, replies, board commands,
    ref samples rejected beyond the joint limits, power."""
    from daemon.structs import StatusFlag

    s = loop.state
    status = np.asarray(s["status"])
    gated = int(((status & int(StatusFlag.NOT_HOMED)) != 0).sum())
    silent = int(((status & int(StatusFlag.NO_REPLY)) != 0).sum())
    tripped = int(((status & int(StatusFlag.TRIPPED)) != 0).sum())
    st = loop.stats
    return (f"t {float(s['time_s']):7.1f} s  tick {st.ticks}  overruns {st.overruns}  "
            f"late max {st.max_late_ns / 1e6:.2f} ms  watchdog {'HOLD' if loop.holding else 'ok'}"
            f"  gated {gated}  pwm {int(np.sum(s['comply']))}  no-reply {silent}  "
            f"tripped {tripped}  cmds {st.cmds_done}/{st.cmds_refused} refused  "
            f"refs rejected {st.refs_rejected}  "
            f"{float(s['power']['V']):.1f} V")


def _single_instance(instance: str) -> socket.socket:
    """Hold an abstract socket named after the instance; it vanishes with the process."""
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    try:
        sock.bind(f"\0hubo-ladder/{instance}/daemon".encode())
    except OSError:
        sock.close()
        raise HuboLadderError(f"another hubo-daemon runs on instance {instance!r}; stop it "
                              "or pick another --instance") from None
    return sock


def _backend(args):
    if args.backend == "sim":
        from daemon.sim.backend import SimBackend
        from ladders.loader import load_ladder

        return SimBackend(load_ladder(args.ladder), args.robot, homed=args.homed), None
    from daemon.can.backend import CanBackend, parse_channels

    chans = parse_channels(args.channels)
    emu = None
    if args.emulate_boards:
        if args.can_interface != "virtual":
            raise InputError("--emulate-boards needs --can-interface virtual")
        from daemon.can.emulator import BoardEmulator
        from daemon.tables import load_joint_table, load_sensor_table

        emu = BoardEmulator(load_joint_table(), load_sensor_table(),
                            {0: chans[0], 1: chans[1]}).start()
        sys.setswitchinterval(0.0005)  # the emulator's threads share the GIL with the loop
    return CanBackend(args.can_interface, chans, bitrate=args.bitrate), emu


def _run(args: argparse.Namespace) -> int:
    from daemon.channels import cleanup_stale
    from daemon.loop import DaemonChannels, DaemonLoop, LoopConfig, set_realtime_priority
    from daemon.state_log import StateLogWriter

    config = LoopConfig(watchdog_s=args.watchdog_s)
    if not 0 <= args.rt_priority <= 99:
        raise InputError(f"--rt-priority {args.rt_priority}: allowed 0..99")
    lock = _single_instance(args.instance)
    removed = cleanup_stale(args.instance)
    if removed:
        log.warning("removed %d stale channel file(s) of instance %r", len(removed),
                    args.instance)
    backend, emu = _backend(args)
    channels = DaemonChannels.open(args.instance)
    state_log = None
    if args.log:
        try:
            state_log = StateLogWriter(args.log, meta={
                "backend": args.backend, "instance": args.instance, "robot": args.robot,
                "ladder": args.ladder if args.backend == "sim" else None,
                "rate_hz": config.rate_hz})
        except OSError as exc:
            raise InputError(f"--log {args.log}: {exc.strerror}") from None
    loop = DaemonLoop(backend, channels, config, state_log=state_log, robot=args.robot)
    if args.rt_priority:
        why = set_realtime_priority(args.rt_priority)
        if why:
            log.warning("no real-time priority (%s); running with normal scheduling", why)
    stop = threading.Event()

    def on_signal(signum, frame):
        stop.set()

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    on_status = (lambda lp: print(status_line(lp), file=sys.stderr, flush=True)) \
        if args.status else None
    print(f"hubo-daemon: {args.backend} backend on instance {args.instance!r}, "
          f"{config.rate_hz:g} Hz" + (f", log {args.log}" if args.log else ""),
          file=sys.stderr, flush=True)
    try:
        stats = loop.run(stop=stop, on_status=on_status)
    finally:
        if state_log is not None:
            state_log.close()
        backend.close()
        if emu is not None:
            emu.stop()
        channels.close()
        lock.close()
    print(f"hubo-daemon: stopped after {stats.ticks} ticks, {stats.overruns} overrun(s), "
          f"{stats.watchdog_trips} watchdog hold(s); boards hold the last reference",
          file=sys.stderr, flush=True)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``hubo-daemon``; returns the exit code."""
    args = _parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(name)s: %(message)s")
    return run_cli("hubo-daemon", lambda: _run(args))


if __name__ == "__main__":
    sys.exit(main())
