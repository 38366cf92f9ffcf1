"""Progress off a terminal (issue 20 item 7): plain lines with an ETA, at most one every
10 s, a first and a last one; the commands write them."""

from __future__ import annotations

import io
import re

from robot.progress import PLAIN_INTERVAL_S, ProgressReporter, format_duration


class _Clock:
    def __init__(self) -> None:
        self.t = 1000.0

    def __call__(self) -> float:
        return self.t


def test_plain_lines_are_rate_limited_and_carry_an_eta():
    out, clock = io.StringIO(), _Clock()
    p = ProgressReporter("check-plan", "lines", 1000, stream=out, clock=clock)
    assert not p.live  # a StringIO is no terminal
    for done in range(0, 1001, 10):  # 100 updates over 50 s
        p.update(done)
        clock.t += 0.5
    p.finish()
    lines = out.getvalue().splitlines()
    assert all(line.startswith("check-plan: ") for line in lines)
    assert lines[0] == "check-plan: lines 0/1,000 (0%), 0:00 elapsed"
    assert lines[-1] == "check-plan: done, 0:50"
    middle = lines[1:-1]
    assert 4 <= len(middle) <= 5  # 50 s at most one every 10 s
    assert PLAIN_INTERVAL_S == 10.0
    # 20 lines per s: at 200 of 1000 after 10 s, 40 s left
    assert "lines 200/1,000 (20%), 0:10 elapsed, about 0:40 left" in middle[0]
    for line in middle:
        assert re.search(r"about \d+:\d\d left$", line)


def test_a_note_and_a_new_total_show_and_finish_is_once():
    out, clock = io.StringIO(), _Clock()
    with ProgressReporter("validate-plan", "simulated s", 100.0, stream=out, clock=clock,
                          show=lambda d, t: f"{d:.1f}/{t:.1f}") as p:
        clock.t += 11
        p.update(20.0, note="segment 3 (climbRung)")
        clock.t += 11
        p.update(40.0, total=80.0)
    p.finish("again")  # ignored: already finished
    text = out.getvalue()
    assert "simulated s 20.0/100.0 (20%), segment 3 (climbRung), 0:11 elapsed" in text
    assert "simulated s 40.0/80.0 (50%)" in text and "about 0:22 left" in text
    assert text.rstrip().endswith("validate-plan: done, 0:22") and "again" not in text


def test_durations():
    assert format_duration(7.4) == "0:07"
    assert format_duration(267) == "4:27"
    assert format_duration(3725) == "1:02:05"


def test_a_restart_measures_the_new_phase_only():
    out, clock = io.StringIO(), _Clock()
    p = ProgressReporter("plan-ladder", "output", 1, stream=out, clock=clock)
    clock.t += 100  # a slow first phase
    p.update(0, total=1000, note="clearance", restart=True)
    clock.t += 10
    p.update(500)
    assert p.eta_s() == 10.0  # 50 lines a second since the phase began


# -- the commands, off a terminal (pytest's capture is no terminal) -------------------------

def test_check_plan_writes_progress_lines(tmp_path, capsys):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from synthetic_plan import synthetic_plan

    from planner.output import write_plan
    from planner.verify.cli import main

    planner, result, q0 = synthetic_plan()
    path = tmp_path / "good.traj"
    write_plan(result, planner, path, 200.0, q_start=q0, clearance_every=0)
    assert main([str(path), "--ladder", "drc", "--every", "20"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert re.fullmatch(r"check-plan: lines 0/[\d,]+ \(0%\), 0:00 elapsed", err[0])
    assert any(re.fullmatch(r"check-plan: done, \d+:\d\d", line) for line in err)


def test_plan_ladder_says_done_only_after_the_output(tmp_path, monkeypatch, capsys):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from synthetic_plan import use_synthetic_search

    from planner.cli import main

    use_synthetic_search(monkeypatch)
    assert main(["drc", "--top-rung", "0", "-o", str(tmp_path / "c.traj")]) == 0
    err = capsys.readouterr().err
    searched = err.index("plan-ladder: 4 steps found, writing the plan")
    done = err.index("plan-ladder: done")
    assert searched < err.index("plan-ladder: output") < done < err.index("wrote ")
    assert err.count("plan-ladder: done") == 1


def test_simulate_reports_simulated_time_rate_limited(tmp_path_factory, monkeypatch, capsys):
    import sys
    import time
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent / "fixtures"))
    from make_fixture import cached_reach_fixture

    from execute.validate import simulate as simulate_module
    from execute.validate.cli import main
    from execute.validate.simulate import SimulationOptions, simulate
    from ladders.loader import load_ladder
    from robot.plan_sidecar import read_sidecar, sidecar_path
    from robot.trajectory_file import read_trajectory

    plan = cached_reach_fixture(tmp_path_factory.getbasetemp())
    sidecar = read_sidecar(sidecar_path(plan))
    traj = read_trajectory(plan, sidecar.rate_hz)
    assert simulate_module.PROGRESS_PERIOD_S == 0.5
    monkeypatch.setattr(simulate_module, "PROGRESS_PERIOD_S", 0.05)  # the fixture is short
    calls: list[tuple[float, float, float]] = []
    run = simulate(traj, sidecar, load_ladder("drc"), SimulationOptions(closed_loop=False),
                   progress=lambda sim_s, total_s: calls.append((time.perf_counter(), sim_s,
                                                                 total_s)))
    assert calls
    walls, sims, totals = zip(*calls, strict=True)
    assert all(b - a >= 0.05 for a, b in zip(walls, walls[1:], strict=False))
    assert list(sims) == sorted(sims) and sims[-1] <= run.simulated_s
    assert totals[0] >= len(traj) / sidecar.rate_hz  # the plan and the settling time
    # validate-plan writes them as lines on stderr, the verdict on stdout
    assert main([str(plan), "--open-loop"]) == 0
    cap = capsys.readouterr()
    assert cap.err.startswith("validate-plan: simulated s 0.0/")
    assert "validate-plan: done" in cap.err and "simulated s" not in cap.out
