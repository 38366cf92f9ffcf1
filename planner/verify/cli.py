"""``check-plan``: a kinematic verifier of a planned climb, independent of the planner.

    check-plan OUT.traj [--ladder L] [--robot R] [--rate HZ] [--every N]

It checks every line with `planner.verify.check.check_plan` (see there for the checks).
It prints the worst line of each check and exits 0 when all pass, 1 when one fails,
2 on bad input (the message names the file and the field or line).
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
from pathlib import Path

import numpy as np

from planner.verify.check import CheckResult, check_plan
from robot.errors import InputError, TrajectoryFileError, run_cli
from robot.plan_sidecar import PlanSidecar

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="check-plan", description=__doc__.split("\n\n")[0])
    p.add_argument("plan", help="the trajectory (OUT.traj or OUT.traj.gz); OUT.plan.json must "
                   "sit next to it")
    p.add_argument("--ladder", help="ladder name or spec file (default: the sidecar's)")
    p.add_argument("--robot", choices=("drc-hubo", "hubo2plus"),
                   help="robot (default: the sidecar's)")
    p.add_argument("--rate", type=float, metavar="HZ", help="file rate (default: the "
                   "sidecar's)")
    p.add_argument("--every", type=int, default=1, metavar="N",
                   help="check collisions and statics on every N-th line only (default 1: every "
                   "line; holds, limits and speed are always checked on every line)")
    return p


def _read(path: Path, rate_hz: float, robot: str) -> np.ndarray:
    """Read a trajectory once: joint values beyond the limits are read as they are (the
    joint-limit check reports them); format errors are bad input."""
    from robot.trajectory_file import read_trajectory

    try:
        return read_trajectory(path, rate_hz, robot, check_speed=False, check_limits=False)
    except TrajectoryFileError:
        pass
    # A malformed file: its error names every problem, values beyond the limits too.
    return read_trajectory(path, rate_hz, robot, check_speed=False)


def _ladder(args, sidecar: PlanSidecar, where: str):
    from ladders.loader import load_ladder, sidecar_ladder

    return load_ladder(args.ladder) if args.ladder else sidecar_ladder(sidecar, where)


def _verdict(r: CheckResult):
    """``pass`` in green, or ``FAIL (n lines)`` in red (styled text: never parsed as markup)."""
    from rich.text import Text

    if r.ok:
        return Text("pass", style="green")
    n = r.failing_lines
    return Text.assemble(("FAIL", "red"), f" ({n} line{'' if n == 1 else 's'})")


def _table(results: list[CheckResult], title: str):
    from rich.table import Table

    t = Table(title=title)
    for col in ("check", "result", "worst line", "value", "limit", "where"):
        t.add_column(col, justify="right" if col in ("worst line", "value", "limit") else "left")
    for r in results:
        t.add_row(r.name, _verdict(r), str(r.worst_line) if r.worst_line else "–",
                  f"{r.value:.4g} {r.unit}", f"{r.limit:g}", r.detail)
    return t


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``check-plan``; returns the exit code."""
    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:
        return int(exc.code or 0)
    # Messages carry file names, joint names and `file:line:col`: they are printed
    # verbatim (run_cli prints plain text; the table through text_console: no emoji codes
    # such as :100:, no markup, no highlighting).
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    return run_cli("check-plan", lambda: _check(args))


def _one_blas_thread() -> None:
    """Run numpy's OpenBLAS on one thread, unless ``OPENBLAS_NUM_THREADS`` says otherwise.

    check-plan's arrays are many small products. With OpenBLAS's default threads each of
    them waits for every core, and on a 2-core machine busy with a simulation the pass
    ran several times slower (a 46 × 6 by 6 × 12 product on 1,024 lines: 4.3 ms against
    0.34). numpy keeps its OpenBLAS in ``numpy.libs``; another BLAS, or none found, is
    left as it is.
    """
    import ctypes
    import glob

    if "OPENBLAS_NUM_THREADS" in os.environ:
        return
    libs = os.path.join(os.path.dirname(np.__file__), os.pardir, "numpy.libs", "*openblas*")
    for path in glob.glob(libs):
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for name in ("scipy_openblas_set_num_threads64_", "scipy_openblas_set_num_threads",
                     "openblas_set_num_threads64_", "openblas_set_num_threads"):
            setter = getattr(lib, name, None)
            if setter is not None:
                setter(1)
                return


def _check(args: argparse.Namespace) -> int:
    """Check the plan of ``args``, print the table; the exit code (1: a check fails)."""
    from robot.plan_sidecar import read_sidecar, sidecar_path
    from robot.progress import ProgressReporter
    from robot.text_console import text_console

    err = text_console(stderr=True)
    path = Path(args.plan)
    if args.every < 1:
        raise InputError(f"--every must be ≥ 1, got {args.every}")
    side = sidecar_path(path)
    if not side.exists():
        raise InputError(f"{path}: its sidecar {side} is missing")
    sidecar = read_sidecar(side)
    robot = args.robot or sidecar.robot
    rate = args.rate or sidecar.rate_hz
    spec = _ladder(args, sidecar, str(side))
    traj = _read(path, rate, robot)
    _one_blas_thread()
    with ProgressReporter("check-plan", "lines", len(traj)) as progress:
        results = check_plan(traj, sidecar, spec, robot, rate, args.every, str(path),
                             progress=lambda done, _n: progress.update(done))
    out = text_console()
    if not out.is_terminal:  # a log file or a pipe: keep each row on one line
        out = text_console(width=200)
    out.print(_table(results, f"check-plan {path} ({len(traj)} lines, {spec.name}, {robot})"))
    failed = [r for r in results if not r.ok]
    if failed:
        for r in failed:
            err.print(f"check-plan: {r.name} fails at line {r.worst_line}: {r.detail}",
                      soft_wrap=True)
        return 1
    err.print(f"check-plan: all {len(results)} checks pass")
    return 0


if __name__ == "__main__":
    sys.exit(main())
