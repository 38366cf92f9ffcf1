"""``batch-eval``: success rates over ladders × seeds × strategies × perturbations.

    batch-eval [--ladders drc,ship,stair | --sweep SWEEP.yaml] [--seeds N] [--first-seed S]
               [--strategies mixed,position,pwm] [--loop closed,open] [--replan-beyond M]
               [--motion SETTING=V1,V2 ...]
               [--perturb KEY=V,...] [--draws D]
               [--engine local|dask] [--address tcp://host:8786] [--workers K]
               [--out DIR] [--plans-from DIR] [--time-limit S] [--top-rung K] [--robot R]
               [--rate HZ] [--max-jobs N] [--no-plots] [-v]

Per (ladder, seed) one plan (seeds S..S+N−1), then per strategy × loop × perturbation
draw one simulated climb of that plan (closed loop through the motion layer, open loop
as the file is; both loops of a strategy see the same draws; ``--motion`` repeats every
closed run per motion-layer setting, on the same draws) (`execute.batch.jobs`; perturbations:
`execute.batch.perturb`; sweeps: `execute.batch.sweep`). Jobs run on a local process
pool or a Dask cluster (`execute.batch.engine`). Every finished job is appended to
``DIR/results.jsonl``; running the same command again skips finished jobs and retries
errored ones. ``--plans-from`` takes the plans of an earlier batch's directory whose
inputs match instead of planning them again (`execute.batch.plan_reuse`). At the end:
the success table (printed, ``DIR/summary.csv``, ``DIR/summary.md``) and plots in
``DIR/plots``.

Exit codes: 0 every job has an outcome (climbs may have failed: that is the data); 1 some
jobs errored or the cluster failed; 2 bad input (the message names the flag or the file
and line); 130 interrupted (rerun to resume).
"""

from __future__ import annotations

import argparse
import itertools
import logging
import math
import os
import sys
import time
from pathlib import Path

from execute.motion.config import SETTINGS, MotionConfig, MotionConfigError, parse_setting
from robot.constants import DAEMON_RATE_HZ
from robot.errors import HuboLadderError, InputError, run_cli
from robot.vocabulary import ArmStrategy

__all__ = ["main", "parse_args"]

log = logging.getLogger("batch-eval")

STRATEGIES = tuple(ArmStrategy)
LOOPS = ("closed", "open")
MAX_SEEDS = 10_000
MAX_WORKERS = 256


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="batch-eval", description=__doc__.split("\n\n")[0])
    src = p.add_mutually_exclusive_group()
    src.add_argument("--ladders", default=None,
                     help="comma-separated bundled ladders or spec files (default drc)")
    src.add_argument("--sweep", metavar="SWEEP.yaml", help="a sweep file of ladder parameters")
    p.add_argument("--seeds", type=int, default=1, metavar="N",
                   help=f"plans per ladder, seeds S..S+N-1 (1..{MAX_SEEDS}, default 1)")
    p.add_argument("--first-seed", type=int, default=1, metavar="S", help="first seed (default 1)")
    p.add_argument("--strategies", default=",".join(STRATEGIES),
                   help="comma-separated arm strategies (default mixed,position,pwm)")
    p.add_argument("--loop", default="closed", metavar="closed,open",
                   help="play each plan through the motion layer (closed), as the file is "
                        "(open), or both, on the same perturbation draws (default closed)")
    p.add_argument("--replan-beyond", type=float, default=0.0, metavar="M",
                   help="closed loop: when the first two grasps find the plan's holds further "
                        "than M from the real ones, plan again for the ladder where the hands "
                        "found it and climb that plan (validate-plan --replan-beyond); within "
                        "[0, 0.2], 0 never (default 0)")
    p.add_argument("--motion", action="append", default=[], metavar="SETTING=V1,V2",
                   help="closed loop: run each closed run once per value of this motion-layer "
                        "setting (a MotionConfig field, e.g. grip_bending_onset=0,0.35); "
                        "repeat the flag to cross settings; every variant sees the same "
                        "draws and gets its own row")
    p.add_argument("--perturb", default="", metavar="KEY=V,...",
                   help="placement=M,yaw=RAD,rung=M,friction=LO:HI,battery=LO:HI")
    p.add_argument("--draws", type=int, default=1, metavar="D",
                   help="perturbation draws per plan and strategy (default 1)")
    p.add_argument("--engine", default="local", help="local (process pool) or dask")
    p.add_argument("--address", metavar="tcp://HOST:PORT",
                   help="Dask scheduler (--engine dask; default: start a LocalCluster)")
    p.add_argument("--workers", type=int, default=None, metavar="K",
                   help="worker processes (default: the CPU count)")
    p.add_argument("--out", default="batch-out", metavar="DIR", help="output directory")
    p.add_argument("--plans-from", metavar="DIR", default=None,
                   help="take the plans of an earlier batch's output directory whose inputs "
                        "match (ladder, seed, robot, time limit, top rung, rate) instead of "
                        "planning them again")
    p.add_argument("--time-limit", type=float, default=600.0, metavar="S",
                   help="planning time limit per plan [s] (default 600)")
    p.add_argument("--top-rung", type=int, default=None, metavar="K",
                   help="climb until both feet are on rung K (default: the highest)")
    p.add_argument("--robot", default="drc-hubo", help="drc-hubo or hubo2plus")
    p.add_argument("--rate", type=float, default=DAEMON_RATE_HZ, metavar="HZ",
                   help=f"trajectory rate [Hz] (default {DAEMON_RATE_HZ:g})")
    p.add_argument("--max-jobs", type=int, default=None, metavar="N",
                   help="run at most N jobs now, then stop (resume later)")
    p.add_argument("--no-plots", action="store_true", help="skip the plots")
    p.add_argument("-v", "--verbose", action="store_true", help="log job errors as they happen")
    return p


