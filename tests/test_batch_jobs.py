"""Batch jobs: expansion, deterministic perturbation draws, sweeps, the results file,
resume after an interruption, and jobs that raise or kill their worker.

The runner tests inject the small real job functions of ``batch_small_jobs`` (no planner,
no MuJoCo) through `JobFunctions`; the real job functions run in test_batch_cli."""

from __future__ import annotations

import dataclasses
import json
import math
import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

import batch_small_jobs as small  # noqa: E402

from execute.batch.engine import local_engine  # noqa: E402
from execute.batch.jobs import JobFunctions, PlanJob, expand_jobs  # noqa: E402
from execute.batch.perturb import Draw, PerturbSpec, draw, parse_perturb  # noqa: E402
from execute.batch.results import ResultsLog  # noqa: E402
from execute.batch.runner import RESULTS_FILE, run_batch  # noqa: E402
from execute.batch.sweep import parse_sweep_yaml  # noqa: E402
from ladders.loader import load_ladder  # noqa: E402
from robot.errors import InputError  # noqa: E402

SMALL = JobFunctions(plan=small.small_plan, validate=small.small_validate)
STRATS = ("mixed", "position", "pwm")
PERTURB = parse_perturb("placement=0.03,yaw=0.05,friction=0.3:0.5,battery=44:50")


def _ladders(*names):
    return [(n, load_ladder(n), {}) for n in names]


# --- expansion and draws ---------------------------------------------------------------

def test_expansion_counts_keys_and_dependencies():
    plans, vals = expand_jobs(_ladders("drc", "stair"), [1, 2, 3], STRATS, PERTURB, draws=2)
    assert len(plans) == 2 * 3 and len(vals) == 2 * 3 * 3 * 2
    keys = [j.key for j in [*plans, *vals]]
    assert len(set(keys)) == len(keys)
    assert {v.plan for v in vals} == set(plans)
    assert "validate/stair/s2/pwm/closed/d1" in keys and "plan/drc/s3" in keys
    # fingerprints follow the inputs: same job, same print; other settings, other print
    again, _ = expand_jobs(_ladders("drc"), [1], STRATS, PERTURB)
    assert again[0].fingerprint == plans[0].fingerprint
    other, _ = expand_jobs(_ladders("drc"), [1], STRATS, PERTURB, time_limit_s=5)
    assert other[0].fingerprint != plans[0].fingerprint


def test_draws_are_deterministic_and_independent():
    a = draw(PERTURB, "drc", 4, "mixed", 0)
    assert a == draw(PERTURB, "drc", 4, "mixed", 0)
    others = {draw(PERTURB, *k) for k in [("stair", 4, "mixed", 0), ("drc", 5, "mixed", 0),
                                          ("drc", 4, "pwm", 0), ("drc", 4, "mixed", 1)]}
    assert a not in others and len(others) == 4
    assert abs(a.dx_m) <= 0.03 and abs(a.dy_m) <= 0.03 and abs(a.dyaw_rad) <= 0.05
    assert 0.3 <= a.friction <= 0.5 and 44 <= a.battery_v <= 50
    # enabling another perturbation does not move this one's values
    only = draw(parse_perturb("placement=0.03"), "drc", 4, "mixed", 0)
    assert (only.dx_m, only.dy_m) == (a.dx_m, a.dy_m)
    assert (only.dyaw_rad, only.friction, only.battery_v) == (0.0, None, 48.0)
    assert draw(PerturbSpec(), "drc", 1, "pwm", 0) == Draw()


def test_draws_spread_over_the_range():
    spec = parse_perturb("placement=0.03")
    xs = [draw(spec, "drc", s, "mixed", 0).dx_m for s in range(200)]
    assert min(xs) < -0.025 and max(xs) > 0.025
    assert abs(sum(xs) / len(xs)) < 0.005


