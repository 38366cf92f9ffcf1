"""``hubo-view``: a plan, or a validate-plan result, in 3D as a Rerun recording.

    hubo-view PLAN.traj[.gz] | RESULT.json | RUN.rrd [-o OUT.rrd | --serve [--web-port P]]
              [--open] [--screenshot PNG] [--at S]
              [--display-hz HZ] [--force-every S] [--no-statics] [-v]

Writes a recording file (default: beside the input, ``PLAN.plan.rrd`` or
``RESULT.rrd``) that opens in Rerun's viewer with no network: ``rerun OUT.rrd``, or on a
machine without a display ``rerun --serve-web OUT.rrd`` and a browser. ``--serve`` serves
the web viewer from this process instead. A simulated run's own recording (the robot as
simulated, beside the plan's ghost) is written by ``validate-plan --record R.rrd``.

``--open`` shows the recording (written, or given as RUN.rrd) in Rerun's viewer with the
time cursor at ``--at S``, by default at the failure of a failed run; ``--screenshot``
saves that view as a PNG from a headless viewer (`execute.view.viewer`).

Exit codes: 0 written, 2 bad input (the message names the file and what is wrong).
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

from robot.errors import InputError, run_cli

__all__ = ["default_output", "display_every_s", "main"]

log = logging.getLogger("hubo-view")

#: Display rates accepted [Hz] (the file's rate is the most there is to show).
DISPLAY_HZ_RANGE = (0.1, 200.0)
#: Hold-force spacings accepted [s].
FORCE_EVERY_RANGE_S = (0.005, 60.0)


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="hubo-view", description=__doc__.split("\n\n")[0])
    p.add_argument("input", help="a plan (PLAN.traj or PLAN.traj.gz, its PLAN.plan.json "
                                 "beside it), a validate-plan result (RESULT.json) or a "
                                 "recording (RUN.rrd) to --open")
    p.add_argument("-o", "--output", metavar="OUT.rrd",
                   help="the recording to write (default: beside the input)")
    p.add_argument("--serve", action="store_true",
                   help="serve Rerun's web viewer from this process instead of writing a "
                        "file (until Ctrl-C)")
    p.add_argument("--web-port", type=int, default=None, metavar="P",
                   help="the web viewer's HTTP port with --serve (default 9090)")
    p.add_argument("--open", action="store_true",
                   help="show the recording in Rerun's viewer, the cursor at --at (needs a "
                        "display)")
    p.add_argument("--screenshot", metavar="PNG",
                   help="save Rerun's view of the recording at --at as a PNG (a headless "
                        "viewer: needs a Vulkan driver)")
    p.add_argument("--at", type=float, default=None, metavar="S",
                   help="with --open or --screenshot: the time [s] to show (default: a "
                        "failed run's failure, else 0)")
    p.add_argument("--display-hz", type=float, default=20.0, metavar="HZ",
                   help="robot poses drawn per second of plan time (default 20; the data "
                        "is not thinned)")
    p.add_argument("--force-every", type=float, default=None, metavar="S",
                   help="planned hold forces every S seconds (default 0.5, at most 400 "
                        "lines a plan)")
    p.add_argument("--no-statics", action="store_true",
                   help="leave out support regions, stability margin and hold forces")
    p.add_argument("-v", "--verbose", action="store_true", help="log what is computed")
    return p


def _kind(path: Path) -> str:
    """``plan``, ``result`` or ``recording``, from the file's name."""
    name = path.name
    if name.endswith((".traj", ".traj.gz")):
        return "plan"
    if name.endswith(".rrd"):
        return "recording"
    if name.endswith(".json") and not name.endswith(".plan.json"):
        return "result"
    raise InputError(f"{path}: hubo-view reads a plan (PLAN.traj or PLAN.traj.gz, with its "
                     "PLAN.plan.json beside it), a validate-plan result (RESULT.json) or a "
                     "recording (RUN.rrd)")


def default_output(path: Path) -> Path:
    """``drc.traj.gz`` → ``drc.plan.rrd``; ``drc.result.json`` → ``drc.result.rrd``."""
    name = path.name
    for suffix in (".traj.gz", ".traj"):
        if name.endswith(suffix):
            return path.with_name(name.removesuffix(suffix) + ".plan.rrd")
    return path.with_name(name.removesuffix(".json") + ".rrd")


