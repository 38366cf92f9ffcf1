"""Latest-value channels: in-process and between real processes (shared memory)."""

from __future__ import annotations

import gc
import logging
import multiprocessing as mp
import os
import signal
import struct
import threading
import time

import numpy as np
import pytest

from daemon import channels as ch
from daemon.channels import (
    ChannelError,
    InProcessChannel,
    ShmChannel,
    channel_path,
    cleanup_stale,
    open_channel,
    reset_in_process,
)
from daemon.structs import REF_DTYPE, STATE_DTYPE, new_sample

CTX = mp.get_context("spawn")


@pytest.fixture()
def instance(request):
    name = f"t{os.getpid()}-{request.node.name[:20]}".replace("[", "-").replace("]", "")
    name = "".join(c for c in name if c.isalnum() or c in "-_")[:40]
    yield name
    reset_in_process(name)
    gc.collect()  # channels a failed test left open
    cleanup_stale(name)


def _ref(value: float) -> np.ndarray:
    s = new_sample(REF_DTYPE)
    s["ref"][:] = value
    return s


# ---------------------------------------------------------------- child processes


def _child_write(instance: str, values: list[float], delay_s: float, writer_id: int) -> None:
    c = ShmChannel("ref", instance, writer_id=writer_id)
    time.sleep(delay_s)
    for v in values:
        c.write(_ref(v))
    c.close()


def _child_write_forever(instance: str, started) -> None:
    c = ShmChannel("ref", instance, writer_id=66)
    k = 0
    while True:
        c.write(_ref(float(k)))
        if k == 10:
            started.set()
        k += 1


def _child_write_fast(instance: str, duration_s: float) -> None:
    c = ShmChannel("ref", instance, writer_id=9)
    s = new_sample(REF_DTYPE)
    k = 0
    end = time.monotonic() + duration_s
    while time.monotonic() < end:
        k += 1
        s["ref"][:] = k
        s["mode"][:] = k % 4
        c.write(s)
    c.close()


def _child_wait(instance: str, last: int, out) -> None:
    c = ShmChannel("ref", instance)
    s = c.wait_newer(last, 5.0)
    out.put(None if s is None else float(s["ref"][0]))
    c.close()


def _run(target, *args):
    p = CTX.Process(target=target, args=args, daemon=True)
    p.start()
    return p


# ---------------------------------------------------------------- both implementations


@pytest.mark.parametrize("in_process", [True, False], ids=["inproc", "shm"])
def test_latest_value_semantics(instance, in_process):
    a = open_channel("ref", instance, writer_id=1, in_process=in_process)
    b = open_channel("ref", instance, writer_id=2, in_process=in_process)
    assert b.read_latest() is None
    t1 = a.write(_ref(1.0))
    a.write(_ref(2.0))
    got = b.read_latest()
    assert float(got["ref"][5]) == 2.0 and int(got["writer_id"]) == 1 and int(got["seq"]) == 2
    assert int(got["time_ns"]) > t1
    b.write(_ref(3.0))  # the newest, from another writer
    assert float(a.read_latest()["ref"][0]) == 3.0
    assert int(a.read_latest()["writer_id"]) == 2
    got["ref"][0] = 99.0  # a copy: changing it changes nothing on the channel
    assert float(a.read_latest()["ref"][0]) == 3.0
    a.close()
    b.close()


@pytest.mark.parametrize("in_process", [True, False], ids=["inproc", "shm"])
def test_wait_newer_times_out_and_wakes(instance, in_process):
    r = open_channel("ref", instance, in_process=in_process)
    w = open_channel("ref", instance, in_process=in_process)
    t0 = time.monotonic()
    assert r.wait_newer(0, 0.05) is None
    assert 0.04 <= time.monotonic() - t0 < 1.0
    stamp = w.write(_ref(1.0))
    assert float(r.wait_newer(0, 0.0)["ref"][0]) == 1.0  # already there: no wait
    assert r.wait_newer(stamp, 0.0) is None
    timer = threading.Timer(0.05, lambda: w.write(_ref(2.0)))
    timer.start()
    got = r.wait_newer(stamp, 5.0)
    timer.join()
    assert got is not None and float(got["ref"][0]) == 2.0
    r.close()
    w.close()