def test_physical_ladder_gets_rung_and_friction_not_placement():
    drc = load_ladder("drc")
    d = Draw(dx_m=0.02, rung_spacing_error_m=0.01, friction=0.3)
    phys = d.physical_ladder(drc)
    assert phys.rung_spacing_m == pytest.approx(0.315) and phys.friction == 0.3
    assert phys.placement_x_m == drc.placement_x_m  # placement: the simulation's job
    assert Draw().physical_ladder(drc) is drc


@pytest.mark.parametrize("text,words", [
    ("foo=1", ["foo=1", "placement, yaw, rung, friction, battery"]),
    ("placement=2", ["placement=2", "(0, 1] m"]),
    ("placement=-0.1", ["placement=-0.1"]),
    ("yaw=abc", ["yaw", "not a number"]),
    ("friction=0.5:0.3", ["friction=0.5:0.3", "lo ≤ hi"]),
    ("battery=44:70", ["battery", "≤ 60 V"]),
    ("rung=0.01,rung=0.02", ["'rung' is given twice"]),
    ("placement", ["key=value"]),
])
def test_bad_perturb_names_the_key_and_range(text, words):
    with pytest.raises(InputError) as exc:
        parse_perturb(text)
    for w in words:
        assert w in str(exc.value)


def test_rung_perturbation_must_keep_the_spacing_in_range():
    stair = load_ladder("stair")
    parse_perturb("rung=0.05").check_ladder(stair)
    with pytest.raises(InputError, match="rung_spacing_m"):
        parse_perturb("rung=0.15").check_ladder(stair)


# --- sweeps ------------------------------------------------------------------------------

GRID = """\
base: drc
mode: grid
parameters:
  slope_deg: [55, 60, 65]
  rung_spacing_m: {min: 0.25, max: 0.35, steps: 2}
  rung_shape: [box, cylinder]
"""


def test_grid_sweep_expands_every_combination():
    cells = parse_sweep_yaml(GRID, "g.yaml")
    assert len(cells) == 3 * 2 * 2
    assert cells[0].name == "drc.c000" and cells[0].spec.name == "drc.c000"
    assert cells[0].params == {"slope_deg": 55.0, "rung_spacing_m": 0.25, "rung_shape": "box"}
    assert cells[-1].spec.slope_deg == 65.0 and cells[-1].spec.rung_shape == "cylinder"
    assert all(c.spec.rail_spacing_m == 1.35 for c in cells)  # the rest is the base's


def test_random_sweep_is_seeded():
    text = ("base: drc\nmode: random\nsamples: 5\nseed: 3\nparameters:\n"
            "  rail_height_m: {min: 0.8, max: 1.1}\n  rung_shape: [box, cylinder]\n")
    a, b = parse_sweep_yaml(text), parse_sweep_yaml(text)
    assert [c.params for c in a] == [c.params for c in b] and len(a) == 5
    assert all(0.8 <= c.spec.rail_height_m <= 1.1 for c in a)
    c = parse_sweep_yaml(text.replace("seed: 3", "seed: 4"))
    assert [x.params for x in c] != [x.params for x in a]


def test_the_benchmark_s_random_ladders_span_the_issue_s_ranges():
    from execute.batch.sweep import load_sweep

    cells = load_sweep(Path(__file__).parents[1] / "bench" / "random_ladders.yaml")
    assert len(cells) == 40
    for lo, hi, values in ((55, 75, [c.spec.slope_deg for c in cells]),
                           (0.25, 0.35, [c.spec.rung_spacing_m for c in cells]),
                           (0.6, 1.0, [c.spec.rail_spacing_m for c in cells])):
        assert lo <= min(values) and max(values) <= hi
        assert max(values) - min(values) > 0.8 * (hi - lo)  # spread, not one corner


