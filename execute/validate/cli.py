"""``validate-plan``: play a plan in MuJoCo through the robot's own control code.

    validate-plan PLAN.traj [--ladder L] [--strategy mixed|position|pwm] [--battery V]
                  [--placement-error dx,dy,dyaw] [--json R.json] [--video V.mp4]
                  [--plots DIR] [--robot R] [--open-loop] [--max-reach-correction M]
                  [--grasp-retries N] [--holding-arm-stiffness S] [--record R.rrd]
                  [--record-hz HZ]

Reads ``PLAN.traj`` and its sidecar ``PLAN.plan.json`` (rate, holds, arm schedule,
ladder), runs `execute.validate.simulate.simulate`, prints the verdict and the metrics, and
writes the result JSON and artifacts asked for.

Exit codes: 0 the robot climbed, 1 it did not, 2 bad input (the message names the file
and line or the option).
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import sys
from pathlib import Path

from execute.motion.config import add_motion_arguments, motion_config_from_args
from robot.errors import InputError, run_cli
from robot.vocabulary import FailureCause

__all__ = ["ladder_from_sidecar", "main", "result_json"]

log = logging.getLogger("validate-plan")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="validate-plan", description=__doc__.split("\n\n")[0])
    p.add_argument("plan", help="the 40-column trajectory (PLAN.traj or PLAN.traj.gz); its sidecar "
                               "PLAN.plan.json must sit next to it")
    p.add_argument("--ladder", help="ladder name or spec file (default: the sidecar's)")
    p.add_argument("--strategy", default="mixed", choices=("mixed", "position", "pwm"),
                   help="arm modes: the sidecar's schedule, rigid, or compliant")
    p.add_argument("--battery", type=float, default=48.0, metavar="V",
                   help="battery voltage [V] (default 48)")
    p.add_argument("--placement-error", default="0,0,0", metavar="dx,dy,dyaw",
                   help="ladder misplacement [m, m, rad]")
    p.add_argument("--open-loop", action="store_true",
                   help="play the file as hubo-read-trajectory did, without the motion layer "
                        "(default: closed loop on the sensed state)")
    add_motion_arguments(p)
    p.add_argument("--json", metavar="R.json", help="write the result here")
    p.add_argument("--video", metavar="V.mp4", help="write an MP4 (needs EGL)")
    p.add_argument("--plots", metavar="DIR", help="write tracking plots and a snapshot strip")
    p.add_argument("--record", metavar="R.rrd",
                   help="write a Rerun recording of the run (the simulated robot beside the "
                        "plan's ghost, events, joint series): rerun R.rrd opens it "
                        "(docs/viewer.md)")
    p.add_argument("--record-hz", type=float, default=20.0, metavar="HZ",
                   help="with --record: robot poses drawn per simulated second, within "
                        "[0.1, 200] (default 20; a whole DRC climb is about 6 MB per Hz)")
    p.add_argument("--robot", default=None, help="robot (default: the sidecar's)")
    p.add_argument("-v", "--verbose", action="store_true", help="log events as they happen")
    return p


def ladder_from_sidecar(d: dict, where: str):
    """The ladder spec of a sidecar's field ``ladder``, by the spec's own rules."""
    from ladders.loader import ladder_from_mapping

    return ladder_from_mapping(d, where)


def motion_summary(report: dict) -> str:
    """One line on what the motion layer did."""
    counts = report["counts"]
    done = ", ".join(f"{n} {kind}" for kind, n in sorted(counts.items())) or "no correction"
    shift = [round(v * 100, 1) for v in report["ladder_shift_m"]]
    return f"motion layer: {done}; ladder estimated {shift} cm off the plan"


#: What to try next, by failure cause (`verdict_lines`).
NEXT_STEP = {
    FailureCause.BOARD_TRIP: "the plan loads that joint to its limit: check-plan's torque "
                             "ratio near that line; re-plan with a lower --max-torque-ratio "
                             "or another --seed",
    FailureCause.FALL: "the robot lost its balance: check-plan's stability margin near that "
                       "line; re-plan with a larger --foot-cop-margin or another --seed",
    FailureCause.HARD_CONTACT: "a body the plan keeps off the ladder hit it: check-plan's "
                               "collision check near that line; re-plan with another --seed",
    FailureCause.GRASP_NOT_LATCHED: "the hand missed its rail: the closed loop corrects "
                                    "reaches up to --max-reach-correction with "
                                    "--grasp-retries; see --plots snapshots at that time",
    FailureCause.GRASP_LOST: "the grip let go under its load: re-plan with another --seed or "
                             "--position-torque-share; the JSON's plan_vs_sim has the hold "
                             "forces",
    FailureCause.FINAL_STANCE: "the robot ended off its final holds: see --plots snapshots at "
                               "the end",
    FailureCause.GRASP_UNVERIFIED: "the motion layer stopped (the JSON's motion section says "
                                   "why); --open-loop plays the file as the thesis did",
    FailureCause.FOOTHOLD_UNVERIFIED: "a foot found no rung where the plan put it: check the "
                                      "ladder's rung heights against its spec",
    FailureCause.LADDER_MISPLACED: "the ladder stands elsewhere than the plan's: set the "
                                   "spec's placement to the one in the JSON's motion stop "
                                   "details and plan again (validate-plan --replan-beyond "
                                   "does this itself)",
}
#: The longest cause line printed; the full text is the JSON's ``why``.
CAUSE_CHARS = 160


def verdict_lines(run, metrics, sidecar) -> list[str]:
    """The printed verdict: a few short lines (verdict, cause, when and where, what to try
    next, key figures); `result_json` keeps the whole explanation."""
    v = run.verdict
    total = (sidecar.ladder.get("geometry") or {}).get("num_rungs")
    rungs = f"climbed {metrics.rungs_climbed}" + (f" of {total}" if total else "") + " rungs"
    turn = max(metrics.max_hand_turn_per_grasp_deg.values(), default=0.0)
    margin = metrics.min_com_margin_m
    figures = (f"figures: {rungs}; peak torque {metrics.peak_torque_ratio:.0%} of the limit "
               f"({metrics.peak_torque_joint}); largest hand turn on a rail {turn:.0f}° per "
               f"grasp; min CoM margin " + ("n/a" if margin is None else
                                           f"{margin * 100:.1f} cm at line "
                                           f"{metrics.min_com_margin_line}"))
    if v.climbed:
        held = len(v.final_holds)
        return ["verdict: climbed",
                f"holds:   every final hold in contact ({held} of {held})",
                f"time:    {run.simulated_s:.1f} s simulated, {metrics.lines_played:,} lines",
                figures]
    f = v.failure
    cause = f.why if len(f.why) <= CAUSE_CHARS else f.why[:CAUSE_CHARS - 1].rstrip() + "…"
    seg = sidecar.segment_at(min(max(f.line, 1), sidecar.line_count))
    return [f"verdict: failed ({f.cause})",
            f"cause:   {cause}",
            f"when:    t = {f.time_s:.2f} s, line {f.line:,} of {sidecar.line_count:,} "
            f"({seg.primitive}@rung{seg.rung}, {seg.phase} phase)",
            f"next:    {NEXT_STEP.get(f.cause, 'see the JSON (--json) for the full record')}",
            figures]


def _why(run, metrics, comparison=None) -> str:
    """A sentence from the physical quantities behind the outcome (and, for a failure,
    where the simulation had departed from the plan)."""
    v = run.verdict
    te = metrics.tracking_error_rad
    track = (f"tracking error left {te['left']:.4f} rad, right {te['right']:.4f} rad; peak "
             f"torque {metrics.peak_torque_ratio:.0%} of the limit at "
             f"{metrics.peak_torque_joint}")
    grips = "; ".join(str(g) for g in run.log.grasps) or "no grip events"
    if v.climbed:
        return f"every final hold in contact ({grips}); {track}"
    departed = "" if comparison is None else f"; {comparison.summary()}"
    return f"{v.failure.why} [{grips}]; {track}{departed}"


def result_json(run, metrics, plan_path: str, comparison=None) -> dict:
    """The result record written by ``--json``; ``comparison`` is the run's end against
    the plan (`execute.validate.plan_compare`), when computed."""
    v = run.verdict
    f = v.failure
    pe = run.options.placement
    return {
        "plan": plan_path,
        "verdict": "climbed" if v.climbed else "failed",
        "cause": None if f is None else f.cause.value,
        "time_s": run.simulated_s if f is None else f.time_s,
        "line": int(run.log.line_index[-1]) + 1 if f is None else f.line,
        "why": _why(run, metrics, comparison),
        "details": {} if f is None else f.details,
        "final_holds": v.final_holds,
        "strategy": run.options.strategy,
        "loop": "closed" if run.options.closed_loop else "open",
        "battery_v": run.options.board.battery_v,
        "placement_error": {"dx_m": pe.dx_m, "dy_m": pe.dy_m, "dyaw_rad": pe.dyaw_rad},
        "board_trips": [str(t) for t in run.log.trips],
        "grasp_events": [str(g) for g in run.log.grasps],
        "metrics": metrics.to_json(),
        "plan_vs_sim": None if comparison is None else comparison.to_json(),
        "motion": run.motion,
        "replan_beyond_m": (run.options.motion.replan_beyond_m if run.options.closed_loop
                            else None),
        "motion_settings": (run.options.motion.changed_settings() if run.options.closed_loop
                            else None),
        "replan": run.replan,
    }


def replan_summary(replan: dict) -> str:
    """One line on a re-plan after the first touch."""
    shift = [round(v * 100, 1) for v in replan["shift_m"][:2]]
    found = (f"the hands found the ladder shifted {shift} cm and turned "
             f"{math.degrees(replan['yaw_rad']):.1f}° (holds up to "
             f"{replan['worst_hold_m'] * 100:.1f} cm off)")
    if replan.get("no_plan"):
        return (f"re-planning after the first touch: {found}; the planner found no plan for "
                f"it in {replan['planning_s']:.0f} s: {replan['no_plan']}")
    return (f"re-planned after the first touch: {found}; planned again in "
            f"{replan['planning_s']:.0f} s; the run below is that plan's")


def _run(args: argparse.Namespace) -> int:
    from daemon.sim.board_model import BoardModelConfig, PlacementError
    from execute.validate.metrics import compute_metrics
    from execute.validate.plan_compare import compare_with_plan
    from execute.validate.simulate import SimulationOptions, simulate
    from execute.view.cli import display_every_s
    from ladders.loader import load_ladder
    from planner.verify.check import plan_verifier
    from robot.plan_sidecar import check_line_count, read_sidecar, sidecar_path
    from robot.progress import ProgressReporter
    from robot.trajectory_file import read_trajectory

    plan = Path(args.plan)
    record_every_s = display_every_s("--record-hz", args.record_hz)
    if args.record:
        from execute.view.output import check_output

        check_output(args.record)
    side = sidecar_path(plan)
    if not side.exists():
        raise InputError(f"{side}: no plan sidecar next to {plan}; validate-plan needs the "
                         "holds and arm schedule that plan-ladder writes")
    sidecar = read_sidecar(side)
    robot = args.robot or sidecar.robot
    traj = read_trajectory(plan, sidecar.rate_hz, robot)
    check_line_count(plan, len(traj), sidecar)
    ladder = load_ladder(args.ladder) if args.ladder else ladder_from_sidecar(
        sidecar.ladder, f"{side}: ladder")
    board_cfg = BoardModelConfig(battery_v=args.battery)
    opts = SimulationOptions(strategy=args.strategy,
                             placement=PlacementError.parse(args.placement_error),
                             board=board_cfg, closed_loop=not args.open_loop,
                             motion=motion_config_from_args(args))
    with ProgressReporter("validate-plan", "simulated s", len(traj) / sidecar.rate_hz,
                          show=lambda done, total: f"{done:.1f}/{total:.1f}") as progress:
        run = simulate(traj, sidecar, ladder, opts, robot,
                       progress=lambda sim_s, total_s: progress.update(sim_s, total=total_s))
    if run.replan is not None:  # the plan played: the new one, or the first if none was found
        traj, sidecar, ladder = run.trajectory_rad, run.sidecar, run.ladder
        print(replan_summary(run.replan), flush=True)
    metrics = compute_metrics(run)
    verifier = plan_verifier(sidecar, ladder, robot)  # one for every comparison below
    comparison = compare_with_plan(run, traj, ladder, verifier)
    result = result_json(run, metrics, str(plan), comparison)
    print("\n".join(verdict_lines(run, metrics, sidecar)))
    if run.motion is not None:
        print(motion_summary(run.motion))
    print(f"simulated {metrics.simulated_s:.2f} s at {metrics.real_time_factor:.1f}× real "
          f"time")
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1))
    if args.record:
        from execute.view.plan_layers import PlanLayers
        from execute.view.run_recording import write_run_recording

        layers = PlanLayers(display_every_s=record_every_s)
        print(f"wrote {write_run_recording(run, traj, ladder, args.record, layers, verifier)}")
    if args.plots or args.video:
        from execute.validate.artifacts import (
            RenderingUnavailable,
            write_plan_comparison_plot,
            write_snapshot_strip,
            write_tracking_plots,
            write_video,
        )
        try:
            if args.plots:
                for p in write_tracking_plots(run, args.plots):
                    print(f"wrote {p}")
                if comparison is not None:
                    path = write_plan_comparison_plot(run, comparison, traj, ladder,
                                                      Path(args.plots) / "plan_vs_sim.png",
                                                      verifier=verifier)
                    print(f"wrote {path}")
                print(f"wrote {write_snapshot_strip(run, Path(args.plots) / 'snapshots.png')}")
            if args.video:
                print(f"wrote {write_video(run, args.video)}")
        except RenderingUnavailable as exc:
            print(f"validate-plan: no rendering: {exc}", file=sys.stderr)
    return 0 if run.verdict.climbed else 1


def _joined_negative_values(argv: list[str]) -> list[str]:
    """``--placement-error -0.03,0,0`` as ``--placement-error=-0.03,0,0``: argparse takes
    a token that starts with '-' and is not a plain number for an option."""
    out: list[str] = []
    for token in argv:
        if out and out[-1] == "--placement-error" and token.startswith("-"):
            out[-1] = f"--placement-error={token}"
        else:
            out.append(token)
    return out


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``validate-plan``; returns the exit code."""
    parser = _parser()
    args = parser.parse_args(_joined_negative_values(sys.argv[1:] if argv is None else argv))
    if args.plots or args.video:
        os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is imported
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(name)s: %(message)s")
    return run_cli("validate-plan", lambda: _run(args))


if __name__ == "__main__":
    sys.exit(main())