def _split(flag: str, text: str) -> list[str]:
    items = [t.strip() for t in text.split(",") if t.strip()]
    if not items:
        raise InputError(f"option {flag} is empty")
    dup = sorted({t for t in items if items.count(t) > 1})
    if dup:
        raise InputError(f"option {flag}: {', '.join(dup)} given twice")
    return items


def parse_args(argv: list[str] | None = None) -> dict:
    """Parse and validate every option up front.

    Returns:
        A dict with ``ladders`` ([(key, spec, sweep values)]), ``seeds``, ``strategies``,
        ``loops``, ``replan_beyond_m``, ``motion_variants`` (`_motion_variants`),
        ``perturb`` (`PerturbSpec`), ``draws``,
        ``engine``, ``address``, ``workers``, ``out``, ``plans_from``, ``time_limit_s``,
        ``top_rung``, ``robot``, ``rate_hz``, ``max_jobs``, ``plots``, ``verbose``.

    Raises:
        InputError: naming the option or ``FILE:LINE`` and the allowed values.
        SystemExit: argparse's own errors (exit 2) and ``--help`` (exit 0).
    """
    from execute.batch.perturb import parse_perturb
    from execute.batch.runner import RESULTS_FILE

    a = _parser().parse_args(argv)
    _check_scalar_options(a)
    strategies = _split("--strategies", a.strategies)
    bad = [s for s in strategies if s not in STRATEGIES]
    if bad:
        raise InputError(f"option --strategies: {', '.join(bad)} unknown; choose from "
                         f"{', '.join(STRATEGIES)}")
    loops = _split("--loop", a.loop)
    bad = [x for x in loops if x not in LOOPS]
    if bad or len(set(loops)) != len(loops):
        raise InputError(f"option --loop is {a.loop!r}; give closed, open or closed,open")
    if a.replan_beyond and "closed" not in loops:
        raise InputError(f"option --replan-beyond is {a.replan_beyond:g}, but --loop is "
                         f"{a.loop!r}: only closed-loop runs plan again")
    motion_variants = _motion_variants(a.motion)
    if a.motion and "closed" not in loops:
        raise InputError(f"option --motion is given, but --loop is {a.loop!r}: the motion "
                         "layer runs in closed loop only")
    perturb = parse_perturb(a.perturb)
    if a.draws > 1 and not perturb:
        raise InputError(f"option --draws is {a.draws}, but there is no --perturb: every draw "
                         "would be the same simulation")
    ladders = _batch_ladders(a)
    for key, spec, _ in ladders:
        perturb.check_ladder(spec)
        if a.top_rung is not None and a.top_rung >= spec.num_rungs:
            raise InputError(f"option --top-rung is {a.top_rung}; ladder '{key}' has rungs "
                             f"0..{spec.num_rungs - 1}")
    if a.plans_from is not None and not (Path(a.plans_from) / RESULTS_FILE).is_file():
        raise InputError(f"option --plans-from: {a.plans_from} holds no {RESULTS_FILE} "
                         "(give the --out directory of an earlier batch-eval run)")
    workers = a.workers or os.cpu_count() or 1
    return {"ladders": ladders, "seeds": list(range(a.first_seed, a.first_seed + a.seeds)),
            "strategies": strategies, "loops": loops, "replan_beyond_m": a.replan_beyond,
            "motion_variants": motion_variants,
            "perturb": perturb, "draws": a.draws,
            "engine": a.engine, "address": a.address, "workers": workers, "out": Path(a.out),
            "plans_from": None if a.plans_from is None else Path(a.plans_from),
            "time_limit_s": a.time_limit, "top_rung": a.top_rung, "robot": a.robot,
            "rate_hz": a.rate, "max_jobs": a.max_jobs, "plots": not a.no_plots,
            "verbose": a.verbose}


