"""Benchmark: ``hubo-bridge`` on loopback, state write → arrival at a bridge subscriber.

Three processes, as on the robot and the operator's computer: a state writer standing in
for the daemon (a ``state`` sample, 2200 B, every 5 ms on absolute deadlines), a
``hubo-bridge robot`` process (mutual TLS, access control), and this process, an
operator's `BridgeOperator` subscribed to the state. Latency: ``CLOCK_MONOTONIC`` at the
subscriber's callback minus the sample's ``time_ns`` (stamped by the channel write; one
host, one clock). Bandwidth at 10 and 200 Hz: the state payload received per second,
and what the bridge process wrote to its sockets per second (``/proc/PID/io`` ``wchar``:
zenoh framing and TLS records included; the bridge logs nothing at its default level).

No target: the issue asks for the figures (docs/daemon.md, "Over the network").
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing as mp
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

log = logging.getLogger(__name__)

RATES_HZ = (10.0, 200.0)
DURATION_S = 6.0  # measured window per rate [s]
WARM_UP_S = 1.0


def _write_states(instance: str, stop) -> None:
    """The daemon's stand-in: one state sample every 5 ms until ``stop`` is set."""
    from daemon.channels import open_channel
    from daemon.loop import sleep_until_ns
    from daemon.structs import STATE_DTYPE, new_sample

    state = open_channel("state", instance)
    s = new_sample(STATE_DTYPE)
    deadline = time.monotonic_ns()
    while not stop.is_set():
        s["tick"] += 1
        state.write(s)
        deadline += 5_000_000
        sleep_until_ns(deadline)
    state.close()


def _wchar(pid: int) -> int:
    for line in Path(f"/proc/{pid}/io").read_text().splitlines():
        if line.startswith("wchar:"):
            return int(line.split()[1])
    raise RuntimeError("no wchar in /proc/PID/io")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def robot_bridge(pki: Path, instance: str, rate_hz: float):
    """A ``hubo-bridge robot`` process on a free loopback port, op1 its writer; yields
    ``(endpoint, process)`` and stops it (SIGTERM) after."""
    endpoint = f"tls/127.0.0.1:{_free_port()}"
    bridge = subprocess.Popen(
        [str(Path(sys.executable).with_name("hubo-bridge")), "robot", "--tls-dir", str(pki),
         "--listen", endpoint, "--instance", instance, "--allow-writer", "op1",
         "--rate-hz", f"{rate_hz:g}"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        yield endpoint, bridge
    finally:
        bridge.send_signal(signal.SIGTERM)
        bridge.wait(10)


@contextlib.contextmanager
def state_writer_and_pki(name: str):
    """The daemon's stand-in writing on a fresh instance (`_write_states`, its own
    process) and a CA with the robot's and op1's certificates; yields ``(instance, pki)``
    and removes the instance's channel files after."""
    from daemon.channels import cleanup_stale
    from daemon.remote.certs import make_certificates

    instance = f"{name}-{os.getpid()}"
    ctx = mp.get_context("spawn")
    stop = ctx.Event()
    writer = ctx.Process(target=_write_states, args=(instance, stop), daemon=True)
    writer.start()
    try:
        with tempfile.TemporaryDirectory() as tmp:
            make_certificates(tmp, "robot", ("op1",))
            yield instance, Path(tmp)
    finally:
        stop.set()
        writer.join(5)
        cleanup_stale(instance)


def measure(rate_hz: float, pki: Path, instance: str) -> dict:
    """One rate: latencies [µs], payload and wire bandwidth [B/s]."""
    from daemon.remote.operator import BridgeOperator, wait_first_state
    from daemon.remote.session_config import TlsFiles

    lat_ns: list[int] = []
    with robot_bridge(pki, instance, rate_hz) as (endpoint, bridge):
        op = None
        for _ in range(50):  # until the bridge listens
            try:
                op = BridgeOperator(endpoint, TlsFiles.from_dir(pki, "op1"), instance,
                                    on_state=lambda s: lat_ns.append(
                                        time.monotonic_ns() - int(s["time_ns"])))
                break
            except Exception:  # noqa: BLE001 - not listening yet
                time.sleep(0.2)
        if op is None:
            raise RuntimeError("the bridge did not start")
        wait_first_state(op, 5.0)
        time.sleep(WARM_UP_S)
        lat_ns.clear()
        n0, b0, w0, t0 = op.states_received, op.state_bytes, _wchar(bridge.pid), time.monotonic()
        time.sleep(DURATION_S)
        n1, b1, w1, t1 = op.states_received, op.state_bytes, _wchar(bridge.pid), time.monotonic()
        lat = np.array(lat_ns[:], dtype=float) * 1e-3
        op.close()
    dt = t1 - t0
    return {"n": n1 - n0, "rate_hz": (n1 - n0) / dt, "lat_us": lat,
            "payload_Bps": (b1 - b0) / dt, "wire_Bps": (w1 - w0) / dt}


def run() -> list[dict]:
    """Figures per rate: latency median and p99 [ms], samples/s, bandwidth [kB/s]."""
    figures = []
    with state_writer_and_pki("bench-bridge") as (instance, pki):
        for rate_hz in RATES_HZ:
            m = measure(rate_hz, pki, instance)
            med, p99 = np.median(m["lat_us"]), np.percentile(m["lat_us"], 99)
            log.info("bridge at %g Hz: %d samples, median %.0f µs, p99 %.0f µs", rate_hz,
                     m["n"], med, p99)
            tag = f"at {rate_hz:g} Hz, loopback, TLS"
            figures += [
                {"name": f"state write→bridge subscriber latency, median ({tag})",
                 "value": round(float(med) / 1e3, 3), "unit": "ms", "target": None},
                {"name": f"state write→bridge subscriber latency, p99 ({tag})",
                 "value": round(float(p99) / 1e3, 3), "unit": "ms", "target": None},
                {"name": f"states received per second ({tag})",
                 "value": round(m["rate_hz"], 1), "unit": "1/s", "target": None},
                {"name": f"state payload bandwidth ({tag})",
                 "value": round(m["payload_Bps"] / 1e3, 2), "unit": "kB/s", "target": None},
                {"name": f"bridge socket writes, framing and TLS included ({tag})",
                 "value": round(m["wire_Bps"] / 1e3, 2), "unit": "kB/s", "target": None},
            ]
    return figures