def display_every_s(flag: str, hz: float) -> float:
    """The spacing [s] of drawn robot poses for a display rate ``hz`` given as ``flag``;
    refused outside `DISPLAY_HZ_RANGE`."""
    lo, hi = DISPLAY_HZ_RANGE
    if not lo <= hz <= hi:
        raise InputError(f"{flag} {hz:g}: choose a rate within [{lo:g}, {hi:g}] Hz")
    return 1.0 / hz


def _layers(args: argparse.Namespace):
    from execute.view.plan_layers import PlanLayers
    from execute.view.plan_statics import FORCE_EVERY_S

    display_s = display_every_s("--display-hz", args.display_hz)
    every = FORCE_EVERY_S if args.force_every is None else args.force_every
    lo, hi = FORCE_EVERY_RANGE_S
    if not lo <= every <= hi:
        raise InputError(f"--force-every {every:g}: choose a spacing within [{lo:g}, "
                         f"{hi:g}] s")
    return PlanLayers(display_every_s=display_s, statics=not args.no_statics,
                      force_every_s=every)


def _check_viewing(args: argparse.Namespace, kind: str) -> None:
    """The options that show a recording: consistent, and in range."""
    if args.serve and (args.output or args.open or args.screenshot):
        raise InputError("--serve is its own viewer: leave out -o, --open and --screenshot")
    if kind == "recording" and not (args.open or args.screenshot):
        raise InputError(f"{args.input}: a recording is opened with --open or "
                         "--screenshot PNG (or: rerun FILE)")
    if kind == "recording" and args.output:
        raise InputError(f"{args.input}: a recording is already written; leave out -o")
    if args.at is not None and not 0.0 <= args.at < float("inf"):
        raise InputError(f"--at {args.at:g}: a time in seconds, 0 or more")
    if args.screenshot:
        shot = Path(args.screenshot)
        if shot.suffix != ".png" or not shot.parent.is_dir():
            raise InputError(f"{shot}: a screenshot is a .png file in a folder that exists")


def _write(args: argparse.Namespace, source: Path, kind: str) -> Path | None:
    """Log the input to its recording (a file, or the served viewer); the file."""
    from execute.view import output

    layers = _layers(args)
    start = time.perf_counter()
    out = None
    if args.serve:
        rec, address = output.serve(args.web_port or output.WEB_PORT)
    else:
        out = Path(args.output) if args.output else default_output(source)
        rec = output.open_file(out)
    if kind == "plan":
        from execute.view.plan_view import read_plan, record_plan

        record_plan(rec, read_plan(source), layers)
    else:
        from execute.view.result_view import record_result

        record_result(rec, source, layers)
    rec.flush()
    took = time.perf_counter() - start
    if out is not None:
        print(f"wrote {out} ({out.stat().st_size / 1e6:.1f} MB) in {took:.1f} s; open it "
              f"with: rerun {out}  (no display: rerun --serve-web {out}, then a browser)")
        return out
    print(f"serving the recording at {address} (logged in {took:.1f} s); Ctrl-C stops")
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        return None


def _run(args: argparse.Namespace) -> int:
    source = Path(args.input)
    kind = _kind(source)
    if not source.is_file():
        raise InputError(f"{source}: no such file")
    _check_viewing(args, kind)
    from execute.view.output import require_rerun

    require_rerun()  # before anything imports it: a one-line message, not a traceback
    out = source if kind == "recording" else _write(args, source, kind)
    if out is None or not (args.open or args.screenshot):
        return 0
    from execute.view.viewer import failure_time, open_in_viewer

    at = args.at if args.at is not None else failure_time(out)
    if args.screenshot:
        open_in_viewer(out, 0.0 if at is None else at, args.screenshot)
        print(f"wrote {args.screenshot}: Rerun's view of {out} at t = {at or 0.0:g} s")
    if args.open:
        open_in_viewer(out, at)
        print(f"opened {out} in Rerun's viewer" + ("" if at is None else f" at t = {at:g} s"))
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``hubo-view``; returns the exit code."""
    args = _parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(name)s: %(message)s")
    return run_cli("hubo-view", lambda: _run(args))


if __name__ == "__main__":
    sys.exit(main())