def _wait_for_a_later_write(r, w, k: int, delay_s: float, stamp: int) -> int:
    """``w`` writes value ``k`` after ``delay_s`` from a timer thread while ``r`` waits (up
    to 10 s) for a sample newer than ``stamp``; the reader must get it within 5 s (with
    ``WAKE_SLICE_S`` pushed out, only a wake-up gets it there). Returns its stamp."""
    timer = threading.Timer(delay_s, w.write, args=(_ref(float(k)),))
    timer.start()
    t0 = time.monotonic()
    got = r.wait_newer(stamp, 10.0)
    waited_s = time.monotonic() - t0
    timer.join()
    assert got is not None and float(got["ref"][0]) == k
    assert waited_s < 5.0, f"write {k} did not wake the reader"
    return int(got["time_ns"])


def test_a_blocked_reader_is_woken_by_each_write_not_by_its_re_check(instance, monkeypatch):
    """Every write wakes a blocked shared-memory reader: with the periodic re-check pushed
    out to 30 s, a lost wake-up leaves ``wait_newer`` asleep for its whole 10 s timeout
    (the bound below is 2,500 times a wake-up). Writes land at random moments around the
    reader's check-then-sleep."""
    monkeypatch.setattr(ch, "WAKE_SLICE_S", 30.0)
    r, w = ShmChannel("ref", instance), ShmChannel("ref", instance)
    stamp = w.write(_ref(0.0))
    delays = np.random.default_rng(0).uniform(0.0, 0.002, 200)
    for k, delay in enumerate(delays, start=1):
        stamp = _wait_for_a_later_write(r, w, k, delay, stamp)
    r.close()
    w.close()


def test_a_reader_woken_before_the_publish_gets_the_sample_if_the_writer_stalls(
    instance, monkeypatch
):
    """A writer wakes blocked readers before it copies and publishes; a reader so woken
    polls for the publish for `SPIN_AFTER_WAKE_NS`, then sleeps again. Here the writer
    stalls 20 ms between that early wake and its publish, far past the poll: the reader
    still gets the sample, woken by the writer's second wake after the publish (the
    periodic re-check is pushed out to 30 s, so a lost wake-up would leave ``wait_newer``
    asleep for its whole 10 s timeout)."""
    monkeypatch.setattr(ch, "WAKE_SLICE_S", 30.0)
    wake, sleep = ch._futex_wake_all, ch._futex_wait
    sleeps_woken = []  # per futex sleep of the reader: ended by a wake?

    def wake_then_stall(addr):
        wake(addr)
        time.sleep(0.02)

    def recorded_sleep(*args):
        sleeps_woken.append(sleep(*args))
        return sleeps_woken[-1]

    monkeypatch.setattr(ch, "_futex_wake_all", wake_then_stall)
    monkeypatch.setattr(ch, "_futex_wait", recorded_sleep)
    r, w = ShmChannel("ref", instance), ShmChannel("ref", instance)
    stamp = w.write(_ref(0.0))
    for k in range(1, 4):
        sleeps_woken.clear()
        stamp = _wait_for_a_later_write(r, w, k, 0.1, stamp)
        # Woken early, gave up its poll, slept again, woken again (or, if the publish
        # came first, found the generation changed).
        assert sleeps_woken[0] and len(sleeps_woken) >= 2
    r.close()
    w.close()


