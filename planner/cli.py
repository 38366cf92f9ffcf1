"""``plan-ladder``: plan a climb and write it as a 40-column trajectory plus sidecar.

    plan-ladder LADDER [--robot drc-hubo|hubo2plus] [--seed N] [--rate HZ] [-o OUT.traj]
                [--time-limit S] [--resolution RAD] [--top-rung K] [--samples N]
                [--arm-strategy mixed|position] [--max-torque-ratio R]
                [--position-torque-share S] [--dwell S]
                [--plots DIR] [-v]

LADDER is a bundled ladder (``drc``, ``ship``, ``stair``) or a spec file. A progress
bar follows the primitives and rungs; a table summarises each primitive at the end.
The same seed gives the same trajectory file, byte for byte.

Exit codes: 0 a plan was written; 1 no plan: the ladder is out of the robot's reach
(``no plan: ladder '<name>' is out of the <robot>'s reach: <what, by how much>``, the
pre-check of `planner.reachability`, in well under a second), or the search stopped
(``no plan: <primitive> at rung <k> (<what it does>): <why the search stopped>``, then
that step's failed samples grouped by reason, in cm, degrees and torque ratios; ``-v``
adds the solver's figures), or the plan could not be timed within the joint limits;
2 bad input (the message names the file, field or option).
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import sys
import time
from pathlib import Path

from planner.holds import FOOT_COP_MARGIN_M, FOOT_FRICTION_SHARE, HELD_WRIST_MARGIN_RAD
from planner.statics.arm_capacity import DEFAULT_POSITION_TORQUE_SHARE
from robot.constants import DAEMON_RATE_HZ
from robot.errors import InputError, run_cli

__all__ = ["main"]

log = logging.getLogger("plan-ladder")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="plan-ladder", description=__doc__.split("\n\n")[0])
    p.add_argument("ladder", help="bundled ladder name (drc, ship, stair) or a spec file")
    p.add_argument("--robot", default="drc-hubo", choices=("drc-hubo", "hubo2plus"))
    p.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    p.add_argument("--rate", type=float, default=DAEMON_RATE_HZ, metavar="HZ",
                   help=f"trajectory file rate [Hz] (default {DAEMON_RATE_HZ:g})")
    p.add_argument("-o", "--out", metavar="OUT.traj",
                   help="trajectory file (default: LADDER-NAME.traj; OUT.traj.gz writes it "
                        "gzip-compressed); the sidecar OUT.plan.json goes next to it")
    p.add_argument("--time-limit", type=float, default=600.0, metavar="S",
                   help="give up planning after this long [s] (default 600)")
    p.add_argument("--resolution", type=float, default=0.01, metavar="RAD",
                   help="interpolation resolution [rad] (default 0.01)")
    p.add_argument("--top-rung", type=int, default=None, metavar="K",
                   help="climb until both feet stand on rung K (0-based; default: the "
                        "highest rung the hands can hold rails above)")
    p.add_argument("--samples", type=int, default=50, metavar="N",
                   help="samples per step before backtracking (default 50)")
    p.add_argument("--arm-strategy", default="mixed", choices=("mixed", "position"),
                   help="how the arms will be driven while their hands hold rails, which sets "
                        "the torque they can carry: mixed = PWM compliance (default), "
                        "position = rigid")
    p.add_argument("--max-torque-ratio", type=float, default=1.0, metavar="R",
                   help="largest planned joint torque as a share of its limit (default 1); "
                        "below 1 leaves a reserve for what open-loop playback does not "
                        "follow exactly")
    p.add_argument("--position-torque-share", type=float,
                   default=DEFAULT_POSITION_TORQUE_SHARE, metavar="S",
                   help="share of its torque limit a joint in position mode may be planned "
                        "to (default %(default)g): the legs take what the compliant arms "
                        "do not give")
    p.add_argument("--reserve-torque-share", type=float, default=None, metavar="S",
                   help="plan each step's first samples (--reserve-samples) with "
                        "position-mode joints at this share of their limits, the rest at "
                        "--position-torque-share (default: no reserve)")
    p.add_argument("--reserve-samples", type=int, default=10, metavar="N",
                   help="samples per step tried at --reserve-torque-share (default "
                        "%(default)s)")
    p.add_argument("--foot-cop-margin", type=float, default=FOOT_COP_MARGIN_M, metavar="M",
                   help="how far the feet's centre of pressure stays inside each sole's "
                        "support [m] (default %(default)g)")
    p.add_argument("--foot-friction-share", type=float, default=FOOT_FRICTION_SHARE,
                   metavar="S", help="share of the ladder's friction coefficient a foot is "
                                     "planned to use (default %(default)g)")
    p.add_argument("--held-wrist-margin", type=float, default=HELD_WRIST_MARGIN_RAD,
                   metavar="RAD", help="how far from zero a hand on its hold keeps its wrist "
                                       "pitch, the wrist's singularity [rad] (default "
                                       "%(default)g; 0: no bound)")
    p.add_argument("--dwell", type=float, default=0.5, metavar="S",
                   help="quasi-static hold after each step [s] (default 0.5)")
    p.add_argument("--plots", metavar="DIR", help="write the CoM/support-region plot of "
                                                  "each stance and a snapshot strip of the "
                                                  "plan (snapshots.png) into DIR")
    p.add_argument("-v", "--verbose", action="count", default=0,
                   help="log planner progress (-vv: every rejected sample)")
    return p


def _check_args(args: argparse.Namespace) -> None:
    for name, value, ok, rule in (
            ("--rate", args.rate, args.rate > 0, "> 0 Hz"),
            ("--time-limit", args.time_limit, args.time_limit > 0, "> 0 s"),
            ("--resolution", args.resolution, 0 < args.resolution <= 0.5, "in (0, 0.5] rad"),
            ("--samples", args.samples, args.samples >= 1, "≥ 1"),
            ("--dwell", args.dwell, args.dwell >= 0, "≥ 0 s"),
            ("--max-torque-ratio", args.max_torque_ratio, 0 < args.max_torque_ratio <= 1,
             "in (0, 1]"),
            ("--position-torque-share", args.position_torque_share,
             0 < args.position_torque_share <= 1, "in (0, 1]"),
            ("--reserve-torque-share", args.reserve_torque_share,
             args.reserve_torque_share is None
             or 0 < args.reserve_torque_share <= args.position_torque_share,
             "in (0, --position-torque-share]"),
            ("--reserve-samples", args.reserve_samples, args.reserve_samples >= 0, "≥ 0"),
            ("--foot-cop-margin", args.foot_cop_margin, 0 <= args.foot_cop_margin <= 0.04,
             "in [0, 0.04] m"),
            ("--foot-friction-share", args.foot_friction_share,
             0 < args.foot_friction_share <= 1, "in (0, 1]"),
            ("--held-wrist-margin", args.held_wrist_margin, 0 <= args.held_wrist_margin <= 0.5,
             "in [0, 0.5] rad")):
        if not ok:
            raise InputError(f"option {name} is {value:g}; it must be {rule}")


#: The search checks its time limit between samples; a sample can take seconds. The CLI


def _summary_table(result, total_s: float, out) -> object:
    from rich.table import Table

    t = Table(title=f"plan: {len(result.step_stats)} steps, search {result.total_s:.1f} s, "
                    f"total {total_s:.1f} s, {out.sidecar.line_count} lines "
                    f"({out.timed.duration_s:.1f} s of motion)")
    for col in ("primitive", "time [s]", "samples", "backtracks", "min margin [cm]",
                "max torque ratio"):
        t.add_column(col, justify="left" if col == "primitive" else "right")
    for st in result.step_stats:
        margin = f"{st.min_margin_m * 100:.1f}" if st.min_margin_m != float("inf") else "–"
        t.add_row(st.label, f"{st.seconds:.2f}", str(st.samples), str(st.backtracks), margin,
                  f"{st.max_torque_ratio:.2f}")
    m = out.sidecar.metrics
    clear = m.get("min_clearance_m")
    t.caption = (f"min clearance {clear * 100:.1f} cm" if clear is not None else
                 "min clearance not measured")
    if turn := m.get("max_held_palm_turn_rad"):
        t.caption += "; held palms turn on their rails up to " + ", ".join(
            f"{math.degrees(a):.1f}° ({side})" for side, a in turn.items())
    return t


def _write_plots(args: argparse.Namespace, result, planner, spec, out, err, on_output) -> None:
    """The stance plots and the snapshot strip into ``args.plots``."""
    from ladders.render import RenderingUnavailable
    from planner.plots import write_plan_strip, write_stance_plots

    on_output("stance plots", 0, 1)
    files = write_stance_plots(result, planner, args.plots)
    log.info("wrote %d stance plots into %s", len(files), args.plots)
    on_output("snapshot strip", 0, 1)
    try:
        strip = write_plan_strip(out.timed.configs, planner.kin, spec,
                                 Path(args.plots) / "snapshots.png", sidecar=out.sidecar)
        log.info("wrote %s", strip)
    except RenderingUnavailable as exc:
        err.print(f"plan-ladder: no snapshot strip: {exc}", markup=False)


def _plan(args: argparse.Namespace, err) -> int:
    from ladders.loader import load_ladder
    from planner.output import write_plan
    from planner.reachability import LadderOutOfReach
    from planner.search import ClimbPlanner, PlannerConfig, PlanningFailed
    from planner.time_limit import HARD_LIMIT_GRACE_S, TimeLimitExceeded, hard_time_limit
    from primitives.library import climb_sequence
    from robot.progress import ProgressReporter
    from robot.text_console import text_console

    t0 = time.perf_counter()
    spec = load_ladder(args.ladder)
    config = PlannerConfig(samples_per_step=args.samples, resolution_rad=args.resolution,
                           time_limit_s=args.time_limit, arm_strategy=args.arm_strategy,
                           max_torque_ratio=args.max_torque_ratio,
                           position_torque_share=args.position_torque_share,
                           reserve_torque_share=args.reserve_torque_share,
                           reserve_samples=args.reserve_samples,
                           foot_cop_margin_m=args.foot_cop_margin,
                           foot_friction_share=args.foot_friction_share,
                           held_wrist_margin_rad=args.held_wrist_margin)
    try:
        planner = ClimbPlanner(spec, robot=args.robot, config=config, seed=args.seed)
    except LadderOutOfReach as exc:
        err.print(f"no plan: {exc}", markup=False, highlight=False, soft_wrap=True)
        return 1
    top = planner.top_rung() if args.top_rung is None else args.top_rung
    if not 0 <= top < spec.num_rungs:
        raise InputError(f"option --top-rung is {top}; ladder '{spec.name}' has rungs "
                         f"0..{spec.num_rungs - 1}")
    steps = climb_sequence(top)
    out_path = Path(args.out) if args.out else Path(f"{spec.name}.traj")
    search = ProgressReporter("plan-ladder", "search: steps", len(steps), console=err)
    search.update(0, note=f"{steps[0].label} (rung 0 of {top})")
    def on_step(i: int, n: int, step, stats) -> None:
        nxt = steps[min(i + 1, n - 1)]
        search.update(i + 1, note=f"{nxt.label} (rung {nxt.rung} of {top})" if i + 1 < n
                      else "all steps found")
        log.info("%s done: %.2f s, %d samples, %d backtracks", step.label, stats.seconds,
                 stats.samples, stats.backtracks)

    try:
        with hard_time_limit(args.time_limit + HARD_LIMIT_GRACE_S):
            result = planner.plan(top_rung=top, progress=on_step)
    except (PlanningFailed, TimeLimitExceeded) as exc:
        search.finish("no plan")
        err.print(planner.no_plan_message(exc, args.time_limit),
                  markup=False, highlight=False, soft_wrap=True)
        return 1
    # Not "done": timing, checking and writing the plan may take minutes more.
    search.finish(f"{len(steps)} steps found, writing the plan")
    search_s = time.perf_counter() - t0
    with ProgressReporter("plan-ladder", "output", 1, console=err) as output:
        phase = [""]

        def on_output(name: str, done: int, total: int) -> None:
            output.update(done, total=total, note=name, restart=name != phase[0])
            phase[0] = name

        out = write_plan(result, planner, out_path, args.rate,
                         {"search_s": result.total_s, "setup_s": search_s - result.total_s},
                         dwell_s=args.dwell, progress=on_output)
        if args.plots:
            _write_plots(args, result, planner, spec, out, err, on_output)
    console = text_console()
    if not console.is_terminal:  # a log file or a pipe: keep each row on one line
        console = text_console(width=200)
    console.print(_summary_table(result, time.perf_counter() - t0, out))
    err.print(f"wrote {out.traj_path} and {out.sidecar_path}", highlight=False, soft_wrap=True)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``plan-ladder``; returns the exit code."""
    from rich.logging import RichHandler

    from robot.text_console import text_console

    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:  # argparse: --help (0) or a bad option (2)
        return int(exc.code or 0)
    if args.plots:
        os.environ.setdefault("MUJOCO_GL", "egl")  # headless, before mujoco is imported
    err = text_console(stderr=True)  # messages carry names and file:line:col verbatim
    level = (logging.WARNING, logging.INFO, logging.DEBUG)[min(args.verbose, 2)]
    logging.basicConfig(level=level, format="%(name)s: %(message)s",
                        handlers=[RichHandler(console=err, show_time=False)], force=True)
    if args.verbose == 0:
        # toppra warns about every path its LP solver finds numerically uncontrollable;
        # planner.timing retries and falls back on those and logs that itself (at INFO).
        logging.getLogger("toppra").setLevel(logging.ERROR)
    return run_cli("plan-ladder", lambda: _run(args, err))


def _run(args: argparse.Namespace, err) -> int:
    """Check the flags, plan, write the files; the exit code (1: no plan found)."""
    _check_args(args)
    return _plan(args, err)


if __name__ == "__main__":
    sys.exit(main())
