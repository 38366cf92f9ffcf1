"""Benchmark: write → blocked-reader-wakes latency of `daemon.channels.ShmChannel`, beside
the operating system's floor measured in the same run.

Two separate processes: a writer writes every ~0.5 ms (uniform 0.25–0.75 ms); a reader
blocks and, on waking, takes ``CLOCK_MONOTONIC`` minus the writer's stamp. For the channel
the stamp is the ``ref`` sample's ``time_ns`` (741 B), taken at the start of `write`, so
the copy and the publish are included. The floor is a bare futex wake between the same two
processes: the writer stamps a shared word, changes the futex word and wakes, through the
channel's own ctypes calls; the reader sleeps on the word. The floor depends on the
machine's load (9–30 µs on the 2-core VM), so the two are measured in interleaved rounds
(floor, channel, floor, ...) and the issue's target is their ratio: channel median
≤ 1.2 × floor median (issue 26). Issue 5's absolute targets (median 11 µs, p99 50 µs, the
thesis's Ach figures) are printed too. If ``iceoryx2`` is importable (it is not a
dependency), its publish/subscribe + event service joins the rounds, for comparison.
"""

from __future__ import annotations

import ctypes
import importlib.util
import logging
import multiprocessing as mp
import os
import time
from pathlib import Path

import numpy as np

log = logging.getLogger(__name__)

MEDIAN_TARGET_US = 11.0  #: issue 5, absolute
P99_TARGET_US = 50.0  #: issue 5, absolute
FLOOR_RATIO_TARGET = 1.2  #: issue 26: channel median / floor median, same run
ROUNDS = 8  #: interleaved rounds of every mechanism
SAMPLES_PER_ROUND = 300
WARM_UP_SAMPLES = 20  #: dropped at the start of every round
PERIOD_S = 0.0005  #: mean time between writes [s]
WAIT_TIMEOUT_S = 0.5  #: a reader's longest single wait [s]


# ---------------------------------------------------------------- mechanisms
# Each is a pair of factories (reader, writer) called in their own process with the run's
# instance name and a shared int64 array; a reader's function blocks once and returns the
# latency [ns] of the write that woke it (None on a timeout), a writer's writes once.


def _floor_words(shared) -> tuple[ctypes.Array, ctypes.c_uint32, ctypes.c_void_p]:
    """The floor's words in ``shared``: the stamp (int64 0), the futex word (low half of
    int64 1) and the futex word's address."""
    addr = ctypes.addressof(shared) + 8
    return shared, ctypes.c_uint32.from_address(addr), ctypes.c_void_p(addr)


def _futex_reader(instance: str, shared):
    from daemon.channels import _futex_wait

    stamp, word, addr = _floor_words(shared)

    def wait() -> int | None:
        generation = word.value
        _futex_wait(addr, generation, WAIT_TIMEOUT_S)
        now = time.monotonic_ns()
        return now - stamp[0] if word.value != generation else None

    return wait


def _futex_writer(instance: str, shared):
    from daemon.channels import _futex_wake_all

    stamp, word, addr = _floor_words(shared)

    def write() -> None:
        t_ns = time.monotonic_ns()
        stamp[0] = t_ns
        word.value = t_ns & 0xFFFFFFFF
        _futex_wake_all(addr)

    return write


def _channel_reader(instance: str, shared):
    from daemon.channels import ShmChannel

    ch = ShmChannel("ref", instance)
    last_ns = 0

    def wait() -> int | None:
        nonlocal last_ns
        sample = ch.wait_newer(last_ns, WAIT_TIMEOUT_S)
        now = time.monotonic_ns()
        if sample is None:
            return None
        last_ns = int(sample["time_ns"])
        return now - last_ns

    return wait


def _channel_writer(instance: str, shared):
    from daemon.channels import ShmChannel
    from daemon.structs import REF_DTYPE, new_sample

    ch = ShmChannel("ref", instance)
    sample = new_sample(REF_DTYPE)
    return lambda: ch.write(sample)


