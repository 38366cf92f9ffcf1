"""play-trajectory --clamp-limits: a real-style file whose knees end 0.0004 and 0.07 rad below
their 0 lower limit plays with the values clamped and reported; by default, or beyond the
tolerance, it is refused (exit 2) and nothing is sent. Against a real loop on shared memory."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from fake_daemon import running_daemon  # noqa: E402
from real_style_traj import real_style_rows, write_real_style  # noqa: E402

from daemon.channels import open_channel  # noqa: E402
from execute.play.cli import main as play_main  # noqa: E402
from robot.joints import JOINT_INDEX  # noqa: E402

RKN, LKN = JOINT_INDEX["RKN"], JOINT_INDEX["LKN"]
FAST = ["-f", "100", "-i", "--init-s", "0.3", "-q"]  # 60 lines in 0.6 s after a 0.3 s move


@pytest.fixture(scope="module")
def daemon():
    with running_daemon("play") as d:
        yield d


def _nothing_sent(instance: str) -> bool:
    ref = open_channel("ref", instance)
    try:
        return ref.read_latest() is None
    finally:
        ref.close()


def test_a_small_knee_overshoot_is_refused_by_default(daemon, tmp_path, capsys):
    instance, _, _ = daemon
    path = write_real_style(tmp_path / "squat.traj", real_style_rows())
    assert play_main(["-n", str(path), "--instance", instance, *FAST]) == 2
    err = capsys.readouterr().err
    assert "squat.traj:60:" in err and "(RKN): -0.07 rad is outside the joint limits" in err
    assert _nothing_sent(instance)


def test_a_large_overshoot_is_refused_even_with_clamp_limits(daemon, tmp_path, capsys):
    instance, _, _ = daemon
    path = write_real_style(tmp_path / "deep.traj", real_style_rows(knee_min_rad=(-0.3, 0.0)))
    code = play_main(["-n", str(path), "--instance", instance, "--clamp-limits", "0.1", *FAST])
    err = capsys.readouterr().err
    assert code == 2
    assert "(RKN): -0.3 rad is outside the joint limits [0, 2.61] rad by more than the " \
           "--clamp-limits tolerance 0.1 rad" in err
    assert _nothing_sent(instance)


def test_clamp_limits_plays_a_small_overshoot_clamped_and_reports_it(daemon, tmp_path, capsys):
    instance, loop, boards = daemon
    path = write_real_style(tmp_path / "squat.traj", real_style_rows())
    with boards.lock:
        boards.sent.clear()
    code = play_main(["-n", str(path), "--instance", instance, "--clamp-limits", "0.1", *FAST])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "--clamp-limits 0.1 rad: 14 value(s) on 2 joint(s) moved onto their limit" in err
    assert "RKN: 13 lines clamped (lines 48-60); largest overshoot 0.07 rad at line 60" in err
    assert "LKN: 1 line clamped (line 60); largest overshoot 0.0004 rad at line 60" in err
    with boards.lock:
        sent = np.array(boards.sent)
    assert sent[:, RKN].min() >= 0.0 and sent[:, LKN].min() >= 0.0
    assert sent[:, RKN].max() > 0.3  # it played the squat (0.6 rad, through the filter)
    assert int(loop.state["refs_rejected"]) == 0  # the daemon had nothing to reject
