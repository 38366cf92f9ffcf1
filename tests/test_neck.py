"""hubo-neck: each key steps its neck joint from the commanded goal, clamped to the joint's
limits; bad flags and unknown keys exit 2 and nothing moves. The key logic alone, then
against a daemon: the in-process one with perfect boards, and a sim (MuJoCo) daemon."""

from __future__ import annotations

import dataclasses
import os
import select
import sys
import termios
import time
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from fake_daemon import running_daemon  # noqa: E402
from test_daemon_e2e import Daemon  # noqa: E402

from daemon.channels import cleanup_stale, open_channel  # noqa: E402
from daemon.neck import (  # noqa: E402
    MOVE_KEYS,
    NeckConfig,
    default_config,
    main,
    next_goals,
    single_keys,
)
from daemon.structs import REF_DTYPE, new_sample  # noqa: E402
from robot.joints import JOINT_INDEX  # noqa: E402
from robot.limits import joint_limits  # noqa: E402

NKY, NK1, NK2 = (JOINT_INDEX[n] for n in ("NKY", "NK1", "NK2"))
LIMITS = joint_limits("drc-hubo")
ZERO = {"NKY": 0.0, "NK1": 0.0, "NK2": 0.0}


@pytest.mark.parametrize(("key", "joint", "step"), [
    ("w", "NK1", -0.3), ("s", "NK1", 0.3), ("a", "NK2", -0.3), ("d", "NK2", 0.3),
    ("q", "NKY", 1.0), ("e", "NKY", -1.0),
])
def test_each_key_steps_its_joint_and_leaves_the_others(key, joint, step):
    start = {"NKY": 0.2, "NK1": -0.1, "NK2": 0.05}
    move = next_goals(key, start, LIMITS, default_config())
    assert move.goals_rad[joint] == pytest.approx(start[joint] + step)
    assert move.moved == (joint,) and move.at_limit == ()
    assert {j: g for j, g in move.goals_rad.items() if j != joint} == \
        {j: g for j, g in start.items() if j != joint}
    assert move.line() == f"{key}  {joint} goal {start[joint] + step:+.3f} rad"


def test_a_step_stops_at_the_joint_limit_and_then_nothing_moves():
    hi = float(LIMITS.upper_rad[NKY])
    move = next_goals("q", {**ZERO, "NKY": hi - 0.5}, LIMITS, default_config())
    assert move.goals_rad["NKY"] == hi and move.at_limit == ("NKY",) and move.moved == ("NKY",)
    assert move.line() == f"q  NKY goal {hi:+.3f} rad  at its limit"
    again = next_goals("q", move.goals_rad, LIMITS, default_config())
    assert again.goals_rad["NKY"] == hi and again.moved == () and again.at_limit == ("NKY",)
    assert again.line().endswith("at its limit  (nothing sent)")
    lo = float(LIMITS.lower_rad[NK1])
    down = next_goals("w", {**ZERO, "NK1": lo + 0.1}, LIMITS, NeckConfig(step_rad=0.5))
    assert down.goals_rad["NK1"] == lo and down.at_limit == ("NK1",)


def test_centre_puts_every_neck_joint_to_zero_within_its_limits():
    lower = LIMITS.lower_rad.copy()
    lower[NK1] = 0.2  # a neck whose pitch range excludes 0
    limits = dataclasses.replace(LIMITS, lower_rad=lower)
    move = next_goals("c", {"NKY": 1.0, "NK1": 0.5, "NK2": -0.3}, limits, default_config())
    assert move.goals_rad == {"NKY": 0.0, "NK1": 0.2, "NK2": 0.0}
    assert move.at_limit == ("NK1",) and move.moved == ("NKY", "NK1", "NK2")
    assert "NK1 goal +0.200 rad  at its limit" in move.line()


def test_the_keys_follow_the_kinematic_tree_axes():
    from robot.kinematic_tree import build_tree
    from robot.params import robot_params

    axes = {n: link.axis for n, link in build_tree(robot_params("drc-hubo")).joint_links.items()}
    # NK1 turns about y: the pitch (w/s); NK2 about x: the roll (a/d); NKY about z (q/e)
    assert tuple(axes["NK1"]) == (0, 1, 0) and tuple(axes["NK2"]) == (1, 0, 0)
    assert tuple(axes["NKY"]) == (0, 0, 1)
    assert {MOVE_KEYS[k].joint for k in "ws"} == {"NK1"}
    assert {MOVE_KEYS[k].joint for k in "ad"} == {"NK2"}


def test_single_keys_reads_without_enter_and_restores_the_terminal():
    master, slave = os.openpty()
    try:
        before = termios.tcgetattr(slave)
        with pytest.raises(RuntimeError), single_keys(slave) as read_key:
            os.write(master, b"wq")  # no Enter: a line-buffered terminal holds these back
            assert select.select([slave], [], [], 2.0)[0], "keys not readable without Enter"
            assert (read_key(), read_key()) == ("w", "q")
            raise RuntimeError("restored even on an exception")
        assert termios.tcgetattr(slave) == before
    finally:
        os.close(master)
        os.close(slave)