def _iox_ports(instance: str, publisher: bool):
    """iceoryx2 0.10 publish/subscribe + event service carrying the ``ref`` struct."""
    import iceoryx2 as iox

    from daemon.structs import REF_DTYPE

    class Ref(ctypes.Structure):
        _pack_ = 1
        _fields_ = [("raw", ctypes.c_uint8 * REF_DTYPE.itemsize)]

        @staticmethod
        def type_name() -> str:
            return "HuboRef"

    cfg = iox.config.default()
    cfg.global_cfg.prefix = iox.FileName.new(f"hubo-bench-{instance}-")
    node = (
        iox.NodeBuilder.new()
        .config(cfg)
        .signal_handling_mode(iox.SignalHandlingMode.Disabled)
        .create(iox.ServiceType.Ipc)
    )
    ps = (
        node.service_builder(iox.ServiceName.new("hubo/ref"))
        .publish_subscribe(Ref)
        .max_publishers(8)
        .history_size(1)
        .subscriber_max_buffer_size(1)
        .enable_safe_overflow(True)
        .open_or_create()
    )
    ev = node.service_builder(iox.ServiceName.new("hubo/ref/event")).event().open_or_create()
    if publisher:
        return node, Ref, ps.publisher_builder().create(), ev.notifier_builder().create()
    return node, Ref, ps.subscriber_builder().create(), ev.listener_builder().create()


def _iox_reader(instance: str, shared):
    import iceoryx2 as iox

    from daemon.structs import REF_DTYPE

    node, _ref, sub, listener = _iox_ports(instance, publisher=False)
    timeout = iox.Duration.from_millis(int(WAIT_TIMEOUT_S * 1000))

    def wait() -> int | None:
        _ = node  # the node owns the ports: keep it alive with them
        listener.timed_wait(timeout)
        newest = None
        while (sample := sub.receive()) is not None:  # drain: keep the newest
            newest = bytes(sample.payload().contents.raw)
        if newest is None:
            return None
        return time.monotonic_ns() - int(np.frombuffer(newest, REF_DTYPE)[0]["time_ns"])

    return wait


def _iox_writer(instance: str, shared):
    from daemon.structs import REF_DTYPE, new_sample

    node, ref_type, pub, notifier = _iox_ports(instance, publisher=True)
    sample, payload = new_sample(REF_DTYPE), ref_type()

    def write() -> None:
        _ = node
        sample["time_ns"] = time.monotonic_ns()
        payload.raw[:] = sample.tobytes()
        pub.send_copy(payload)
        notifier.notify()

    return write


_MECHANISMS = {
    "futex": (_futex_reader, _futex_writer),
    "channel": (_channel_reader, _channel_writer),
    "iceoryx2": (_iox_reader, _iox_writer),
}


# ---------------------------------------------------------------- the two processes


def _reader(mechanisms, instance, shared, barrier, done, out) -> None:
    waits = {m: _MECHANISMS[m][0](instance, shared) for m in mechanisms}
    latencies = {m: [] for m in mechanisms}
    for _ in range(ROUNDS):
        for m in mechanisms:
            got = []
            barrier.wait(60)
            deadline = time.monotonic() + 30.0
            while len(got) < SAMPLES_PER_ROUND and time.monotonic() < deadline:
                lat_ns = waits[m]()
                if lat_ns is not None:
                    got.append(lat_ns)
            done.value = 1
            barrier.wait(60)  # the writer has stopped
            done.value = 0  # before the next round's first barrier, which the writer awaits
            latencies[m].extend(got[WARM_UP_SAMPLES:])
    out.put(latencies)


def _writer(mechanisms, instance, shared, barrier, done) -> None:
    writes = {m: _MECHANISMS[m][1](instance, shared) for m in mechanisms}
    sleeps_s = (PERIOD_S * (0.5 + np.random.default_rng(0).random(4096))).tolist()
    for _ in range(ROUNDS):
        for m in mechanisms:
            barrier.wait(60)
            k = 0
            while not done.value:
                # Like a control loop: write, then sleep. Work done between the write and
                # the sleep would delay a reader that the kernel woke on the writer's CPU.
                writes[m]()
                time.sleep(sleeps_s[k % len(sleeps_s)])
                k += 1
            barrier.wait(60)


