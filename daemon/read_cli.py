"""``hubo-read``: a live view of the daemon's state, and a state log.

    hubo-read [--instance NAME] [--joints RSP,LSP,...] [--log FILE] [--duration S]
              [--refresh HZ] [--once]

The table (rich) shows per joint the sent reference, position, error, velocity, current,
duty, compliance, homing and status flags, and above it the tick, overruns, FT sensors,
IMU and power; it refreshes ``--refresh`` times a second. ``--log FILE`` records every
state sample the daemon publishes (`daemon.state_log` format, ``STATE_DTYPE`` records;
`daemon.state_log.read_state_log` reads it). ``--once`` prints one table and exits.

Exit codes: 0 done (Ctrl-C ends a live view), 1 no daemon, 2 bad input.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from robot.errors import HuboLadderError, InputError, run_cli

__all__ = ["main", "state_table"]


def state_table(s: np.ndarray, joints: list[int]):
    """A rich Table of one state sample."""
    from rich.table import Table

    from daemon.structs import FT_NAMES, IMU_NAMES, StatusFlag
    from robot.joints import JOINT_NAMES

    ft = "  ".join(f"{n} {s['ft'][k]['fz']:+.0f} N" for k, n in enumerate(FT_NAMES))
    imu = s["imu"][0]
    title = (f"tick {int(s['tick'])}  t {float(s['time_s']):.2f} s  overruns "
             f"{int(s['overruns'])}  refs rejected {int(s['refs_rejected'])}  "
             f"power {float(s['power']['V']):.1f} V "
             f"{float(s['power']['I']):.1f} A\n{ft}  {IMU_NAMES[0]} a "
             f"({imu['ax']:+.2f}, {imu['ay']:+.2f}, {imu['az']:+.2f}) m/s²")
    t = Table(title=title, title_justify="left")
    for col in ("joint", "ref [rad]", "pos [rad]", "err [rad]", "vel [rad/s]", "cur [A]",
                "duty [%]", "pwm", "zeroed", "status"):
        t.add_column(col, justify="left" if col in ("joint", "status") else "right")
    for j in joints:
        flags = StatusFlag(int(s["status"][j]))
        names = " ".join(f.name for f in StatusFlag if f and f in flags) or "ok"
        t.add_row(JOINT_NAMES[j], f"{s['ref'][j]:+.4f}", f"{s['pos'][j]:+.4f}",
                  f"{s['ref'][j] - s['pos'][j]:+.4f}", f"{s['vel'][j]:+.3f}",
                  f"{s['cur'][j]:.2f}", f"{s['duty'][j]:+.1f}", str(int(s["comply"][j])),
                  str(int(s["zeroed"][j])), names)
    return t


def _joints(text: str | None) -> list[int]:
    from robot.joints import JOINT_INDEX, JOINT_NAMES

    if not text:
        return list(range(len(JOINT_NAMES)))
    out = []
    for name in text.split(","):
        if name.strip().upper() not in JOINT_INDEX:
            raise InputError(f"--joints: unknown joint {name!r}; valid: {' '.join(JOINT_NAMES)}")
        out.append(JOINT_INDEX[name.strip().upper()])
    return out


def _run(args) -> int:
    from rich.live import Live

    from daemon.channels import open_channel
    from daemon.state_log import StateLogWriter
    from daemon.structs import STATE_DTYPE
    from robot.text_console import text_console

    joints = _joints(args.joints)
    if not args.refresh > 0:
        raise InputError(f"--refresh {args.refresh}: must be > 0 [Hz]")
    state = open_channel("state", args.instance)
    s = state.wait_newer(0, 2.0)
    if s is None or time.monotonic_ns() - int(s["time_ns"]) > 500_000_000:
        state.close()
        raise HuboLadderError(f"no hubo-daemon is ticking on instance {args.instance!r}")
    console = text_console()
    if args.once:
        console.print(state_table(s, joints))
        state.close()
        return 0
    writer = None
    if args.log:
        try:
            writer = StateLogWriter(args.log, STATE_DTYPE, meta={"instance": args.instance,
                                                                  "source": "hubo-read"})
        except OSError as exc:
            raise InputError(f"--log {args.log}: {exc.strerror}") from None
    end = time.monotonic() + args.duration if args.duration else float("inf")
    period = 1.0 / args.refresh
    next_draw = 0.0
    try:
        with Live(state_table(s, joints), console=console, auto_refresh=False) as live:
            while time.monotonic() < end:
                new = state.wait_newer(int(s["time_ns"]), 0.5)
                if new is None:
                    continue
                s = new
                if writer is not None:
                    writer.append(s)
                if time.monotonic() >= next_draw:
                    next_draw = time.monotonic() + period
                    live.update(state_table(s, joints), refresh=True)
    except KeyboardInterrupt:
        pass
    finally:
        if writer is not None:
            writer.close()
        state.close()
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``hubo-read``; returns the exit code."""
    p = argparse.ArgumentParser(prog="hubo-read", description=__doc__.split("\n\n")[0])
    p.add_argument("--instance", default="default", help="daemon instance (default)")
    p.add_argument("--joints", help="comma-separated joints to show (default: all 40)")
    p.add_argument("--log", metavar="FILE", help="record every state sample here")
    p.add_argument("--duration", type=float, metavar="S", help="stop after S seconds")
    p.add_argument("--refresh", type=float, default=5.0, metavar="HZ",
                   help="table refresh rate (default 5 Hz)")
    p.add_argument("--once", action="store_true", help="print one table and exit")
    args = p.parse_args(argv)
    return run_cli("hubo-read", lambda: _run(args))


if __name__ == "__main__":
    sys.exit(main())
