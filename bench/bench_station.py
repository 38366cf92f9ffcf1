"""Benchmark: ``hubo-init --bridge``'s state source on loopback, state write → arrival at
the page's `daemon.station.bridge_link.BridgeLink`.

Three processes, as with the robot and the operator's computer: the daemon's stand-in
writing a ``state`` sample every 5 ms (`bench.bench_bridge`'s writer), a ``hubo-bridge
robot`` process (mutual TLS, access control) publishing at hubo-init's default pull
(10 Hz) and at the page's fastest refresh (20 Hz), and this process, the page's
`BridgeLink`. Latency: the link's arrival stamp (``StateReading.received_ns``, taken in
zenoh's callback) minus the sample's ``time_ns`` (stamped by the channel write; one host,
one clock). The page's own refresh (its timer, at ``--rate-hz``) comes on top.

No target: the issue asks for the figure (docs/daemon.md, "The operator's page").
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np

from bench.bench_bridge import robot_bridge, state_writer_and_pki

log = logging.getLogger(__name__)

RATES_HZ = (10.0, 20.0)
SAMPLES = 300  # measured samples per rate (30 s at 10 Hz, 15 s at 20 Hz)
WARM_UP_S = 1.0
POLL_S = 0.002  # how often the link is read; the arrival stamp does not depend on it [s]


def _open_link(endpoint: str, pki: Path, instance: str):
    """The page's link as op1, once the bridge listens (at most 10 s)."""
    from daemon.remote.session_config import TlsFiles
    from daemon.station.bridge_link import BridgeLink
    from robot.errors import HuboLadderError

    deadline = time.monotonic() + 10.0
    while True:
        try:
            return BridgeLink(endpoint, TlsFiles.from_dir(pki, "op1"), instance)
        except HuboLadderError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)


def measure(rate_hz: float, pki: Path, instance: str) -> np.ndarray:
    """Latencies [µs] of `SAMPLES` state samples through the bridge at ``rate_hz``."""
    lat_ns: list[int] = []
    with robot_bridge(pki, instance, rate_hz) as (endpoint, _):
        link = _open_link(endpoint, pki, instance)
        try:
            time.sleep(WARM_UP_S)
            last_ns = 0
            deadline = time.monotonic() + 3.0 * SAMPLES / rate_hz  # bounded
            while len(lat_ns) < SAMPLES and time.monotonic() < deadline:
                r = link.read()
                if r is not None and int(r.state["time_ns"]) != last_ns:
                    last_ns = int(r.state["time_ns"])
                    lat_ns.append(r.received_ns - last_ns)
                time.sleep(POLL_S)
        finally:
            link.close()
    if len(lat_ns) < SAMPLES:
        raise RuntimeError(f"{len(lat_ns)} of {SAMPLES} samples arrived at {rate_hz:g} Hz")
    return np.array(lat_ns, dtype=float) * 1e-3


def run() -> list[dict]:
    """Figures per rate: latency median, p99 and max [ms]."""
    figures = []
    with state_writer_and_pki("bench-station") as (instance, pki):
        for rate_hz in RATES_HZ:
            lat_us = measure(rate_hz, pki, instance)
            med, p99 = np.median(lat_us), np.percentile(lat_us, 99)
            log.info("page link at %g Hz: %d samples, median %.0f µs, p99 %.0f µs",
                     rate_hz, lat_us.size, med, p99)
            tag = f"at {rate_hz:g} Hz, {lat_us.size} samples, loopback, TLS"
            figures += [
                {"name": f"state write→hubo-init's bridge link, {what} ({tag})",
                 "value": round(float(v) / 1e3, 3), "unit": "ms", "target": None}
                for what, v in (("median", med), ("p99", p99), ("max", lat_us.max()))]
    return figures
