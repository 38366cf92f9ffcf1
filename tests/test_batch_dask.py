"""The Dask engine: a LocalCluster runs the same jobs through the same runner and gives
the same results as the local process pool for the same seeds (timing and worker
fields aside)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

pytest.importorskip("distributed")

sys.path.insert(0, str(Path(__file__).parent))

import batch_small_jobs as small  # noqa: E402

from execute.batch.engine import dask_engine, local_engine  # noqa: E402
from execute.batch.jobs import JobFunctions, expand_jobs  # noqa: E402
from execute.batch.perturb import parse_perturb  # noqa: E402
from execute.batch.results import comparable  # noqa: E402
from execute.batch.runner import run_batch  # noqa: E402
from ladders.loader import load_ladder  # noqa: E402

SMALL = JobFunctions(plan=small.small_plan, validate=small.small_validate)


def _same(a, b) -> None:
    strip = [{k: v for k, v in comparable(r).items() if k != "finished_at"} for r in a]
    other = [{k: v for k, v in comparable(r).items() if k != "finished_at"} for r in b]
    assert strip == other


def test_dask_local_cluster_matches_the_process_pool(tmp_path):
    ladders = [(n, load_ladder(n), {}) for n in ("drc", "ship", "stair")]
    plans, vals = expand_jobs(ladders, [1, 2, 3, small.RAISE_VALIDATE_SEED],
                              ["mixed", "position", "pwm"],
                              parse_perturb("placement=0.03,yaw=0.05,battery=44:50"), draws=2)
    with local_engine(2) as eng:
        local = run_batch(plans, vals, tmp_path / "local", eng, functions=SMALL)
    with dask_engine(workers=2, processes=False) as eng:
        assert eng.name == "dask" and eng.slots == 2
        dask = run_batch(plans, vals, tmp_path / "dask", eng, functions=SMALL)
    assert len(local.records) == len(plans) + len(vals)
    assert {r["outcome"] for r in local.records if r["status"] == "ok"} >= {"climbed",
                                                                              "failed"}
    assert len(local.errors) == len(dask.errors) == 3 * 2  # the raising seed: 3 ladders × 2 draws
    _same(local.records, dask.records)


def test_real_jobs_identical_on_dask_and_the_process_pool(tmp_path):
    """Plan + simulate for real (stair, first rung, ~6 s to plan) on both engines; one
    strategy (the fake-job test above covers the strategy axis)."""
    plans, vals = expand_jobs([("stair", load_ladder("stair"), {})], [3], ["mixed"],
                              parse_perturb("placement=0.02"), top_rung=0, time_limit_s=60)
    with local_engine(1) as eng:
        local = run_batch(plans, vals, tmp_path / "local", eng)
    with dask_engine(workers=1, processes=False) as eng:
        dask = run_batch(plans, vals, tmp_path / "dask", eng)
    assert not local.errors and not dask.errors
    assert len(local.records) == 2  # the plan and its validation
    _same(local.records, dask.records)
    # and the plans themselves are the same files, byte for byte
    traj = local.records[0].get("traj")
    if traj:
        assert (tmp_path / "local" / traj).read_bytes() == (tmp_path / "dask" / traj).read_bytes()
