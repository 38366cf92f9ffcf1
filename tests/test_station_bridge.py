"""hubo-init through hubo-bridge, on loopback only: the page's bridge link (state in,
commands out, the robot's answers shown as the local tools word them), bad option
combinations, and the page itself: a sim daemon, ``hubo-bridge robot`` beside it and
``hubo-init --bridge`` in another process, driven in headless Chromium. Every wait is
bounded in time."""

from __future__ import annotations

import io
import sys
import time
from contextlib import redirect_stderr
from pathlib import Path

import pytest

pytest.importorskip("zenoh")

sys.path.insert(0, str(Path(__file__).parent))

from fake_daemon import running_daemon  # noqa: E402
from test_bridge import Bridge  # noqa: E402
from test_daemon_e2e import Daemon  # noqa: E402
from test_station import Page, _free_port, needs_chromium  # noqa: E402
from test_station import home_one_joint_from_the_page as home_one_joint  # noqa: E402
from test_station import refusal_shown_and_nothing_sent as refusal_shown  # noqa: E402

from daemon.channels import open_channel  # noqa: E402
from daemon.remote.certs import make_certificates  # noqa: E402
from daemon.remote.session_config import TlsFiles  # noqa: E402
from daemon.station import LocalLink  # noqa: E402
from daemon.station.bridge_link import BridgeLink  # noqa: E402
from daemon.station.cli import main  # noqa: E402
from robot.joints import JOINT_INDEX, JOINT_NAMES  # noqa: E402

#: The bridge's refusal of a console command it does not carry (daemon/remote/robot.py).
NOT_OVER_THE_BRIDGE = "not allowed over the bridge; allowed: homeAll, home J"


@pytest.fixture(scope="module")
def pki(tmp_path_factory) -> Path:
    """A CA with the robot, a writer (op1) and a read-only operator (viewer)."""
    d = tmp_path_factory.mktemp("pki")
    make_certificates(d, "robot", ("op1", "viewer"))
    return d


def _listening(bridge: Bridge, timeout_s: float = 20.0) -> None:
    """Wait until the robot bridge process logged that it listens."""
    deadline = time.monotonic() + timeout_s
    while "bridge on " not in bridge.log_path.read_text():
        assert bridge.proc.poll() is None, bridge.log_path.read_text()
        assert time.monotonic() < deadline, "hubo-bridge robot did not start"
        time.sleep(0.1)


def _link(pki: Path, bridge: Bridge, instance: str, name: str = "op1") -> BridgeLink:
    """A bridge link that has received the robot's state."""
    _listening(bridge)
    link = BridgeLink(bridge.endpoint, TlsFiles.from_dir(pki, name), instance)
    deadline = time.monotonic() + 10.0
    while link.read() is None:
        if time.monotonic() > deadline:
            link.close()
            raise AssertionError("no state through the bridge")
        time.sleep(0.02)
    return link


def test_the_bridge_link_reads_the_state_and_carries_the_commands(pki, tmp_path):
    with running_daemon("station-bridge") as (instance, loop, boards):
        bridge = Bridge(pki, instance, tmp_path, "--rate-hz", "20")
        local = LocalLink(instance)
        link = None
        try:
            link = _link(pki, bridge, instance)
            first = link.read()
            assert first.ref_mode is None  # the ref channel does not come back
            assert 0 <= first.age_s() < 1.0
            t0 = int(first.state["time_ns"])
            deadline = time.monotonic() + 5.0
            while int(link.read().state["time_ns"]) == t0:
                assert time.monotonic() < deadline, "the state stopped after one sample"
                time.sleep(0.02)
            # the robot's console answers; its refusals read as the local console's
            done = loop.stats.cmds_done
            out = link.home("LKN")
            assert out.ok and loop.stats.cmds_done == done + 1
            remote, here = link.console_line("kp RSP 99"), local.console_line("kp RSP 99")
            assert not remote.ok and remote == here, (remote, here)
            assert remote.line().startswith("kp RSP 99 REFUSED: kp 99 for RSP refused")
            out = link.console_line("goto RKN 0.5")
            assert not out.ok and NOT_OVER_THE_BRIDGE in out.text
            assert loop.stats.cmds_done == done + 1 and loop.gains.kp[JOINT_INDEX["RSP"]] != 99
            with open_channel("ref", instance) as ref:
                assert ref.read_latest() is None  # goto sent nothing
            # hubo-neck's key and the player's stop, answered by the robot's tools
            assert link.neck_key("q") == ("neck q", True, "q  NKY goal +1.000 rad")
            out = link.stop_player()
            assert not out.ok and "no play-trajectory is playing" in out.text
            assert out == local.stop_player()
        finally:
            if link is not None:
                link.close()
            local.close()
            bridge.stop()


