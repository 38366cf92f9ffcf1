"""Benchmark: real-time factor of the lock-step simulation (player → control → MuJoCo).

Target: ≥ 10× real time on one core for a climb. The climb is ``plan-ladder drc --seed 4``
(planned here, ≈ 100 s; the seed of ``make demo``), simulated to
its end under ``mixed`` and ``position`` even after a failure (the figure is the
simulator's speed, not the verdict; the verdict is printed).
``HUBO_BENCH_PLAN=path/to/plan.traj`` (with its ``.plan.json``) times another plan, and
``HUBO_BENCH_PLAN=fixture`` the hand-built test fixture (6.2 s of motion + 1 s settle).
``HUBO_BENCH_SIM_S=300`` times only the first 300 simulated seconds of each run, in CPU
seconds (for a before/after comparison of two commits on a busy machine).

The same plan times ``check-plan`` (every line, the default): target ≤ 60 s for a whole
DRC climb (issue 20), reading the file included.
"""

from __future__ import annotations

import importlib.util
import os
import tempfile
from pathlib import Path

TARGET_RTF = 10.0
TARGET_CHECK_PLAN_S = 60.0
#: The DRC seed of `make demo` (its whole climb, the run a user times first).
DRC_SEED = 4


def _fixture_plan(tmp: str) -> Path:
    path = Path(__file__).resolve().parent.parent / "tests" / "fixtures" / "make_fixture.py"
    spec = importlib.util.spec_from_file_location("make_fixture", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.make_reach_fixture(tmp)


def _drc_plan(tmp: str) -> Path:
    from planner.cli import main as plan_ladder

    path = Path(tmp) / "drc.traj"
    if plan_ladder(["drc", "--seed", str(DRC_SEED), "-o", str(path)]) != 0:
        raise RuntimeError(f"plan-ladder drc --seed {DRC_SEED} found no plan to simulate")
    return path


def run() -> list[dict]:
    """Time one simulated climb per strategy; report simulated s / wall s."""
    from execute.validate.simulate import SimulationOptions, simulate
    from ladders.loader import sidecar_ladder
    from robot.plan_sidecar import read_sidecar, sidecar_path
    from robot.trajectory_file import read_trajectory

    out = []
    with tempfile.TemporaryDirectory() as tmp:
        choice = os.environ.get("HUBO_BENCH_PLAN", "")
        plan = (_fixture_plan(tmp) if choice == "fixture" else
                Path(choice) if choice else _drc_plan(tmp))
        sc = read_sidecar(sidecar_path(plan))
        traj = read_trajectory(plan, sc.rate_hz, sc.robot)
        ladder = sidecar_ladder(sc, str(plan))
        out.append(_check_plan(plan, sc.line_count))
        limit_s = float(os.environ.get("HUBO_BENCH_SIM_S", "0") or 0)
        for strategy in ("mixed", "position"):
            options = SimulationOptions(strategy=strategy, record_qpos=False,
                                        stop_on_failure=False)
            if limit_s > 0:
                rtf = _first_seconds_rtf(traj, sc, ladder, options, limit_s)
                what = f"first {limit_s:g} s simulated, CPU time"
            else:
                run_ = simulate(traj, sc, ladder, options, sc.robot)
                rtf = run_.real_time_factor
                what = f"{run_.simulated_s:.0f} s simulated; " + (
                    "climbed" if run_.verdict.climbed else
                    f"failed at {run_.verdict.failure.time_s:.1f} s")
            out.append({"name": f"sim_real_time_factor_{plan.stem}_{strategy} ({what})",
                        "value": round(rtf, 2), "unit": "x real time",
                        "target": f">= {TARGET_RTF:g}", "ok": rtf >= TARGET_RTF})
    return out


class _Enough(Exception):
    """Raised from the progress callback to end a run at the time asked."""


def _first_seconds_rtf(traj, sc, ladder, options, limit_s: float) -> float:
    """Simulated seconds per CPU second over the first ``limit_s`` simulated seconds."""
    import time

    from execute.validate.simulate import simulate

    def enough(simulated_s: float, _expected_s: float) -> None:
        if simulated_s >= limit_s:
            raise _Enough(simulated_s)

    cpu0 = time.process_time()
    try:
        run_ = simulate(traj, sc, ladder, options, sc.robot, progress=enough)
        simulated_s = run_.simulated_s  # the run ended first
    except _Enough as stop:
        simulated_s = float(stop.args[0])
    return simulated_s / (time.process_time() - cpu0)


def _check_plan(plan: Path, lines: int) -> dict:
    """``check-plan PLAN`` in-process (its report swallowed): wall time [s]."""
    import contextlib
    import io
    import time

    from planner.verify.cli import main as check_plan

    t0 = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        status = check_plan([str(plan)])
    wall = time.perf_counter() - t0
    return {"name": f"check_plan_{plan.stem} ({lines:,} lines, every line; exit {status})",
            "value": round(wall, 1), "unit": "s", "target": f"<= {TARGET_CHECK_PLAN_S:g}",
            "ok": wall <= TARGET_CHECK_PLAN_S}


if __name__ == "__main__":
    for row in run():
        print(row)
