"""Every command that takes a ``.traj`` takes a ``.traj.gz`` (issue 20 item 10): plan-ladder
writes one (sidecar ``NAME.plan.json`` next to it), check-plan and validate-plan read it,
play-trajectory plays it."""

from __future__ import annotations

import gzip
import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from fake_daemon import running_daemon  # noqa: E402
from make_fixture import cached_reach_fixture  # noqa: E402
from real_style_traj import real_style_rows, write_real_style  # noqa: E402
from synthetic_plan import use_synthetic_search  # noqa: E402

from execute.play.cli import main as play_main  # noqa: E402
from execute.validate.cli import main as validate_main  # noqa: E402
from planner.cli import main as plan_main  # noqa: E402
from planner.verify import cli as check_plan_cli  # noqa: E402
from robot.joints import JOINT_INDEX  # noqa: E402
from robot.plan_sidecar import read_sidecar, sidecar_path  # noqa: E402
from robot.trajectory_file import read_trajectory  # noqa: E402


@pytest.fixture
def fake_search(monkeypatch):
    """The search replaced by the synthetic plan (the real one is slow for now)."""
    return use_synthetic_search(monkeypatch)


def test_plan_ladder_writes_gz_and_check_plan_reads_it(fake_search, tmp_path, capsys):
    gz, plain = tmp_path / "climb.traj.gz", tmp_path / "plain" / "climb.traj"
    plain.parent.mkdir()
    assert plan_main(["drc", "--top-rung", "0", "-o", str(gz)]) == 0
    assert plan_main(["drc", "--top-rung", "0", "-o", str(plain)]) == 0
    assert f"wrote {gz} and {tmp_path / 'climb.plan.json'}" in capsys.readouterr().err
    assert gz.read_bytes()[:2] == b"\x1f\x8b"
    assert gzip.decompress(gz.read_bytes()) == plain.read_bytes()
    assert read_sidecar(sidecar_path(gz)).line_count == len(read_trajectory(gz, 200.0))
    assert check_plan_cli.main([str(gz), "--ladder", "drc", "--every", "25"]) == 0


def test_validate_plan_reads_gz(tmp_path_factory, tmp_path, capsys):
    plan = cached_reach_fixture(tmp_path_factory.getbasetemp())
    gz = tmp_path / "reach.traj.gz"
    gz.write_bytes(gzip.compress(plan.read_bytes()))
    shutil.copy(sidecar_path(plan), sidecar_path(gz))
    out = tmp_path / "r.json"
    assert validate_main([str(gz), "--strategy", "mixed", "--open-loop", "--json",
                          str(out)]) == 0
    assert json.loads(out.read_text())["verdict"] == "climbed"
    assert not (tmp_path / "reach.traj.plan.json").exists()


def test_play_trajectory_plays_gz(tmp_path, capsys):
    plain = write_real_style(tmp_path / "squat.traj", real_style_rows(knee_min_rad=(0.1, 0.1)))
    gz = tmp_path / "squat.traj.gz"
    gz.write_bytes(gzip.compress(plain.read_bytes()))
    with running_daemon("playgz") as (instance, _, boards):
        code = play_main(["-n", str(gz), "--instance", instance, "-f", "100", "-i",
                          "--init-s", "0.3", "-q"])
        assert code == 0, capsys.readouterr().err
        with boards.lock:
            sent = np.array(boards.sent)
    assert sent[:, JOINT_INDEX["RKN"]].max() > 0.3  # it played the squat