def test_a_page_whose_certificate_may_not_write_shows_no_answer(pki, tmp_path):
    with running_daemon("station-viewer") as (instance, loop, boards):
        bridge = Bridge(pki, instance, tmp_path)
        link = None
        try:
            link = _link(pki, bridge, instance, "viewer")  # it may read the state
            link.operator.timeout_s = 1.0
            done = loop.stats.cmds_done
            out = link.home_all()
            assert not out.ok and "no answer from the robot bridge" in out.text
            assert loop.stats.cmds_done == done
        finally:
            if link is not None:
                link.close()
            bridge.stop()


@pytest.mark.parametrize(("argv", "says"), [
    (["--bridge", "tls/127.0.0.1:7447"], "--bridge needs --tls-dir and --name"),
    (["--bridge", "tls/127.0.0.1:7447", "--name", "op1"], "--bridge needs --tls-dir and"),
    (["--tls-dir", "pki"], "--tls-dir refused without --bridge"),
    (["--tls-dir", "pki", "--name", "op1"], "--tls-dir and --name refused without --bridge"),
    (["--bridge", "tcp/127.0.0.1:7447", "--tls-dir", "{pki}", "--name", "op1"],
     "--bridge 'tcp/127.0.0.1:7447' refused: use tls/HOST:PORT"),
    (["--bridge", "tls/127.0.0.1:7447", "--tls-dir", "{pki}", "--name", "nobody"],
     "no file {pki}/nobody.pem"),
])
def test_bad_option_combinations_exit_2_in_one_line(pki, argv, says):
    err = io.StringIO()
    with redirect_stderr(err):
        assert main([a.format(pki=pki) for a in argv]) == 2
    assert err.getvalue().count("\n") == 1, err.getvalue()
    assert err.getvalue().startswith("hubo-init: ") and says.format(pki=pki) in err.getvalue()


def test_no_robot_bridge_to_connect_to_exits_1(pki, capsys):
    port = _free_port()  # nobody listens there
    assert main(["--bridge", f"tls/127.0.0.1:{port}", "--tls-dir", str(pki), "--name",
                 "op1", "--port", str(_free_port())]) == 1
    err = capsys.readouterr().err
    assert err.startswith("hubo-init: zenoh: ") and len(err.splitlines()) == 1, err


# ---------------------------------------------------------------- the page, in Chromium


@pytest.fixture(scope="module")
def bridged_page(pki, tmp_path_factory):
    """A sim daemon (not homed), its robot bridge, ``hubo-init --bridge`` as op1, Chromium."""
    tmp = tmp_path_factory.mktemp("station-bridge")
    daemon = Daemon(tmp, "station-bridge", "--backend", "sim").start()
    bridge = Bridge(pki, daemon.instance, tmp, "--rate-hz", "20")
    try:
        _listening(bridge)
        page = Page(tmp, daemon, ["--bridge", bridge.endpoint, "--tls-dir", str(pki),
                                  "--name", "op1", "--instance", daemon.instance])
    except BaseException:
        bridge.stop()
        daemon.close()
        raise
    page.bridge = bridge
    try:
        yield page
    finally:
        page.close(bridge.stop)


@needs_chromium
def test_the_bridged_page_shows_every_joint(bridged_page):
    page, b = bridged_page, bridged_page.browser
    b.wait_for("document.body.innerText.includes('homed 0/40')")
    assert f"through hubo-bridge at {page.bridge.endpoint}" in b.text()
    for name in JOINT_NAMES:
        assert page.row(name, "r.cells[5].textContent.trim()") == "NOT_HOMED"
    assert page.row("RKN", "r.cells[4].textContent.trim()") == "position"  # no ref mode
    assert "RHFT" in b.text() and "battery" in b.text()


@needs_chromium
def test_home_through_the_bridge_homes_the_chosen_joint(bridged_page):
    home_one_joint(bridged_page, "RKN")  # read back on the robot's channel


@needs_chromium
def test_a_command_the_bridge_refuses_shows_its_reason(bridged_page):
    refusal_shown(bridged_page, "goto RKN 0.5",
                  f"goto RKN 0.5 REFUSED: console command 'goto RKN 0.5' {NOT_OVER_THE_BRIDGE}")


@needs_chromium
def test_the_page_says_when_the_bridge_goes_silent(bridged_page):
    """Last: it stops the robot bridge."""
    page, b = bridged_page, bridged_page.browser
    b.wait_for("document.body.innerText.includes('homed ')")
    page.bridge.stop()
    b.wait_for("document.body.innerText.includes('the link is down, or the robot')", 15.0)
    assert "no state for " in b.text()