@pytest.mark.parametrize("text,words", [
    (GRID.replace("slope_deg: [55, 60, 65]", "slope_deg: [55, 95]"),
     ["g.yaml:4:", "parameters.slope_deg", "[30, 90] deg"]),
    (GRID.replace("rung_shape", "rung_colour"), ["g.yaml:6:", "cannot be swept"]),
    (GRID.replace("steps: 2", "steps: 0"), ["g.yaml:5:", "steps", "[1, 100]"]),
    (GRID.replace("mode: grid", "mode: sobol"), ["g.yaml:2:", "'grid', 'random'"]),
    (GRID.replace("base: drc", "base: dcr"), ["g.yaml:1:", "unknown ladder 'dcr'"]),
    (GRID + "extra: 1\n", ["g.yaml:7:", "field 'extra' is unknown"]),
    ("base: drc\nmode: random\nparameters:\n  slope_deg: [50]\n", ["'samples' is missing"]),
    ("base: drc\nparameters: {slope_deg: [50\n", ["YAML syntax error"]),
])
def test_bad_sweep_files_name_line_and_field(text, words):
    with pytest.raises(InputError) as exc:
        parse_sweep_yaml(text, "g.yaml")
    for w in words:
        assert w in str(exc.value)


# --- the results file ----------------------------------------------------------------------

def test_results_log_survives_a_torn_last_line(tmp_path):
    log = ResultsLog(tmp_path / RESULTS_FILE)
    log.append({"key": "a", "status": "ok", "fingerprint": "f"})
    with open(tmp_path / RESULTS_FILE, "a") as fh:
        fh.write('{"key": "b", "stat')  # killed mid-write
    again = ResultsLog(tmp_path / RESULTS_FILE)
    assert again.finished("a", "f") and again.finished("a", "g") is None
    assert again.finished("b", "f") is None
    again.append({"key": "b", "status": "ok", "fingerprint": "f"})
    assert [r["key"] for r in ResultsLog.read(tmp_path / RESULTS_FILE)] == ["a", "b"]


# --- running: resume and crashes -------------------------------------------------------------

@pytest.fixture(scope="module")
def engine():
    with local_engine(2) as eng:
        yield eng


def test_every_job_runs_in_a_fresh_process():
    """OMPL is seeded once per process: a worker reused across plans would make a batch
    cell differ from plan-ladder with the same seed."""
    with local_engine(1) as eng:
        pids = [eng.submit(os.getpid).result() for _ in range(3)]
    assert len(set(pids)) == 3 and os.getpid() not in pids


def _lines(out: Path) -> list[dict]:
    return [json.loads(x) for x in (out / RESULTS_FILE).read_text().splitlines()]


def test_interrupted_run_resumes_without_redoing_jobs(tmp_path, engine):
    plans, vals = expand_jobs(_ladders("drc", "stair"), [1, 2], STRATS, PERTURB)
    first = run_batch(plans, vals, tmp_path, engine, functions=SMALL, max_jobs=5)
    assert first.ran >= 5 and first.skipped == 0
    done_before = {r["key"] for r in _lines(tmp_path)}
    assert len(done_before) < len(plans) + len(vals)  # really interrupted

    starts = []
    second = run_batch(plans, vals, tmp_path, engine, functions=SMALL,
                       on_start=lambda n, s: starts.append((n, s)))
    assert starts == [(len(plans) + len(vals) - len(done_before), len(done_before))]
    lines = _lines(tmp_path)
    keys = [r["key"] for r in lines]
    assert len(keys) == len(set(keys)) == len(plans) + len(vals)  # nothing ran twice
    assert second.skipped == len(done_before) and not second.errors

    # a clean run in another directory gives the same outcomes
    from execute.batch.results import comparable

    clean = run_batch(plans, vals, tmp_path / "clean", engine, functions=SMALL)
    strip = [{k: v for k, v in comparable(r).items() if k != "finished_at"}
             for r in second.records]
    assert strip == [comparable(r) for r in clean.records]

    third = run_batch(plans, vals, tmp_path, engine, functions=SMALL)
    assert third.ran == 0 and third.skipped == len(keys)


