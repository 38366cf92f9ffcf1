"""Batch jobs: what one plan or one validation is, how a batch expands into them, and
the job functions that run them (module-level, so process pools and Dask can ship them).

Per (ladder, seed) there is one **plan** job; per (ladder, seed, strategy, draw index)
one **validate** job that plays that plan in simulation under its drawn perturbation
(`execute.batch.perturb`). Every job carries everything it needs (ladder spec, seed,
draw), so jobs run in any order on any worker; a validate job only needs its plan's
files, which the plan job writes under ``OUT/plans/`` (with a remote Dask cluster,
``OUT`` must be on a filesystem the workers share).

A job function returns a JSON-able dict, the job's *outcome*:

- plan: ``outcome`` ``planned`` (``traj``, ``plan_s``, ``motion_s``, ``top_rung``) or
  ``no_plan`` (``cause`` ``no_plan``; ``why``: plan-ladder's ``no plan: ...`` message,
  the reach pre-check's refusal or the deepest step reached and its reasons in user
  terms, or the timing error; its validate jobs carry the same ``why``;
  ``search_reason``: the search's own text, with the solver's figures);
- validate: ``outcome`` ``climbed`` or ``failed`` with ``cause`` and ``why`` from
  `execute.validate.verdict`, the simulated time and the metrics of
  `execute.validate.metrics`; the whole `execute.validate.cli.result_json` record is kept
  under ``result``.

Exceptions are not caught here: the runner records them as the job's error.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from execute.batch.perturb import Draw, PerturbSpec, draw
from ladders.spec import LadderSpec
from planner.time_limit import HARD_LIMIT_GRACE_S, TimeLimitExceeded, hard_time_limit
from robot.constants import DAEMON_RATE_HZ
from robot.vocabulary import FailureCause

__all__ = ["DEFAULT_JOB_FUNCTIONS", "HARD_LIMIT_GRACE_S", "JobFunctions", "PlanJob",
           "ValidateJob", "expand_jobs", "plan_job", "validate_job"]

#: The start of a plan job's outcome when it found no plan.
_NO_PLAN = {"outcome": "no_plan", "cause": FailureCause.NO_PLAN.value}


def _fingerprint(obj: dict) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]


@dataclass(frozen=True)
class PlanJob:
    """Plan one climb.

    Attributes:
        ladder_key: the ladder's key in tables (bundled name or sweep-cell name).
        ladder: the ladder spec.
        seed: planner seed.
        robot: robot name.
        time_limit_s: planning time limit [s].
        top_rung: climb until both feet are on this rung (None: the planner's highest).
        rate_hz: trajectory rate [Hz].
        sweep: swept (field, value) pairs of the ladder's sweep cell (empty: no sweep).
    """

    ladder_key: str
    ladder: LadderSpec
    seed: int
    robot: str = "drc-hubo"
    time_limit_s: float = 600.0
    top_rung: int | None = None
    rate_hz: float = DAEMON_RATE_HZ
    sweep: tuple[tuple[str, Any], ...] = ()

    kind = "plan"

    @property
    def key(self) -> str:
        """Readable unique id within a batch."""
        return f"plan/{self.ladder_key}/s{self.seed}"

    @property
    def fingerprint(self) -> str:
        """Hash of every input: a record counts as this job's only if it matches. A part
        the ladder does not have (its landing: None fields) is left out, so that a batch
        made before the spec had that part still resumes."""
        ladder = {k: v for k, v in dataclasses.asdict(self.ladder).items() if v is not None}
        return _fingerprint({"kind": "plan", "ladder": ladder,
                             "seed": self.seed, "robot": self.robot,
                             "time_limit_s": self.time_limit_s, "top_rung": self.top_rung,
                             "rate_hz": self.rate_hz})

    @property
    def traj_name(self) -> str:
        """The trajectory's path relative to the output directory."""
        return f"plans/{self.ladder_key}-s{self.seed}-{self.fingerprint[:8]}.traj"

    def describe(self) -> dict:
        """The job's identity fields of a results record."""
        return {"key": self.key, "fingerprint": self.fingerprint, "kind": self.kind,
                "ladder": self.ladder_key, "seed": self.seed, "sweep": dict(self.sweep)}


@dataclass(frozen=True)
class ValidateJob:
    """Play a plan in simulation with one strategy under one drawn perturbation.

    Attributes:
        plan: the plan job this depends on.
        strategy: ``mixed``, ``position`` or ``pwm``.
        draw_index: index of the perturbation draw (0-based).
        draw: the drawn perturbation (the same for both loops: runs pair up).
        loop: ``closed`` (through the motion layer) or ``open`` (the file as it is).
        replan_beyond_m: closed loop: plan again after the first two grasps when they find
            a hold further than this from the plan's [m] (`MotionConfig.replan_beyond_m`;
            0 never).
        motion: closed loop: (field, value) settings of the motion layer that this run
            sets (`batch-eval --motion`), in name order; the others keep their defaults.
    """

    plan: PlanJob
    strategy: str
    draw_index: int
    draw: Draw
    loop: str = "closed"
    replan_beyond_m: float = 0.0
    motion: tuple[tuple[str, Any], ...] = ()

    kind = "validate"

    @property
    def key(self) -> str:
        settings = "".join(f"/{name}={value}" for name, value in self.motion)
        return f"validate/{self.plan.ladder_key}/s{self.plan.seed}/{self.strategy}/" \
               f"{self.loop}{settings}/d{self.draw_index}"

    @property
    def fingerprint(self) -> str:
        identity = {"kind": "validate", "plan": self.plan.fingerprint,
                    "strategy": self.strategy, "loop": self.loop, "draw": self.draw.to_json()}
        # each option is absent when unused, so batches from before it still resume
        if self.replans:
            identity["replan_beyond_m"] = self.replan_beyond_m
        if self.motion:
            identity["motion"] = dict(self.motion)
        return _fingerprint(identity)

    @property
    def replans(self) -> bool:
        """Whether the run may plan again after its first touch (closed loop only)."""
        return self.loop == "closed" and self.replan_beyond_m > 0

    def describe(self) -> dict:
        return {"key": self.key, "fingerprint": self.fingerprint, "kind": self.kind,
                "ladder": self.plan.ladder_key, "seed": self.plan.seed,
                "sweep": dict(self.plan.sweep), "strategy": self.strategy,
                "loop": self.loop, "draw": self.draw_index,
                "perturbation": self.draw.to_json()} | (
                    {"replan_beyond_m": self.replan_beyond_m} if self.replans else {}) | (
                    {"motion": dict(self.motion)} if self.motion else {})

    @property
    def label(self) -> str:
        """The row of the summary this run counts in."""
        return run_label(self.strategy, self.loop,
                         self.replan_beyond_m if self.replans else 0.0, dict(self.motion))


def run_label(strategy: str, loop: str, replan_beyond_m: float = 0.0,
              motion: dict[str, Any] | None = None) -> str:
    """``"mixed closed"``: a strategy played open or closed loop;
    ``"mixed closed, re-plan > 2 cm"`` when a closed run may plan again after its first
    touch; ``"mixed closed, grip_bending_onset=0.35"`` with motion-layer settings."""
    label = f"{strategy} {loop}"
    if loop == "closed" and replan_beyond_m > 0:
        label += f", re-plan > {replan_beyond_m * 100:g} cm"
    for name, value in (motion or {}).items():
        label += f", {name}={_setting_text(value)}"
    return label


def _setting_text(value: Any) -> str:
    if isinstance(value, bool):
        return "on" if value else "off"
    return f"{value:g}"


def record_label(record: dict) -> str:
    """The summary row of a validate record (records written before the loop axis
    existed were open loop)."""
    return run_label(record["strategy"], record.get("loop", "open"),
                     record.get("replan_beyond_m", 0.0), record.get("motion"))


def expand_jobs(ladders: Sequence[tuple[str, LadderSpec, dict[str, Any]]], seeds: Sequence[int],
                strategies: Sequence[str], perturb: PerturbSpec, draws: int = 1, *,
                robot: str = "drc-hubo", time_limit_s: float = 600.0,
                top_rung: int | None = None, rate_hz: float = DAEMON_RATE_HZ,
                loops: Sequence[str] = ("closed",), replan_beyond_m: float = 0.0,
                motion_variants: Sequence[tuple[tuple[str, Any], ...]] = ((),)
                ) -> tuple[list[PlanJob], list[ValidateJob]]:
    """Every job of a batch.

    Args:
        ladders: (key, spec, swept values) per ladder.
        seeds: planner seeds.
        strategies: arm strategies to validate each plan with.
        perturb: what to perturb.
        draws: perturbation draws per (plan, strategy).
        robot, time_limit_s, top_rung, rate_hz: planning settings (see `PlanJob`).
        loops: ``closed`` and/or ``open``; both loops of a strategy see the same draws.
        replan_beyond_m: closed runs plan again beyond this first-touch error [m] (0 never).
        motion_variants: the closed runs' motion-layer settings (`ValidateJob.motion`):
            every closed run is made once per variant, each on the same draws; an open
            run, which has no motion layer, once. A variant's settings are kept in name
            order, the order a resumed batch reads them back in from its results file
            (written with sorted keys), so that its key, row and records agree.

    Returns:
        (plan jobs, validate jobs), in ladder, seed, strategy, loop, variant, draw order.
    """
    plans, validations = [], []
    for key, spec, sweep in ladders:
        for seed in seeds:
            p = PlanJob(key, spec, int(seed), robot, time_limit_s, top_rung, rate_hz,
                        tuple(sweep.items()))
            plans.append(p)
            for strategy in strategies:
                for loop in loops:
                    for motion in (motion_variants if loop == "closed" else ((),)):
                        for i in range(draws):
                            validations.append(ValidateJob(
                                p, strategy, i, draw(perturb, key, int(seed), strategy, i),
                                loop, replan_beyond_m, tuple(sorted(motion))))
    return plans, validations




def plan_job(job: PlanJob, out_dir: str) -> dict:
    """Plan a climb and write ``OUT/<job.traj_name>`` and its sidecar.

    Args:
        job: the plan job.
        out_dir: the batch's output directory.

    Returns:
        The outcome (module docstring). ``plan_s`` is the wall time of search and
        timing [s].
    """
    from planner.output import write_plan
    from planner.reachability import LadderOutOfReach
    from planner.search import ClimbPlanner, PlannerConfig, PlanningFailed
    from planner.timing import TimingError

    t0 = time.perf_counter()
    try:
        planner = ClimbPlanner(job.ladder, robot=job.robot,
                               config=PlannerConfig(time_limit_s=job.time_limit_s),
                               seed=job.seed)
    except LadderOutOfReach as exc:
        return {**_NO_PLAN, "plan_s": time.perf_counter() - t0, "top_rung": job.top_rung,
                "where": "reach", "why": f"no plan: {exc}"}
    top = planner.top_rung() if job.top_rung is None else job.top_rung
    try:
        with hard_time_limit(job.time_limit_s + HARD_LIMIT_GRACE_S):
            result = planner.plan(top_rung=top)
    except PlanningFailed as exc:
        where = f"{exc.step.primitive.name} at rung {exc.step.rung}"
        return {**_NO_PLAN, "plan_s": time.perf_counter() - t0, "top_rung": top,
                "where": where, "why": planner.no_plan_message(exc, job.time_limit_s),
                "search_reason": f"{where}: {exc.reason}"}
    except TimeLimitExceeded as exc:
        return {**_NO_PLAN, "plan_s": time.perf_counter() - t0,
                "top_rung": top, "where": "time limit",
                "why": planner.no_plan_message(exc, job.time_limit_s)}
    search_s = time.perf_counter() - t0
    out = Path(out_dir) / job.traj_name
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        written = write_plan(result, planner, out, job.rate_hz,
                             {"search_s": result.total_s, "setup_s": search_s - result.total_s})
    except TimingError as exc:
        return {**_NO_PLAN, "plan_s": time.perf_counter() - t0,
                "top_rung": top, "where": "timing", "why": f"no plan: timing: {exc}"}
    return {"outcome": "planned", "traj": job.traj_name, "plan_s": time.perf_counter() - t0,
            "search_s": result.total_s, "motion_s": written.timed.duration_s,
            "lines": written.sidecar.line_count, "top_rung": top}


def validate_job(job: ValidateJob, plan_outcome: dict, out_dir: str) -> dict:
    """Simulate the plan of ``plan_outcome`` with the job's strategy and perturbation.

    Args:
        job: the validate job.
        plan_outcome: its plan job's outcome (``planned``, with ``traj``).
        out_dir: the batch's output directory.

    Returns:
        The outcome (module docstring); ``simulated_s_per_rung`` is reported only for a
        climb (a failed run stops early, so its time per rung means nothing).
    """
    from daemon.sim.board_model import BoardModelConfig, PlacementError
    from execute.motion.config import MotionConfig
    from execute.validate.cli import result_json
    from execute.validate.metrics import compute_metrics
    from execute.validate.plan_compare import compare_with_plan
    from execute.validate.simulate import SimulationOptions, simulate
    from robot.plan_sidecar import read_sidecar, sidecar_path
    from robot.trajectory_file import read_trajectory

    plan = Path(out_dir) / plan_outcome["traj"]
    sidecar = read_sidecar(sidecar_path(plan))
    traj = read_trajectory(plan, sidecar.rate_hz, sidecar.robot)
    d = job.draw
    opts = SimulationOptions(strategy=job.strategy,
                             placement=PlacementError(d.dx_m, d.dy_m, d.dyaw_rad),
                             board=BoardModelConfig(battery_v=d.battery_v), record_qpos=False,
                             closed_loop=job.loop == "closed",
                             motion=MotionConfig(replan_beyond_m=job.replan_beyond_m,
                                                 **dict(job.motion)))
    run = simulate(traj, sidecar, d.physical_ladder(job.plan.ladder), opts, sidecar.robot)
    metrics = compute_metrics(run)
    result = result_json(run, metrics, plan_outcome["traj"],
                         compare_with_plan(run, traj, job.plan.ladder))
    climbed = run.verdict.climbed
    return {"outcome": "climbed" if climbed else "failed", "cause": result["cause"],
            "why": result["why"], "simulated_s": metrics.simulated_s,
            "simulated_s_per_rung": metrics.simulated_s_per_rung if climbed else None,
            "real_time_factor": metrics.real_time_factor, "result": result}


@dataclass(frozen=True)
class JobFunctions:
    """The functions a runner calls; module-level callables (picklable by reference).

    Attributes:
        plan: ``plan(job: PlanJob, out_dir: str) -> dict``.
        validate: ``validate(job: ValidateJob, plan_outcome: dict, out_dir: str) -> dict``.
    """

    plan: Callable[[PlanJob, str], dict] = plan_job
    validate: Callable[[ValidateJob, dict, str], dict] = validate_job


DEFAULT_JOB_FUNCTIONS = JobFunctions()