@pytest.mark.parametrize(("argv", "message"), [
    (["--step", "0.6", "--keys", "w"], "--step 0.6 refused: allowed (0, 0.5] rad"),
    (["--step", "0", "--keys", "w"], "--step 0 refused: allowed (0, 0.5] rad"),
    (["--yaw-step", "1.6", "--keys", "q"], "--yaw-step 1.6 refused: allowed (0, 1.5] rad"),
    (["--yaw-step", "inf", "--keys", "q"], "--yaw-step 'inf' is not a number"),
    (["--keys", "wwz"], "--keys 'wwz': unknown key 'z' at position 3; keys: w s a d q e c x"),
])
def test_bad_flags_and_unknown_keys_exit_2_in_one_line_and_nothing_moves(capsys, argv,
                                                                         message):
    with running_daemon("neck-refused") as (instance, loop, boards):
        assert main(["--instance", instance, *argv]) == 2
        out, err = capsys.readouterr()
        assert out == "" and len(err.splitlines()) == 1
        assert err.startswith(f"hubo-neck: {message}")
        ticks = loop.stats.ticks
        while loop.stats.ticks < ticks + 20:
            time.sleep(0.01)
        for name in ("ref-neck", "ref"):
            channel = open_channel(name, instance)
            assert channel.read_latest() is None, name
            channel.close()
        assert not boards.pos.any()


def test_neck_goals_go_on_ref_neck_over_a_playing_reference(capsys):
    """A player's ``ref`` keeps the other joints; the neck steps from the player's neck
    entries and hubo-neck never writes ``ref``."""
    with running_daemon("neck-over-ref") as (instance, loop, boards):
        ref, state = open_channel("ref", instance), open_channel("state", instance)
        r = new_sample(REF_DTYPE)
        r["ref"][JOINT_INDEX["RSP"]], r["ref"][NKY] = -0.2, 0.2
        ref.write(r)
        seq = int(ref.read_latest()["seq"])
        assert main(["--instance", instance, "--keys", "qsx", "--yaw-step", "0.5"]) == 0
        assert capsys.readouterr().out.splitlines() == ["q  NKY goal +0.700 rad",
                                                        "s  NK1 goal +0.300 rad"]
        assert int(ref.read_latest()["seq"]) == seq
        ref.close()
        s = state.read_latest()
        deadline = time.monotonic() + 10.0
        while abs(s["pos"][NKY] - 0.7) > 2e-3 and time.monotonic() < deadline:
            s = state.wait_newer(int(s["time_ns"]), 1.0) or s
        state.close()
        assert s["pos"][[NKY, NK1, NK2]] == pytest.approx([0.7, 0.3, 0.0], abs=2e-3)
        assert s["pos"][JOINT_INDEX["RSP"]] == pytest.approx(-0.2, abs=2e-3)


def test_sim_daemon_neck_follows_the_keys_and_stops_at_its_limit(tmp_path, capsys):
    """A MuJoCo daemon with no reference yet (hubo-neck sends the console's hold first):
    the joints read back from the state channel move by the steps, and the yaw stops on
    its limit: no tick of the daemon's log commands or reads it past the limit.

    The head settles after each yaw key: keys within a fraction of a second whip the
    simulated head past its goal, here 0.05 rad past the limit (docs/daemon.md, hubo-neck)."""
    hi = float(LIMITS.upper_rad[NKY])
    d = Daemon(tmp_path, "neck", "--backend", "sim", "--homed")

    def settled(joint: int, rad: float):
        return lambda s: abs(s["pos"][joint] - rad) < 0.02 and abs(s["vel"][joint]) < 0.05

    try:
        d.start()
        assert main(["--instance", d.instance, "--keys", "wwd"]) == 0
        s = d.wait_until(lambda s: settled(NK1, -0.6)(s) and settled(NK2, 0.3)(s), 10.0)
        assert s["pos"][NKY] == pytest.approx(0.0, abs=0.02)
        for goal in (1.0, 2.0, 3.0):  # one key at a time, as the operator watching
            assert main(["--instance", d.instance, "--keys", "q"]) == 0
            d.wait_until(settled(NKY, goal), 10.0)
        assert main(["--instance", d.instance, "--keys", "qq"]) == 0
        assert capsys.readouterr().out.splitlines() == [
            "w  NK1 goal -0.300 rad", "w  NK1 goal -0.600 rad", "d  NK2 goal +0.300 rad",
            "q  NKY goal +1.000 rad", "q  NKY goal +2.000 rad", "q  NKY goal +3.000 rad",
            f"q  NKY goal {hi:+.3f} rad  at its limit",
            f"q  NKY goal {hi:+.3f} rad  at its limit  (nothing sent)"]
        d.wait_until(settled(NKY, hi), 10.0)
        neck = open_channel("ref-neck", d.instance)
        seq = int(neck.read_latest()["seq"])
        assert main(["--instance", d.instance, "--keys", "eez"]) == 2
        assert int(neck.read_latest()["seq"]) == seq  # refused before anything moved
        neck.close()
        time.sleep(0.5)
        d.stop()
    finally:
        d.close()
        cleanup_stale(d.instance)
    rec = d.records()
    assert rec["ref_cmd"][:, NKY].max() <= hi and rec["ref"][:, NKY].max() <= hi
    assert rec["pos"][:, NKY].max() <= hi + 1e-3
    assert rec["pos"][-1, NKY] == pytest.approx(hi, abs=0.02)
    assert int(rec["refs_rejected"][-1]) == 0  # clamped here: the daemon never had to reject
    assert np.abs(rec["pos"][-1, [NK1, NK2]] - [-0.6, 0.3]).max() < 0.02