def test_raising_and_crashing_jobs_are_recorded_and_the_run_goes_on(tmp_path, engine):
    seeds = [1, small.RAISE_VALIDATE_SEED, small.CRASH_SEED, small.RAISE_PLAN_SEED, 2]
    plans, vals = expand_jobs(_ladders("drc"), seeds, STRATS, PERTURB)
    run = run_batch(plans, vals, tmp_path, engine, functions=SMALL)
    by_key = {r["key"]: r for r in run.records}
    assert len(by_key) == len(plans) + len(vals)

    raised = by_key[f"validate/drc/s{small.RAISE_VALIDATE_SEED}/position/closed/d0"]
    assert raised["status"] == "error" and raised["error"].startswith("ValueError: simulation")
    assert "small_validate" in raised["traceback"]

    crashed = by_key[f"validate/drc/s{small.CRASH_SEED}/pwm/closed/d0"]
    assert crashed["status"] == "error" and "BrokenProcessPool" in crashed["error"]
    # its neighbours were re-run, not blamed
    assert by_key[f"validate/drc/s{small.CRASH_SEED}/mixed/closed/d0"]["status"] == "ok"

    assert by_key[f"plan/drc/s{small.RAISE_PLAN_SEED}"]["error"].startswith("RuntimeError")
    dep = by_key[f"validate/drc/s{small.RAISE_PLAN_SEED}/mixed/closed/d0"]
    assert dep["status"] == "error" and "its plan job" in dep["error"]

    errors = {r["key"] for r in run.errors}
    assert len(errors) == 1 + 1 + 1 + 3
    ok = [r for r in run.records if r["status"] == "ok"]
    assert len(ok) == len(by_key) - len(errors)  # every other job has an outcome

    # on resume only the errored jobs run again
    starts = []
    run_batch(plans, vals, tmp_path, engine, functions=SMALL,
              on_start=lambda n, s: starts.append(n))
    assert starts == [len(errors)]


def test_no_plan_makes_failed_trials_without_simulating(tmp_path, engine):
    steep = dataclasses.replace(load_ladder("drc"), name="steep", slope_deg=90.0)
    plans, vals = expand_jobs([("steep", steep, {})], range(1, 21), ["mixed"], PerturbSpec())
    run = run_batch(plans, vals, tmp_path, engine, functions=SMALL)
    no_plan = {r["seed"] for r in run.records if r["kind"] == "plan" and
               r["outcome"] == "no_plan"}
    assert no_plan  # margin 0.05 − 0.03 ± 0.02·N(0,1): some seeds fail to plan
    for r in run.records:
        if r["kind"] == "validate" and r["seed"] in no_plan:
            assert (r["outcome"], r["cause"]) == ("failed", "no_plan")
            assert r["why"].startswith("no plan: climbRung at rung 1")  # the plan's, once
    assert math.isfinite(run.wall_s)


def test_a_ladder_without_a_landing_keeps_its_plan_fingerprint():
    """Batches made before the spec had a landing still resume: absent parts are not
    hashed; a landing is."""
    import hashlib

    stair = load_ladder("stair")
    job = PlanJob(ladder_key="stair", ladder=stair, seed=3)
    fields = {k: v for k, v in dataclasses.asdict(stair).items()
              if not k.startswith("landing_")}
    before = hashlib.sha256(json.dumps(
        {"kind": "plan", "ladder": fields, "seed": 3, "robot": job.robot,
         "time_limit_s": job.time_limit_s, "top_rung": None, "rate_hz": job.rate_hz},
        sort_keys=True, default=str).encode()).hexdigest()[:16]
    assert job.fingerprint == before
    landed = dataclasses.replace(stair, landing_height_m=0.2, landing_depth_m=1.0,
                                 landing_width_m=1.0, landing_handrails=False)
    assert PlanJob(ladder_key="stair", ladder=landed, seed=3).fingerprint != before