def test_other_structs_and_errors(instance):
    c = ShmChannel("state", instance)
    s = new_sample(STATE_DTYPE)
    s["imu"]["az"][0] = 9.81
    s["tick"] = 7
    c.write(s)
    got = c.read_latest()
    assert got.dtype == STATE_DTYPE and float(got["imu"]["az"][0]) == 9.81 and got["tick"] == 7
    c.close()
    with pytest.raises(ChannelError, match="instance 'bad/name'"):
        ShmChannel("ref", "bad/name")
    with pytest.raises(ChannelError, match="no default struct; known channels"):
        ShmChannel("nope", instance)
    with pytest.raises(ChannelError, match="lacks header field"):
        InProcessChannel("x", instance, dtype=np.dtype([("a", "<f8")]))
    held = ShmChannel("ref", instance)  # in use with the ref layout
    with pytest.raises(ChannelError, match="another layout and is in use"):
        ShmChannel("ref", instance, dtype=STATE_DTYPE)
    held.close()
    ShmChannel("ref", instance, dtype=STATE_DTYPE).close()  # unused: re-initialised


def test_writer_slots_are_per_object_and_limited(instance):
    ws = [ShmChannel("ref", instance, writer_id=k) for k in range(ch.MAX_WRITERS)]
    for k, w in enumerate(ws):
        w.write(_ref(float(k)))
    extra = ShmChannel("ref", instance)
    with pytest.raises(ChannelError, match="writer slots are in use"):
        extra.write(_ref(0.0))
    ws[0].close()  # frees its slot
    extra.write(_ref(42.0))
    assert float(extra.read_latest()["ref"][0]) == 42.0
    for w in ws[1:] + [extra]:
        w.close()


def test_torn_slot_of_a_dead_writer_is_skipped_then_reclaimed(instance):
    w = ShmChannel("ref", instance, writer_id=1)
    w.write(_ref(1.0))  # slot 0
    other = ShmChannel("ref", instance, writer_id=2)
    other.write(_ref(2.0))  # slot 1
    w.write(_ref(4.0))
    # Simulate w killed mid-write: its slot's counter stays odd and its lock is gone.
    r = ShmChannel("ref", instance)
    struct.pack_into("<q", r._mm, ch._TABLE_OFF, 5)
    w.close()
    assert float(r.read_latest()["ref"][0]) == 2.0  # the torn slot is ignored
    fresh = ShmChannel("ref", instance, writer_id=3)
    fresh.write(_ref(3.0))  # claims slot 0 and repairs it
    assert float(r.read_latest()["ref"][0]) == 3.0
    for c in (other, r, fresh):
        c.close()


def test_a_writer_caught_mid_copy_hides_nothing(instance):
    w = ShmChannel("ref", instance)
    w.write(_ref(1.0))
    # The next write goes to the other buffer; scribble on it as a preempted writer would.
    data = ch._DATA_OFF + (w._buffer ^ 1) * w._stride
    w._mm[data : data + 100] = b"\xff" * 100
    r = ShmChannel("ref", instance)
    assert float(r.read_latest()["ref"][0]) == 1.0
    w.write(_ref(2.0))
    assert float(r.read_latest()["ref"][39]) == 2.0
    r.close()
    w.close()


def test_a_writer_preempted_mid_publish_hides_nothing(instance, caplog):
    """A writer stopped inside its publish (odd counter) for longer than a reader spins is
    not taken for dead: a reader that saw its previous row reads that row's buffer."""
    w = ShmChannel("ref", instance)
    w.write(_ref(1.0))
    r = ShmChannel("ref", instance)
    assert float(r.read_latest()["ref"][0]) == 1.0
    # w.write(_ref(2.0)) stopped mid-publish: the other buffer filled, the counter odd,
    # the row's buffer index already switched to it, its stamp not yet.
    buffer = w._buffer ^ 1
    data = ch._DATA_OFF + buffer * w._stride
    w._mv[data : data + w._size] = _ref(2.0).tobytes()
    w._table[w._row] = w._counter + 1
    w._table[w._row + 4] = buffer
    with caplog.at_level(logging.WARNING, logger="daemon.channels"):
        assert float(r.read_latest()["ref"][0]) == 1.0
    assert "stuck" not in caplog.text
    w._table[w._row] = w._counter + 2  # the publish ends
    assert float(r.read_latest()["ref"][0]) == 2.0
    r.close()
    w.close()