#: The motion-layer settings ``--motion`` varies: all but ``replan_beyond_m``, whose own
#: flag also plans again.
_MOTION_FLAG_SETTINGS = tuple(s for s in SETTINGS if s != "replan_beyond_m")


def _motion_variants(flags: list[str]) -> list[tuple[tuple[str, object], ...]]:
    """Every combination of the ``--motion SETTING=V1,V2`` flags' values, in flag order
    (one empty variant when none is given)."""
    axes: list[list[tuple[str, object]]] = []
    names: list[str] = []
    for flag in flags:
        name, eq, values = flag.partition("=")
        name = name.strip()
        if not eq or not values.strip():
            raise InputError(f"option --motion {flag!r}: give SETTING=V1,V2 (settings: "
                             f"{', '.join(_MOTION_FLAG_SETTINGS)})")
        if name == "replan_beyond_m":
            raise InputError("option --motion replan_beyond_m: use --replan-beyond, which "
                             "also plans again")
        if name in names:
            raise InputError(f"option --motion: {name} given twice; list its values in one "
                             "flag")
        names.append(name)
        try:
            axes.append([(name, parse_setting(name, v))
                         for v in _split(f"--motion {name}", values)])
        except InputError as exc:
            raise InputError(f"option --motion: {exc}") from None
    return list(itertools.product(*axes))


def _check_scalar_options(a: argparse.Namespace) -> None:
    """The numeric options against their ranges, then --engine, --address and --robot."""
    for name, value, ok, rule in (
            ("--seeds", a.seeds, 1 <= a.seeds <= MAX_SEEDS, f"in [1, {MAX_SEEDS}]"),
            ("--first-seed", a.first_seed, 0 <= a.first_seed < 2**31, "in [0, 2^31)"),
            ("--draws", a.draws, 1 <= a.draws <= 1000, "in [1, 1000]"),
            ("--time-limit", a.time_limit, math.isfinite(a.time_limit) and a.time_limit > 0,
             "> 0 s"),
            ("--rate", a.rate, math.isfinite(a.rate) and 1 <= a.rate <= 1000,
             "in [1, 1000] Hz"),
            ("--workers", a.workers, a.workers is None or 1 <= a.workers <= MAX_WORKERS,
             f"in [1, {MAX_WORKERS}]"),
            ("--max-jobs", a.max_jobs, a.max_jobs is None or a.max_jobs >= 1, "≥ 1"),
            ("--top-rung", a.top_rung, a.top_rung is None or a.top_rung >= 0, "≥ 0")):
        if not ok:
            raise InputError(f"option {name} is {value:g}; it must be {rule}")
    try:
        MotionConfig(replan_beyond_m=a.replan_beyond)
    except MotionConfigError as exc:
        raise InputError(f"option --replan-beyond: {exc}") from None
    if a.engine not in ("local", "dask"):
        raise InputError(f"option --engine is {a.engine!r}; choose local or dask")
    if a.address is not None:
        if a.engine != "dask":
            raise InputError("option --address needs --engine dask")
        if "://" not in a.address:
            raise InputError(f"option --address is {a.address!r}; expected a scheduler "
                             "address like tcp://host:8786")
    if a.robot not in ("drc-hubo", "hubo2plus"):
        raise InputError(f"option --robot is {a.robot!r}; choose drc-hubo or hubo2plus")


