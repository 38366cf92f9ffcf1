"""batch-eval: bad input exits 2 naming the option; a small run writes its tables and
plots; one real plan-and-validate run on the cheapest case (stair, first rung).

Not covered by a test (too slow for the suite): a full-height climb (``--top-rung``
unset, ~50 s of planning and ~30 s of simulation per DRC job); `bench/bench_batch.py`
and the measurement in the issue cover it."""

from __future__ import annotations

import csv
import io
import json
import sys
from pathlib import Path

import pytest
from rich.console import Console

sys.path.insert(0, str(Path(__file__).parent))

import batch_small_jobs as small  # noqa: E402

from execute.batch.cli import main, parse_args, run  # noqa: E402
from execute.batch.jobs import JobFunctions, expand_jobs  # noqa: E402
from execute.batch.perturb import parse_perturb  # noqa: E402
from execute.batch.runner import RESULTS_FILE  # noqa: E402
from ladders.loader import load_ladder  # noqa: E402
from robot.vocabulary import FailureCause  # noqa: E402

SMALL = JobFunctions(plan=small.small_plan, validate=small.small_validate)


@pytest.mark.parametrize("argv,words", [
    (["--seeds", "0"], ["--seeds is 0", "[1, 10000]"]),
    (["--seeds", "x"], ["--seeds", "invalid int"]),
    (["--workers", "0"], ["--workers is 0", "[1, 256]"]),
    (["--time-limit", "-1"], ["--time-limit is -1", "> 0 s"]),
    (["--strategies", "mixed,hover"], ["--strategies", "hover", "mixed, position, pwm"]),
    (["--strategies", "pwm,pwm"], ["--strategies", "pwm given twice"]),
    (["--loop", "closed,sideways"], ["--loop", "closed, open or closed,open"]),
    (["--ladders", "drc,tower"], ["--ladders", "unknown ladder 'tower'"]),
    (["--perturb", "placement=3"], ["--perturb placement=3", "(0, 1] m"]),
    (["--perturb", "wind=3"], ["wind=3", "placement, yaw, rung, friction, battery"]),
    (["--perturb", "rung=0.2", "--ladders", "stair"], ["rung=0.2", "rung_spacing_m"]),
    (["--draws", "3"], ["--draws is 3", "no --perturb"]),
    (["--engine", "ray"], ["--engine", "local or dask"]),
    (["--address", "tcp://h:8786"], ["--address needs --engine dask"]),
    (["--engine", "dask", "--address", "h:8786"], ["--address", "tcp://host:8786"]),
    (["--ladders", "stair", "--top-rung", "4"], ["--top-rung is 4", "0..3"]),
    (["--ladders", "drc", "--sweep", "s.yaml"], ["not allowed with argument"]),
    (["--plans-from", "no-such-dir"], ["--plans-from", "no-such-dir", "results.jsonl"]),
    (["--replan-beyond", "0.5"], ["--replan-beyond", "replan_beyond_m = 0.5", "[0, 0.2]"]),
    (["--replan-beyond", "0.02", "--loop", "open"], ["--replan-beyond is 0.02",
                                                     "only closed-loop runs plan again"]),
    (["--motion", "grip_bending_onset=0,0.5"], ["--motion", "grip_bending_onset = 0.5",
                                                "[0, 0.39]"]),
    (["--motion", "grasp_retries=2.5"], ["--motion", "grasp_retries", "an integer"]),
    (["--motion", "gravity_compensation=maybe"], ["--motion", "on or off"]),
    (["--motion", "wobble=1"], ["--motion", "'wobble' is unknown", "grip_bending_onset"]),
    (["--motion", "grip_bending_onset"], ["--motion", "SETTING=V1,V2"]),
    (["--motion", "replan_beyond_m=0.02"], ["--motion", "use --replan-beyond"]),
    (["--motion", "grip_bending_onset=0.3", "--loop", "open"], ["--motion",
                                                                "closed loop only"]),
    (["--motion", "grip_bending_onset=0.3", "--motion", "grip_bending_onset=0.2"],
     ["grip_bending_onset given twice"]),
])
def test_bad_flags_exit_2_naming_the_option(argv, words, tmp_path, capsys):
    assert main([*argv, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    for w in words:
        assert w in err, err
    assert not (tmp_path / RESULTS_FILE).exists()


def test_bad_sweep_file_exits_2_with_its_line(tmp_path, capsys):
    sweep = tmp_path / "s.yaml"
    sweep.write_text("base: drc\nparameters:\n  slope_deg: [60, 20]\n")
    assert main(["--sweep", str(sweep), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert f"{sweep}:3:" in err and "parameters.slope_deg" in err and "[30, 90] deg" in err


def _run_small(argv: list[str]) -> tuple[int, str]:
    out = io.StringIO()
    console = Console(file=out, width=240, force_terminal=False)
    err = Console(file=io.StringIO(), width=240)
    code = run(parse_args(argv), console, err, functions=SMALL)
    return code, out.getvalue()


def test_small_run_prints_and_writes_tables_and_plots(tmp_path):
    out = tmp_path / "o"
    code, text = _run_small(["--ladders", "drc,stair", "--seeds", "4", "--perturb",
                             "placement=0.03", "--draws", "2", "--workers", "2",
                             "--out", str(out)])
    assert code == 0
    assert "success rate per ladder × strategy" in text and "planning per ladder" in text
    rows = list(csv.DictReader((out / "summary.csv").open()))
    assert [(r["ladder"], r["strategy"]) for r in rows] == [
        (lad, f"{s} closed") for lad in ("drc", "stair") for s in ("mixed", "position", "pwm")]
    for r in rows:
        assert int(r["runs"]) == 8 and int(r["errors"]) == 0 and int(r["missing"]) == 0
        assert float(r["ci95_low"]) <= float(r["rate"] or 0) <= float(r["ci95_high"])
    md = (out / "summary.md").read_text()
    assert md.count("| drc |") == 3 + 1 and "## Failure causes" in md
    for name in ("success_per_strategy", "success_vs_slope", "success_vs_spacing"):
        assert (out / "plots" / f"{name}.png").stat().st_size > 5000
    records = [json.loads(x) for x in (out / RESULTS_FILE).read_text().splitlines()]
    assert len(records) == 2 * 4 + 2 * 4 * 3 * 2


def _both_loops(out: Path, *extra: str) -> tuple[list[str], list[dict]]:
    """A small mixed batch on drc seeds 1–2, closed and open loop: (summary rows'
    labels, validate records)."""
    code, _text = _run_small(["--ladders", "drc", "--seeds", "2", "--strategies", "mixed",
                              "--loop", "closed,open", *extra, "--workers", "1",
                              "--out", str(out)])
    assert code == 0
    rows = list(csv.DictReader((out / "summary.csv").open()))
    records = [json.loads(x) for x in (out / RESULTS_FILE).read_text().splitlines()]
    return [r["strategy"] for r in rows], [r for r in records if r["kind"] == "validate"]


def test_loop_axis_pairs_open_and_closed_runs_on_the_same_draws(tmp_path):
    labels, runs = _both_loops(tmp_path / "o", "--perturb", "placement=0.03")
    assert labels == ["mixed closed", "mixed open"]
    assert sorted(r["loop"] for r in runs) == ["closed", "closed", "open", "open"]
    for seed in (1, 2):
        pair = [r["perturbation"] for r in runs if r["seed"] == seed]
        assert len(pair) == 2 and pair[0] == pair[1]


def test_re_planning_closed_runs_get_their_own_row_and_fingerprint(tmp_path):
    """``--replan-beyond`` reaches the closed runs only, names their row, and changes
    their fingerprint (a batch without it resumes from its old records)."""
    labels, runs = _both_loops(tmp_path / "o", "--replan-beyond", "0.02")
    assert labels == ["mixed closed, re-plan > 2 cm", "mixed open"]
    assert sorted((r["loop"], r.get("replan_beyond_m")) for r in runs) == [
        ("closed", 0.02), ("closed", 0.02), ("open", None), ("open", None)]
    jobs = expand_jobs([("drc", load_ladder("drc"), {})], [1], ["mixed"],
                       parse_perturb(""), loops=("closed",))[1]
    again = expand_jobs([("drc", load_ladder("drc"), {})], [1], ["mixed"],
                        parse_perturb(""), loops=("closed",), replan_beyond_m=0.02)[1]
    assert jobs[0].fingerprint != again[0].fingerprint
    assert "replan_beyond_m" not in jobs[0].describe()


def test_motion_settings_repeat_each_closed_run_on_the_same_draws(tmp_path):
    """``--motion`` makes one closed run per setting value, each in its own row, on the
    draws that the other values and the open run see; the settings reach the job and its
    fingerprint, and crossing two flags makes every combination."""
    flags = ("--perturb", "placement=0.03", "--motion", "grip_bending_onset=0,0.35",
             "--motion", "gravity_compensation=off")
    labels, runs = _both_loops(tmp_path / "o", *flags)
    assert labels == ["mixed closed, gravity_compensation=off, grip_bending_onset=0",
                      "mixed closed, gravity_compensation=off, grip_bending_onset=0.35",
                      "mixed open"]
    # resumed, the rows count the records read back from the results file
    _both_loops(tmp_path / "o", *flags)
    rows = list(csv.DictReader((tmp_path / "o" / "summary.csv").open()))
    assert [(r["runs"], r["missing"]) for r in rows] == [("2", "0")] * 3
    seed1 = sorted((r for r in runs if r["seed"] == 1), key=lambda r: r["key"])
    assert [(r["loop"], r.get("motion")) for r in seed1] == [
        ("closed", {"grip_bending_onset": 0.0, "gravity_compensation": False}),
        ("closed", {"grip_bending_onset": 0.35, "gravity_compensation": False}),
        ("open", None)]
    for seed in (1, 2):
        draws = [r["perturbation"] for r in runs if r["seed"] == seed]
        assert len(draws) == 3 and draws[0] == draws[1] == draws[2]
    jobs = expand_jobs([("drc", load_ladder("drc"), {})], [1], ["mixed"], parse_perturb(""),
                       motion_variants=[(), (("grip_bending_onset", 0.35),)])[1]
    assert len({j.fingerprint for j in jobs}) == len({j.key for j in jobs}) == 2
    assert "motion" not in jobs[0].describe()


def test_small_sweep_run_writes_a_heat_map(tmp_path):
    sweep = tmp_path / "s.yaml"
    sweep.write_text("base: drc\nmode: grid\nparameters:\n  slope_deg: [50, 60, 70]\n"
                     "  rung_spacing_m: {min: 0.28, max: 0.32, steps: 2}\n")
    out = tmp_path / "o"
    code, text = _run_small(["--sweep", str(sweep), "--seeds", "2", "--strategies",
                             "mixed,pwm", "--workers", "2", "--out", str(out)])
    assert code == 0
    rows = list(csv.DictReader((out / "summary.csv").open()))
    assert len(rows) == 6 * 2 and {"slope_deg", "rung_spacing_m"} <= set(rows[0])
    assert rows[0]["ladder"] == "drc.c000" and "drc.c005" in text
    assert (out / "plots" / "heatmap_rung_spacing_m_slope_deg.png").exists()


def test_plans_from_an_earlier_batch_are_taken_when_their_inputs_match(tmp_path):
    """A second batch validates the first one's plans under another perturbation without
    planning again; a plan with other inputs (here a time limit) is planned anew."""
    first = tmp_path / "first"
    code, _ = _run_small(["--ladders", "drc", "--seeds", "3", "--strategies", "mixed",
                          "--workers", "1", "--out", str(first)])
    assert code == 0
    second = tmp_path / "second"
    argv = ["--ladders", "drc", "--seeds", "4", "--strategies", "mixed", "--perturb",
            "placement=0.03", "--workers", "1", "--out", str(second),
            "--plans-from", str(first)]
    err = Console(file=io.StringIO(), width=240)
    assert run(parse_args(argv), Console(file=io.StringIO()), err, functions=SMALL) == 0
    assert "took 3 of 4 plan(s)" in err.file.getvalue()
    records = [json.loads(x) for x in (second / RESULTS_FILE).read_text().splitlines()]
    plans = [r for r in records if r["kind"] == "plan"]
    assert sorted(r["seed"] for r in plans if r.get("reused_from")) == [1, 2, 3]
    assert [r["seed"] for r in plans if not r.get("reused_from")] == [4]  # planned here
    for r in plans:
        assert (second / r["traj"]).read_text() == (first / r["traj"]).read_text() \
            if r.get("reused_from") else (second / r["traj"]).is_file()
    assert sum(r["kind"] == "validate" for r in records) == 4
    third = tmp_path / "third"
    other = parse_args(argv[:-4] + ["--time-limit", "30", "--out", str(third),
                                    "--plans-from", str(first)])
    assert run(other, Console(file=io.StringIO()), err, functions=SMALL) == 0
    records = [json.loads(x) for x in (third / RESULTS_FILE).read_text().splitlines()]
    assert not any(r.get("reused_from") for r in records)  # other inputs: planned anew


def test_errored_jobs_give_exit_1(tmp_path):
    code, _ = _run_small(["--ladders", "drc", "--seeds", "1", "--first-seed",
                          str(small.RAISE_VALIDATE_SEED), "--workers", "1",
                          "--out", str(tmp_path)])
    assert code == 1


def test_real_plan_and_validate_on_the_stair_first_rung(tmp_path, capsys):
    """The real job functions, end to end: plan stair up to rung 0 (~6 s), then play it
    with the three strategies (each ends within ~20 s of simulated time)."""
    out = tmp_path / "real"
    code = main(["--ladders", "stair", "--top-rung", "0", "--seeds", "1", "--perturb",
                 "placement=0.01", "--replan-beyond", "0.05", "--workers", "2",
                 "--motion", "grip_bending_onset=0.3",
                 "--out", str(out), "--no-plots"])
    text = capsys.readouterr().out
    assert code == 0, text
    recs = {r["key"]: r for r in map(json.loads, (out / RESULTS_FILE).read_text().splitlines())}
    plan = recs.pop("plan/stair/s1")
    assert plan["status"] == "ok" and plan["outcome"] in ("planned", "no_plan")
    assert len(recs) == 3
    causes = {c.value for c in FailureCause}
    for r in recs.values():
        assert r["status"] == "ok" and r["outcome"] in ("climbed", "failed")
        if plan["outcome"] == "planned":
            # the record carries validate-plan's own result: cause, why and metrics
            assert r["result"]["strategy"] == r["strategy"]
            assert r["result"]["replan_beyond_m"] == 0.05  # the motion layer got the options
            assert r["result"]["motion_settings"] == {"replan_beyond_m": 0.05,
                                                      "grip_bending_onset": 0.3}
            assert r["result"]["placement_error"]["dx_m"] == r["perturbation"]["dx_m"]
            assert r["outcome"] == "climbed" or r["cause"] in causes
            assert r["why"] and r["simulated_s"] > 0
            # and where the run ended against the plan's own account of that line
            assert r["result"]["plan_vs_sim"]["line"] == r["result"]["line"]
    assert "stair" in text and "mixed" in text


def test_the_summary_counts_re_plans_their_outcomes_and_planning_time(tmp_path):
    """Closed runs that could plan again get a table of their own: how many did, how
    many found no new plan, how many of the re-planned climbed, and the planning time."""
    from execute.batch.report import summarize_records, write_markdown

    def run(seed: int, outcome: str, replan: dict | None) -> dict:
        return {"kind": "validate", "ladder": "drc", "seed": seed, "strategy": "mixed",
                "loop": "closed", "replan_beyond_m": 0.02, "status": "ok",
                "outcome": outcome, "cause": None if outcome == "climbed" else "board_trip",
                "result": {"replan": replan}}

    records = [run(1, "climbed", {"planning_s": 150.0, "no_plan": None}),
               run(2, "failed", {"planning_s": 210.0, "no_plan": None}),
               run(3, "failed", {"planning_s": 30.0, "no_plan": "placeHands: no sample"}),
               run(4, "climbed", None)]
    label = "mixed closed, re-plan > 2 cm"
    summary = summarize_records(records, {"drc": load_ladder("drc")}, [label],
                                {("drc", label): 4}, {"drc": 0})
    (row,) = summary.replans
    assert (row.runs, row.replanned, row.no_plan, row.climbed) == (4, 3, 1, 1)
    assert (row.planning_s.min, row.planning_s.median) == (30.0, 150.0)
    md = write_markdown(summary, tmp_path / "s.md").read_text()
    assert "## Re-plans after the first touch" in md
    assert f"| drc | {label} | 4 | 3 | 1 | 1 | 30 / 150 /" in md
    without = summarize_records([{k: v for k, v in r.items() if k != "replan_beyond_m"}
                                 for r in records],
                                {"drc": load_ladder("drc")}, ["mixed closed"],
                                {("drc", "mixed closed"): 4}, {"drc": 0})
    assert not without.replans
    assert "Re-plans" not in write_markdown(without, tmp_path / "w.md").read_text()