def measure_latencies(mechanisms: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Write → wake latencies [µs] per mechanism, from `ROUNDS` interleaved rounds of
    `SAMPLES_PER_ROUND` writes between two fresh processes.

    Args:
        mechanisms: out of ``"futex"`` (the floor), ``"channel"`` and ``"iceoryx2"``.
    """
    from daemon.channels import cleanup_stale

    ctx = mp.get_context("spawn")
    instance = f"bench{os.getpid()}"
    shared = ctx.RawArray(ctypes.c_int64, 2)
    barrier, done, out = ctx.Barrier(2), ctx.RawValue(ctypes.c_int, 0), ctx.Queue()
    args = (mechanisms, instance, shared, barrier, done)
    reader = ctx.Process(target=_reader, args=(*args, out), daemon=True)
    writer = ctx.Process(target=_writer, args=args, daemon=True)
    reader.start()
    writer.start()
    try:
        latencies = out.get(timeout=300)
    finally:
        for p in (reader, writer):
            p.join(10)
            if p.is_alive():
                p.kill()
        cleanup_stale(instance)
        for root, pattern in (("/tmp/iceoryx2", "**/"), ("/dev/shm", "")):
            for leftover in Path(root).glob(f"{pattern}hubo-bench-{instance}-*"):
                leftover.unlink(missing_ok=True)  # iceoryx2's files of this run
    return {m: np.asarray(v, dtype=float) / 1e3 for m, v in latencies.items()}


def run() -> list[dict]:
    """Figures: the channel's median and p99 write → wake latency between two processes
    [µs], the floor's, and the ratio of the medians."""
    from daemon.structs import REF_DTYPE

    mechanisms = ("futex", "channel")
    if importlib.util.find_spec("iceoryx2") is not None:  # the candidate we did not pick
        mechanisms += ("iceoryx2",)
    lat = measure_latencies(mechanisms)
    floor = float(np.median(lat["futex"]))
    med, p99 = float(np.median(lat["channel"])), float(np.percentile(lat["channel"], 99))
    ratio = med / floor
    log.info("channel %.1f / %.1f µs, floor %.1f µs, ratio %.2f over %d rounds",
             med, p99, floor, ratio, ROUNDS)
    setup = f"2 processes, {REF_DTYPE.itemsize} B"
    figures = [
        {"name": f"channel write→wake latency, median ({setup})", "value": round(med, 2),
         "unit": "µs", "target": MEDIAN_TARGET_US, "ok": med <= MEDIAN_TARGET_US},
        {"name": f"channel write→wake latency, p99 ({setup})", "value": round(p99, 2),
         "unit": "µs", "target": P99_TARGET_US, "ok": p99 <= P99_TARGET_US},
        {"name": "OS floor: bare futex wake, median (same processes, interleaved rounds)",
         "value": round(floor, 2), "unit": "µs", "target": None, "ok": True},
        {"name": "OS floor: bare futex wake, p99",
         "value": round(float(np.percentile(lat["futex"], 99)), 2), "unit": "µs",
         "target": None, "ok": True},
        {"name": "channel median / floor median (same run)", "value": round(ratio, 2),
         "unit": "×", "target": FLOOR_RATIO_TARGET, "ok": ratio <= FLOOR_RATIO_TARGET},
    ]
    if "iceoryx2" in lat:
        for label, value in (("median", np.median(lat["iceoryx2"])),
                             ("p99", np.percentile(lat["iceoryx2"], 99))):
            figures.append({"name": f"for comparison: iceoryx2 0.10 pub/sub + event, {label}",
                            "value": round(float(value), 2), "unit": "µs", "target": None,
                            "ok": True})
    return figures