def _batch_ladders(a: argparse.Namespace) -> list[tuple[str, object, dict]]:
    """The batch's ladders as (key, spec, swept values): a sweep's cells, or the
    --ladders list (each key once)."""
    from ladders.loader import load_ladder

    if a.sweep:
        from execute.batch.sweep import load_sweep

        return [(c.name, c.spec, c.params) for c in load_sweep(a.sweep)]
    ladders: list[tuple[str, object, dict]] = []
    for name in _split("--ladders", a.ladders or "drc"):
        try:
            spec = load_ladder(name)
        except InputError as exc:
            raise InputError(f"option --ladders: {exc}") from None
        key = name if spec.name == name else spec.name
        if any(k == key for k, _, _ in ladders):
            raise InputError(f"option --ladders: two ladders are named '{key}'")
        ladders.append((key, spec, {}))
    return ladders


def run(opts: dict, console, err, functions=None, engine=None) -> int:
    """Run a parsed batch (see `parse_args`) and write its reports; returns the exit code.

    Args:
        opts: parsed options.
        console: rich console for the tables (stdout).
        err: rich console for progress and messages (stderr).
        functions: job functions (`execute.batch.jobs.JobFunctions`; default the real ones).
        engine: an engine to use instead of opening ``opts['engine']`` (tests).
    """
    from execute.batch.jobs import expand_jobs
    from execute.batch.runner import RESULTS_FILE

    plans, validations = expand_jobs(opts["ladders"], opts["seeds"], opts["strategies"],
                                     opts["perturb"], opts["draws"], robot=opts["robot"],
                                     time_limit_s=opts["time_limit_s"],
                                     top_rung=opts["top_rung"], rate_hz=opts["rate_hz"],
                                     loops=opts["loops"],
                                     replan_beyond_m=opts.get("replan_beyond_m", 0.0),
                                     motion_variants=opts.get("motion_variants", [()]))
    out: Path = opts["out"]
    out.mkdir(parents=True, exist_ok=True)
    if opts.get("plans_from") is not None:
        from execute.batch.plan_reuse import reuse_plans

        taken = reuse_plans(plans, opts["plans_from"], out, RESULTS_FILE)
        err.print(f"batch-eval: took {taken} of {len(plans)} plan(s) from "
                  f"{opts['plans_from']}", highlight=False)
    t0 = time.perf_counter()
    batch = _run_with_progress(plans, validations, opts, err, functions, engine)
    files = _write_reports(batch, plans, validations, opts, console)
    wall = time.perf_counter() - t0
    err.print(f"ran {batch.ran} job(s), skipped {batch.skipped} finished, in {wall:.1f} s; "
              f"wrote {', '.join(str(f) for f in files)}", highlight=False, soft_wrap=True)
    missing = len(plans) + len(validations) - len(batch.records)
    if missing:
        err.print(f"{missing} job(s) not run yet; run the same command again to continue",
                  highlight=False)
    if batch.errors:
        err.print(f"{len(batch.errors)} job(s) errored (recorded in {out / RESULTS_FILE}); "
                  f"first: {batch.errors[0]['key']}: {batch.errors[0].get('error')}",
                  markup=False, highlight=False, soft_wrap=True)
        return 1
    return 0