def test_a_reader_that_missed_the_last_row_keeps_its_last_sample(instance, caplog):
    """A writer caught mid-publish while the reader missed its previous row (it read
    nothing since an older one): the reader hands out the last sample it read, not None
    (a player given None by a preempted daemon stopped, 2026-11-28)."""
    w = ShmChannel("ref", instance)
    w.write(_ref(1.0))
    r = ShmChannel("ref", instance)
    assert float(r.read_latest()["ref"][0]) == 1.0
    w.write(_ref(2.0))
    w.write(_ref(3.0))  # r reads neither
    w._table[w._row] = w._counter + 1  # the next publish starts and stops there
    with caplog.at_level(logging.WARNING, logger="daemon.channels"):
        got = r.read_latest()
    assert got is not None and float(got["ref"][0]) == 1.0
    fresh = ShmChannel("ref", instance)  # never read anything: nothing to keep
    assert fresh.read_latest() is None
    for c in (fresh, r, w):
        c.close()


# ---------------------------------------------------------------- real processes


def test_no_torn_reads_under_a_fast_writer(instance):
    r = ShmChannel("ref", instance)
    p = _run(_child_write_fast, instance, 1.0)
    seen = 0
    last = 0
    end = time.monotonic() + 20.0
    while time.monotonic() < end and (p.is_alive() or seen == 0):
        s = r.read_latest()
        if s is None:
            continue
        k = float(s["ref"][0])
        assert np.all(s["ref"] == k) and np.all(s["mode"] == int(k) % 4)  # one write
        assert int(s["seq"]) == int(k) and int(s["time_ns"]) >= last
        last = int(s["time_ns"])
        seen += 1
    p.join(20)
    assert seen > 100
    r.close()



def test_two_processes_reader_gets_newest_from_two_writers(instance):
    r = ShmChannel("ref", instance)
    p1 = _run(_child_write, instance, [1.0, 2.0], 0.0, 11)
    p1.join(20)
    p2 = _run(_child_write, instance, [5.0], 0.0, 12)
    p2.join(20)
    got = r.read_latest()
    assert float(got["ref"][0]) == 5.0 and int(got["writer_id"]) == 12
    p3 = _run(_child_write, instance, [7.0], 0.0, 11)
    p3.join(20)
    got = r.read_latest()
    assert float(got["ref"][0]) == 7.0 and int(got["writer_id"]) == 11
    assert all(p.exitcode == 0 for p in (p1, p2, p3))
    r.close()


def test_two_processes_blocking_wait(instance):
    w = ShmChannel("ref", instance)
    stamp = w.write(_ref(1.0))
    out = CTX.Queue()
    p = _run(_child_wait, instance, stamp, out)
    time.sleep(0.3)  # let the child block
    w.write(_ref(2.0))
    assert out.get(timeout=20) == 2.0
    p.join(20)
    # ... and a writer in another process wakes a reader here.
    stamp = w.read_latest()["time_ns"]
    p = _run(_child_write, instance, [3.0], 0.3, 5)
    got = w.wait_newer(int(stamp), 20.0)
    assert got is not None and float(got["ref"][0]) == 3.0
    p.join(20)
    w.close()


def test_sigkilled_writer_then_fresh_start(instance):
    started = CTX.Event()
    p = _run(_child_write_forever, instance, started)
    assert started.wait(20)
    os.kill(p.pid, signal.SIGKILL)  # possibly mid-write
    p.join(20)
    # Nothing blocks the next start: a new writer and reader work at once.
    p2 = _run(_child_write, instance, [123.0], 0.0, 77)
    p2.join(20)
    assert p2.exitcode == 0
    r = ShmChannel("ref", instance)
    got = r.wait_newer(0, 1.0)
    assert got is not None and float(got["ref"][0]) == 123.0
    r.close()
    # Nobody uses the channel any more: start-up cleanup removes it.
    assert channel_path(instance, "ref") in cleanup_stale(instance)
    assert not channel_path(instance, "ref").exists()


def test_cleanup_keeps_channels_in_use(instance):
    c = ShmChannel("ref", instance)
    assert cleanup_stale(instance) == []
    c.close()
    assert cleanup_stale(instance) == [channel_path(instance, "ref")]
