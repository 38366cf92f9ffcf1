"""hubo-console: positions beyond a joint's limits and gains beyond the safety limits are
refused with exit 2, naming the joint, the value and the range, and nothing moves."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from fake_daemon import running_daemon  # noqa: E402

from daemon.channels import cleanup_stale, open_channel  # noqa: E402
from daemon.console import main as console_main  # noqa: E402
from robot.joints import JOINT_INDEX  # noqa: E402

RKN = JOINT_INDEX["RKN"]


@pytest.fixture(scope="module")
def daemon():
    with running_daemon("console") as d:
        yield d


def _settle(loop, ticks):
    end = loop.stats.ticks + ticks
    deadline = time.monotonic() + 10.0
    while loop.stats.ticks < end and time.monotonic() < deadline:
        time.sleep(0.01)


@pytest.mark.parametrize(("command", "value", "allowed"), [
    ("goto RKN 3.0", "3", "[0, 2.61]"),
    ("comp RKN -0.5", "-0.5", "[0, 2.61]"),
    ("goto REB 0.2", "0.2", "[-2.65, 0]"),
])
def test_a_position_beyond_the_limits_is_refused_and_nothing_moves(daemon, capsys, command,
                                                                    value, allowed):
    instance, loop, boards = daemon
    ref = open_channel("ref", instance)
    before = ref.read_latest()
    pos_before = boards.pos.copy()
    assert console_main(["--instance", instance, "-c", command]) == 2
    err = capsys.readouterr().err
    joint = command.split()[1]
    assert f"{command.split()[0]} {joint} {value} refused: {joint} is allowed {allowed} rad" \
        in err and "nothing sent" in err
    after = ref.read_latest()
    assert (before is None and after is None) or int(after["seq"]) == int(before["seq"])
    _settle(loop, 40)
    assert np.array_equal(boards.pos, pos_before)
    assert int(loop.state["refs_rejected"]) == 0  # refused before the channel
    ref.close()


def test_a_position_within_the_limits_moves_the_joint(daemon, capsys):
    instance, loop, boards = daemon
    assert console_main(["--instance", instance, "-c", "goto RKN 0.8"]) == 0
    _settle(loop, 300)  # the reference filter: 99.95 % in 1.5 s
    assert boards.pos[RKN] == pytest.approx(0.8, abs=0.01)
    assert console_main(["--instance", instance, "-c", "goto RKN 2.61"]) == 0  # on the limit


@pytest.mark.parametrize("command", ["kp RSP 70", "kd RSP 10", "maxPWM RSP 8", "kp RSP -1"])
def test_gains_beyond_the_safety_limits_are_refused(daemon, capsys, command):
    instance, loop, _ = daemon
    gains_before = loop.gains
    assert console_main(["--instance", instance, "-c", command]) == 2
    err = capsys.readouterr().err
    assert "refused" in err and "RSP" in err and "kp < 70, kd < 10, max_pwm < 8" in err
    _settle(loop, 10)
    assert loop.gains == gains_before


def test_gains_within_the_safety_limits_are_set(daemon):
    instance, loop, _ = daemon
    assert console_main(["--instance", instance, "-c", "kp RSP 69.9; kd RSP 9.9; "
                                                       "maxPWM RSP 7.9"]) == 0
    j = JOINT_INDEX["RSP"]
    assert (loop.gains.kp[j], loop.gains.kd[j], loop.gains.max_pwm_pct[j]) == (69.9, 9.9, 7.9)


def test_a_refused_command_is_reported_and_the_next_one_runs(daemon, capsys):
    instance, _, _ = daemon
    assert console_main(["--instance", instance, "-c", "frobnicate; goto RKN 3.0; quit; "
                                                       "bogus"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("hubo-console: unknown command 'frobnicate'; commands: homeAll")
    assert err[1].startswith("hubo-console: goto RKN 3 refused")
    assert len(err) == 2  # quit ends the commands


def test_no_daemon_is_a_one_line_failure(capsys):
    assert console_main(["--instance", "console-nobody", "-c", "statusAll"]) == 1
    err = capsys.readouterr().err
    assert err.strip() == "hubo-console: no hubo-daemon is ticking on instance 'console-nobody'"
    cleanup_stale("console-nobody")  # the channels the console opened to look