def _run_with_progress(plans, validations, opts: dict, err, functions, engine):
    """`execute.batch.runner.run_batch` on the engine (opened here unless given), with a
    progress bar on ``err``; an engine opened here is closed, cancelling queued jobs if
    the run is interrupted."""
    from execute.batch.engine import open_engine
    from execute.batch.jobs import DEFAULT_JOB_FUNCTIONS
    from execute.batch.runner import RESULTS_FILE, run_batch
    from robot.progress import ProgressReporter

    out: Path = opts["out"]
    eng = engine if engine is not None else open_engine(opts["engine"], opts["workers"],
                                                        opts["address"])
    err.print(f"batch-eval: {len(plans)} plan and {len(validations)} validate jobs on "
              f"{eng.description}; results in {out / RESULTS_FILE}", highlight=False)
    with ProgressReporter("batch-eval", "jobs", 0, console=err) as progress:
        def on_start(total: int, skipped: int) -> None:
            if skipped:
                err.print(f"resuming: {skipped} job(s) already finished, {total} to run",
                          highlight=False)
            progress.update(0, total=total, restart=True)

        def on_record(rec: dict) -> None:
            status = rec.get("outcome") if rec["status"] == "ok" else "error"
            progress.update(progress.done + 1, note=f"last: {rec['key']} {status}")

        try:
            batch = run_batch(plans, validations, out, eng,
                              functions=functions or DEFAULT_JOB_FUNCTIONS,
                              on_start=on_start, on_record=on_record,
                              max_jobs=opts["max_jobs"])
        except BaseException:
            if engine is None:  # interrupted: drop queued jobs, do not wait for them
                eng.close(cancel=True)
            raise
        if engine is None:
            eng.close()
    return batch


def _write_reports(batch, plans, validations, opts: dict, console) -> list[Path]:
    """The success table: printed, ``summary.csv``, ``summary.md`` and (unless
    ``--no-plots``) the plots; returns the files written."""
    from execute.batch.report import (
        print_summary,
        summarize_records,
        write_csv,
        write_markdown,
    )

    out: Path = opts["out"]
    expected: dict[tuple[str, str], int] = {}
    for v in validations:
        k = (v.plan.ladder_key, v.label)
        expected[k] = expected.get(k, 0) + 1
    expected_plans: dict[str, int] = {}
    for p in plans:
        expected_plans[p.ladder_key] = expected_plans.get(p.ladder_key, 0) + 1
    labels = list(dict.fromkeys(v.label for v in validations))  # strategy, loop, variant
    summary = summarize_records(batch.records, {k: s for k, s, _ in opts["ladders"]},
                                labels, expected, expected_plans)
    print_summary(summary, console)
    files = [write_csv(summary, out / "summary.csv"), write_markdown(summary, out / "summary.md")]
    if opts["plots"]:
        from execute.batch.plots import write_plots

        files += write_plots(summary, out / "plots")
    return files


class BatchSetupError(HuboLadderError):
    """The batch could not run: an optional dependency is missing (Dask) or a file
    cannot be read or written."""


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``batch-eval``; returns the exit code."""
    return run_cli("batch-eval", lambda: _main(argv))


def _main(argv: list[str] | None) -> int:
    from rich.console import Console

    from robot.text_console import text_console

    err = text_console(stderr=True)  # messages carry file names and file:line:col verbatim
    try:
        opts = parse_args(argv)
    except SystemExit as exc:  # argparse: --help (0) or a bad option (2)
        return int(exc.code or 0)
    logging.basicConfig(level=logging.INFO if opts["verbose"] else logging.WARNING,
                        format="%(name)s: %(message)s", force=True)
    console = Console()
    if not console.is_terminal:  # a log file or a pipe: keep each row on one line
        console = Console(width=220)
    try:
        return run(opts, console, err)
    except KeyboardInterrupt:
        err.print(f"batch-eval: interrupted; finished jobs are in {opts['out']}/results.jsonl, "
                  "run the same command again to resume", highlight=False)
        return 130
    except (ImportError, OSError) as exc:
        raise BatchSetupError(str(exc)) from exc

if __name__ == "__main__":
    sys.exit(main())
