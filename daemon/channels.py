"""Latest-value channels between processes: the role Ach played for hubo-ach.

A `Channel` carries fixed-layout samples (numpy structured dtypes of `daemon.structs`).
Several writers may write; a reader gets the newest sample from anyone, polling
(`Channel.read_latest`) or blocking with a timeout (`Channel.wait_newer`). Every write
stamps the struct header: ``writer_id``, ``seq`` (per writer, from 1) and ``time_ns``
(``CLOCK_MONOTONIC`` [ns], strictly increasing per writer, comparable across processes).
"Newest" means the largest ``(time_ns, seq, writer_id)``.

Two implementations behind the one interface:

- `InProcessChannel`: a lock and a condition variable, for tests and lock-step
  simulation (``validate-plan``). Channels of the same instance and name in one process
  share one value.
- `ShmChannel`: between processes. One file in ``/dev/shm`` per channel and daemon
  instance (``hubo-ladder.<instance>.<name>``), mapped with `mmap`:

  - one slot per writer with two data buffers: the writer fills the buffer readers are
    not pointed at, then publishes it under a seqlock (odd counter while the slot's row
    of stamp and buffer index changes, a few hundred ns). A reader copies the newest
    published buffer and re-checks the counter. The table of counters and rows is read
    and written as whole aligned int64s (a `memoryview` cast), never with
    ``struct.pack_into``, which zero-fills its target before writing: a reader that
    caught a counter at 0 took a buffer being overwritten for a published one. A writer
    preempted or killed mid-copy never hides its previous sample, nor mid-publish: the
    buffer its last published row named stays intact until the publish ends, so a
    reader that saw that row reads it;
  - slots are claimed with Linux open-file-description locks (``F_OFD_SETLK``), which the
    kernel drops when a process dies, so a killed writer's slot is free for the next one;
  - a blocked reader sleeps on a futex: a 32-bit generation word in the file that every
    write sets to its time stamp's low bits after publishing, next to the index of the
    slot it published. The reader
    raises its "waiting" byte, reads the generation, checks the slots and only then
    sleeps, and only while the generation is unchanged, so a write in between is never
    missed. A writer that sees a waiting byte after publishing wakes every sleeper with
    one system call, and a woken reader copies the slot named there without scanning. A
    writer also wakes sleepers early, before it copies, so that the reader's wake-up and
    the publish overlap (with the two on different CPUs this halved what the channel adds
    to a bare futex wake); a reader so woken polls the generation word for at most
    ``SPIN_AFTER_WAKE_NS`` and then sleeps again, for the wake after the publish. A
    waiting reader still re-checks the slots every ``WAKE_SLICE_S``. Futexes on a shared
    mapping need nothing cleaned up after a crash;
  - `cleanup_stale` removes channel files no live process has open (the daemon calls it
    at start-up).

Why a futex on a shared file and not an IPC library (iceoryx2) or a datagram per
reader: it wakes a blocked reader fastest of the three measured, and needs nothing
cleaned up after a crash. ``bench/bench_channels.py`` measures the wake-up latency beside
a bare futex wake in the same run; the figures and the comparison are in
docs/decisions/channels.md.

The seqlock assumes x86-64's store ordering (TSO); on weakly ordered CPUs (aarch64) the
counter re-check needs real barriers. Do not fork a process that holds a channel open:
the child shares its open file description, and so its locks.

Size: the file layout, the seqlock and the futex wake-up are one protocol between
processes; each part is only correct together with the others.
"""

from __future__ import annotations

import abc
import ctypes
import errno
import fcntl
import logging
import mmap
import os
import platform
import re
import struct
import threading
import time
import zlib
from pathlib import Path

import numpy as np

from daemon.structs import CHANNEL_DTYPES
from robot.errors import HuboLadderError

log = logging.getLogger(__name__)

SHM_DIR = Path("/dev/shm")
FILE_PREFIX = "hubo-ladder."
MAX_WRITERS = 8  #: writer slots per channel
#: Blocking-reader slots per channel: one "waiting" byte each, 8 so that a writer tests
#: them all as one int64.
MAX_READERS = 8
WAKE_SLICE_S = 0.005  #: a waiting reader re-checks the slots at least this often [s]
#: How long a woken reader polls the generation word for the write that woke it [ns]: a
#: writer wakes readers before it copies and publishes, which takes it about 16 µs from
#: its wake call on a loaded 2-core machine, while a sleeper takes about 17 µs to run; a
#: poll rarely turns more than once. Bounded so that a writer preempted mid-write costs
#: the reader no more; it then sleeps again and the writer's second wake, after the
#: publish, wakes it.
SPIN_AFTER_WAKE_NS = 50_000
_NAME_RE = re.compile(r"^[A-Za-z0-9_-]{1,40}$")


class ChannelError(HuboLadderError):
    """A channel cannot be opened or used (bad name, layout mismatch, no free slot)."""


def sample_key(sample: np.ndarray) -> tuple[int, int, int]:
    """Ordering key of a sample: ``(time_ns, seq, writer_id)``; larger is newer."""
    return int(sample["time_ns"]), int(sample["seq"]), int(sample["writer_id"])


class Channel(abc.ABC):
    """A latest-value channel of one struct dtype.

    Args:
        name: channel name, e.g. ``"ref"``.
        dtype: struct dtype; it must start with the `daemon.structs` header fields.
        writer_id: stamped into every sample written through this object; defaults to
            the process id.
    """

    def __init__(self, name: str, dtype: np.dtype, writer_id: int | None = None):
        for field in ("writer_id", "seq", "time_ns"):
            if dtype.names is None or field not in dtype.names:
                raise ChannelError(f"channel '{name}': dtype lacks header field '{field}'")
        self.name = name
        self.dtype = dtype
        self.writer_id = (os.getpid() if writer_id is None else writer_id) & 0xFFFFFFFF
        self._seq = 0
        self._last_time_ns = 0

    def _stamp(self, sample: np.ndarray) -> np.ndarray:
        """Copy ``sample`` into a fresh 0-d array and stamp its header."""
        out = np.array(sample, dtype=self.dtype).reshape(())
        self._seq += 1
        self._last_time_ns = max(time.monotonic_ns(), self._last_time_ns + 1)
        out["writer_id"] = self.writer_id
        out["seq"] = self._seq
        out["time_ns"] = self._last_time_ns
        return out

    @abc.abstractmethod
    def write(self, sample: np.ndarray) -> int:
        """Publish a sample (copied; header stamped). Returns its ``time_ns`` stamp."""

    @abc.abstractmethod
    def read_latest(self) -> np.ndarray | None:
        """The newest sample from any writer (a 0-d copy), or None if none was written."""

    @abc.abstractmethod
    def wait_newer(self, last_seq: int, timeout_s: float) -> np.ndarray | None:
        """Block until a sample newer than ``last_seq`` exists, or ``timeout_s`` passed.

        Args:
            last_seq: the ``time_ns`` stamp of the newest sample the caller has seen
                (0 for none). Stamps order samples across writers.
            timeout_s: how long to wait at most [s]; 0 polls.

        Returns:
            The newest sample if its stamp is larger than ``last_seq``, else None.
        """

    def close(self) -> None:  # noqa: B027 - optional hook, nothing to release by default
        """Release the channel's resources; idempotent."""

    def __enter__(self) -> Channel:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r}, {self.dtype.itemsize} B)"


# ---------------------------------------------------------------- in-process


class _Hub:
    def __init__(self) -> None:
        self.cond = threading.Condition()
        self.latest: np.ndarray | None = None


_hubs: dict[tuple[str, str], _Hub] = {}
_hubs_lock = threading.Lock()


class InProcessChannel(Channel):
    """A channel between threads of one process (tests, lock-step simulation).

    Args:
        name: channel name.
        instance: daemon instance name; channels of equal (instance, name) share a value.
        dtype: struct dtype; defaults to `daemon.structs.CHANNEL_DTYPES` [name].
        writer_id: see `Channel`.
    """

    def __init__(
        self,
        name: str,
        instance: str = "default",
        dtype: np.dtype | None = None,
        writer_id: int | None = None,
    ):
        super().__init__(name, _dtype_for(name, dtype), writer_id)
        with _hubs_lock:
            self._hub = _hubs.setdefault((instance, name), _Hub())

    def write(self, sample: np.ndarray) -> int:
        out = self._stamp(sample)
        with self._hub.cond:
            cur = self._hub.latest
            if cur is None or sample_key(out) > sample_key(cur):
                self._hub.latest = out
            self._hub.cond.notify_all()
        return int(out["time_ns"])

    def read_latest(self) -> np.ndarray | None:
        with self._hub.cond:
            cur = self._hub.latest
        return None if cur is None else cur.copy()

    def wait_newer(self, last_seq: int, timeout_s: float) -> np.ndarray | None:
        def newer() -> bool:
            cur = self._hub.latest
            return cur is not None and int(cur["time_ns"]) > last_seq

        with self._hub.cond:
            if self._hub.cond.wait_for(newer, timeout=max(timeout_s, 0.0)):
                return self._hub.latest.copy()
        return None


def reset_in_process(instance: str) -> None:
    """Forget every in-process channel value of ``instance`` (test isolation)."""
    with _hubs_lock:
        for key in [k for k in _hubs if k[0] == instance]:
            del _hubs[key]


# ---------------------------------------------------------------- shared memory

_MAGIC = b"HUBOCHN1"
_VERSION = 2
_HDR = struct.Struct("<8sIIIIQ")  # magic, version, sample_size, writers, readers, dtype crc
_GENERATION_OFF = 48  # u32 futex word: low bits of the last publish's time_ns
_LAST_SLOT_OFF = 52  # u8: the writer slot published last
_WAIT_OFF = 64  # MAX_READERS "waiting" bytes
_TABLE_OFF = 128  # per writer slot, 8 × i64: counter, time_ns, seq, writer_id, buffer, pad
_ROW_Q = 8
_DATA_OFF = _TABLE_OFF + 8 * _ROW_Q * MAX_WRITERS
# Lock byte offsets (OFD locks may lie beyond the end of the file).
_LOCK_INIT = 1 << 20
_LOCK_PRESENCE = _LOCK_INIT + 1
_LOCK_WRITER = _LOCK_INIT + 16
_LOCK_READER = _LOCK_INIT + 64
_STAMP = struct.Struct("<IQq")  # the struct header: writer_id, seq, time_ns
_FLOCK = struct.Struct("hhqqi4x")  # struct flock on Linux x86-64 / aarch64
#: Reads of an odd counter before the slot is taken as stuck (a dead writer), when the
#: reader never saw the slot's previous row (otherwise that row's buffer is read at once).
_ODD_SPIN = 2000

_LIBC = ctypes.CDLL(None, use_errno=True)
#: syscall() is variadic: the number is passed as a C long, not a promoted int.
_SYS_FUTEX = {"x86_64": 202, "aarch64": 98}.get(platform.machine())
_FUTEX_WAIT, _FUTEX_WAKE = 0, 1  # shared (not FUTEX_PRIVATE): the word is in a file mapping
_WAKE_ALL = 0x7FFFFFFF


class _Timespec(ctypes.Structure):
    _fields_ = [("tv_sec", ctypes.c_long), ("tv_nsec", ctypes.c_long)]


#: The syscall number as a C long, made once. With the address made once too (by the
#: caller) and the arguments the futex operation ignores left out, a wake with nobody
#: asleep takes 0.70 µs instead of 1.05 µs (S28, in a loop).
_SYS_FUTEX_ARG = ctypes.c_long(_SYS_FUTEX or 0)


def _futex_wait(addr: ctypes.c_void_p, expected: int, timeout_s: float) -> bool:
    """Sleep while the u32 at ``addr`` equals ``expected``, at most ``timeout_s``.

    Returns:
        True if a wake ended the sleep, False on a changed value (EAGAIN), the timeout or
        a signal. Either way the caller re-checks; True also tells it a write is on its
        way (`ShmChannel.write` wakes before it publishes).
    """
    ts = _Timespec(int(timeout_s), int((timeout_s % 1.0) * 1e9))
    # FUTEX_WAIT reads uaddr, op, val and timeout only: the syscall's last two are omitted.
    return _LIBC.syscall(_SYS_FUTEX_ARG, addr, _FUTEX_WAIT, ctypes.c_uint32(expected),
                         ctypes.byref(ts)) == 0


def _futex_wake_all(addr: ctypes.c_void_p) -> None:
    """Wake every sleeper on the u32 at ``addr``. FUTEX_WAKE reads uaddr, op and val only."""
    _LIBC.syscall(_SYS_FUTEX_ARG, addr, _FUTEX_WAKE, _WAKE_ALL)


def _ofd_lock(fd: int, kind: int, start: int, wait: bool = False) -> bool:
    """Take (or with F_UNLCK release) an OFD lock on one byte. False if held elsewhere."""
    cmd = fcntl.F_OFD_SETLKW if wait else fcntl.F_OFD_SETLK
    try:
        fcntl.fcntl(fd, cmd, _FLOCK.pack(kind, os.SEEK_SET, start, 1, 0))
    except OSError as e:
        if e.errno in (errno.EAGAIN, errno.EACCES):
            return False
        raise
    return True


def _dtype_for(name: str, dtype: np.dtype | None) -> np.dtype:
    if dtype is not None:
        return np.dtype(dtype)
    if name not in CHANNEL_DTYPES:
        raise ChannelError(
            f"channel '{name}': no default struct; known channels: {sorted(CHANNEL_DTYPES)}"
        )
    return CHANNEL_DTYPES[name]


def _check_name(kind: str, value: str) -> None:
    if not _NAME_RE.match(value):
        raise ChannelError(f"{kind} '{value}': use 1–40 characters of A–Z a–z 0–9 _ -")


def channel_path(instance: str, name: str) -> Path:
    """The ``/dev/shm`` file of channel ``name`` of daemon ``instance``."""
    return SHM_DIR / f"{FILE_PREFIX}{instance}.{name}"


class ShmChannel(Channel):
    """A channel between processes in shared memory (see the module docstring).

    Args:
        name: channel name (letters, digits, ``_``, ``-``).
        instance: daemon instance name; namespaces the file names so that parallel
            daemons and tests never collide.
        dtype: struct dtype; defaults to `daemon.structs.CHANNEL_DTYPES` [name].
        writer_id: see `Channel`.

    Raises:
        ChannelError: bad name, or the file holds another layout while in use.
    """

    def __init__(
        self,
        name: str,
        instance: str = "default",
        dtype: np.dtype | None = None,
        writer_id: int | None = None,
    ):
        super().__init__(name, _dtype_for(name, dtype), writer_id)
        _check_name("instance", instance)
        _check_name("channel", name)
        self.instance = instance
        self.path = channel_path(instance, name)
        self._size = self.dtype.itemsize
        self._stride = (self._size + 63) // 64 * 64
        self._fd = -1
        self._fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o660)
        self._mm: mmap.mmap | None = None
        self._wslot: int | None = None
        self._rslot: int | None = None
        self._generation: ctypes.c_uint32 | None = None  # the futex word, in the mapping
        self._stuck: dict[int, int] = {}  # slot → counter seen odd for too long
        # slot → (counter, key, buffer) of the last published (even) row seen
        self._published: dict[int, tuple[int, tuple[int, int, int], int]] = {}
        self._last_read: np.ndarray | None = None  # the newest sample this reader returned
        self._spare: tuple[np.ndarray, bytearray] | None = None  # see `_spare_sample`
        self._fence = threading.Lock()
        if _SYS_FUTEX is None:
            raise ChannelError(f"shared-memory channels need Linux futexes on x86-64 or "
                               f"aarch64, not {platform.machine()}")
        try:
            self._open_segment()
        except BaseException:
            os.close(self._fd)
            self._fd = -1
            raise

    # -- set-up

    def _open_segment(self) -> None:
        fd = self._fd
        total = _DATA_OFF + MAX_WRITERS * 2 * self._stride
        crc = zlib.crc32(str(self.dtype.descr).encode())
        header = _HDR.pack(_MAGIC, _VERSION, self._size, MAX_WRITERS, MAX_READERS, crc)
        _ofd_lock(fd, fcntl.F_WRLCK, _LOCK_INIT, wait=True)
        try:
            alone = _ofd_lock(fd, fcntl.F_WRLCK, _LOCK_PRESENCE)
            st = os.fstat(fd)
            current = os.pread(fd, _HDR.size, 0) if st.st_size >= _HDR.size else b""
            if current != header:
                if not alone:
                    raise ChannelError(
                        f"channel file {self.path} holds another layout and is in use; "
                        f"stop its users or pick another instance name"
                    )
                if current:
                    log.warning("re-initialising stale channel file %s", self.path)
                os.ftruncate(fd, 0)
                os.ftruncate(fd, total)
                os.pwrite(fd, header, 0)
            elif alone:
                log.debug("reusing channel file %s (no live users)", self.path)
            _ofd_lock(fd, fcntl.F_RDLCK, _LOCK_PRESENCE)  # downgrade: "I use this file"
        finally:
            _ofd_lock(fd, fcntl.F_UNLCK, _LOCK_INIT)
        self._mm = mmap.mmap(fd, total)
        self._mv = memoryview(self._mm)
        # The writer table as int64s: each item is one aligned 8-byte load or store.
        # struct.pack_into zero-fills its target before writing the fields, so a reader
        # could see a counter of 0 mid-store, and struct reads and writes "<q" a byte at
        # a time; the seqlock needs each counter and row field read and written whole.
        self._table = self._mv[_TABLE_OFF:_DATA_OFF].cast("q")
        # The MAX_READERS (8) waiting bytes as one int64: a writer tests them with one load.
        self._waiting = self._mv[_WAIT_OFF : _WAIT_OFF + MAX_READERS].cast("q")
        self._generation = ctypes.c_uint32.from_buffer(self._mm, _GENERATION_OFF)
        self._generation_addr = ctypes.c_void_p(ctypes.addressof(self._generation))

    def _claim_writer_slot(self) -> int:
        for i in range(MAX_WRITERS):
            if _ofd_lock(self._fd, fcntl.F_WRLCK, _LOCK_WRITER + i):
                row, table = _ROW_Q * i, self._table
                counter = table[row]
                if counter & 1:  # a writer died while publishing: the row may be torn
                    log.warning("%s: writer slot %d was torn by a dead writer", self.path, i)
                    for k in range(1, 5):
                        table[row + k] = 0
                    table[row] = counter + 1
                self._counter, self._buffer = table[row], table[row + 4]
                self._row = row
                self._data_off = _DATA_OFF + 2 * i * self._stride
                self._wslot = i
                return i
        raise ChannelError(f"{self.path}: all {MAX_WRITERS} writer slots are in use")

    def _claim_reader_slot(self) -> int:
        for k in range(MAX_READERS):
            if _ofd_lock(self._fd, fcntl.F_WRLCK, _LOCK_READER + k):
                self._rslot = k
                return k
        raise ChannelError(f"{self.path}: all {MAX_READERS} reader slots are in use")

    # -- data

    def write(self, sample: np.ndarray) -> int:
        t_ns = self._last_time_ns = max(time.monotonic_ns(), self._last_time_ns + 1)
        if self._wslot is None:
            self._claim_writer_slot()
        # Identity first: numpy's dtype comparison costs microseconds to a writer whose
        # caches the machine's other work emptied; np.asarray passes an equal dtype through.
        if sample.__class__ is not np.ndarray or sample.dtype is not self.dtype:
            sample = np.asarray(sample, dtype=self.dtype)
        # Early wake: a sleeping reader takes longer to be scheduled than this publish
        # takes, so it wakes while we copy and finds the sample published (it polls the
        # generation word for up to SPIN_AFTER_WAKE_NS). No fence: a reader this read
        # misses is woken below.
        if self._waiting[0]:
            _futex_wake_all(self._generation_addr)
        mm, table, row = self._mm, self._table, self._row
        self._seq += 1
        buffer = self._buffer ^ 1  # write the buffer readers are not pointed at
        data = self._data_off + buffer * self._stride
        self._mv[data : data + self._size] = sample.tobytes()
        _STAMP.pack_into(mm, data, self.writer_id, self._seq, t_ns)
        counter = self._counter  # we own the slot: no need to read it back
        table[row] = counter + 1  # odd: publishing
        table[row + 1], table[row + 2] = t_ns, self._seq
        table[row + 3], table[row + 4] = self.writer_id, buffer
        table[row] = counter + 2
        self._counter, self._buffer = counter + 2, buffer
        mm[_LAST_SLOT_OFF] = self._wslot  # tells a woken reader which slot to copy
        # A store, not an increment: two writers' read-modify-writes could race to the same
        # value, and a reader that read it in between would sleep through the second write.
        self._generation.value = t_ns & 0xFFFFFFFF
        with self._fence:  # full barrier (locked instruction) before reading the flags
            pass
        # A reader still (or again) waiting: one that went to sleep after the early wake,
        # or gave up its spin.
        if self._waiting[0]:
            _futex_wake_all(self._generation_addr)
        return t_ns

    def _newest(self) -> tuple[int, tuple[int, int, int], int] | None:
        """(slot, key, counter, buffer) of the newest published slot.

        A slot caught mid-publish (odd counter) counts with the row it published last, if
        this reader saw that row: its buffer is intact until the publish ends
        (`_read_slot` checks). Spinning on it instead would take a writer the scheduler
        preempted there for longer than the spin (3 ms on a loaded 2-core machine) for a
        dead one and hide its sample: the daemon then had no reference for a tick, held
        it rigid and dropped a PWM arm's compliance.
        """
        published = self._published
        for _ in range(_ODD_SPIN):
            table = self._table.tolist()
            best = None
            busy = False
            for i in range(MAX_WRITERS):
                r = _ROW_Q * i
                counter = table[r]
                if counter == 0:
                    continue
                if counter & 1:
                    row = published.get(i)
                    if row is None or row[0] != counter - 1:
                        if self._stuck.get(i) != counter:
                            busy = True
                        continue
                else:
                    row = (counter, (table[r + 1], table[r + 2], table[r + 3]), table[r + 4] & 1)
                    published[i] = row
                if best is None or row[1] > best[1]:
                    best = (i, row[1], row[0], row[2])
            if not busy:
                return best
        for i in range(MAX_WRITERS):  # still odd after the spin: a writer died publishing
            counter = table[_ROW_Q * i]
            if counter & 1 and self._stuck.get(i) != counter:
                log.warning("%s: writer slot %d stuck mid-write; ignoring it", self.path, i)
                self._stuck[i] = counter
        return best

    def _spare_sample(self) -> tuple[np.ndarray, bytearray]:
        """The 0-d array the next read fills, and the bytearray it views. Made before a
        reader sleeps, so that a woken one only copies bytes: building the array after the
        wake cost about 4 µs of a 31 µs wake on a loaded 2-core machine (S28)."""
        if self._spare is None:
            raw = bytearray(self._size)
            self._spare = np.ndarray((), self.dtype, buffer=raw), raw
        return self._spare

    def _read_slot(self, i: int, counter: int, buffer: int) -> np.ndarray | None:
        """Copy ``buffer`` of slot ``i``, published at the even ``counter``; None if the
        writer may have written into it meanwhile. It writes the other buffer and then
        publishes it (``counter + 1`` while publishing, ``+ 2`` after); only its next write
        reuses this one."""
        sample, raw = self._spare_sample()
        data = _DATA_OFF + (2 * i + buffer) * self._stride
        raw[:] = self._mv[data : data + self._size]
        if self._table[_ROW_Q * i] > counter + 1:
            return None  # the spare is filled again by the next try
        self._spare = None  # handed out
        return sample

    def read_latest(self) -> np.ndarray | None:
        """The newest sample, or — while every writer this reader could read is caught
        mid-publish and it missed their last complete row — the last sample it read, as
        an Ach reader keeps its last frame (a daemon preempted mid-publish on a loaded
        machine had handed a player None). None only if it never read one."""
        for _ in range(_ODD_SPIN):
            found = self._newest()
            if found is None:
                return None if self._last_read is None else self._last_read.copy()
            sample = self._read_slot(found[0], found[2], found[3])
            if sample is not None:
                self._last_read = sample  # a fresh buffer; the fallback hands out copies
                return sample
        raise ChannelError(f"{self.path}: could not read a consistent sample")

    def wait_newer(self, last_seq: int, timeout_s: float) -> np.ndarray | None:
        deadline = time.monotonic() + max(timeout_s, 0.0)
        latest = self.read_latest()
        # Locals: after a wake every attribute look-up costs (the machine's other work
        # emptied this process's caches while it slept).
        mm, table, generation_word = self._mm, self._table, self._generation
        while True:
            if latest is not None and int(latest["time_ns"]) > last_seq:
                return latest
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return None
            if self._rslot is None:
                self._claim_reader_slot()
            waiting = _WAIT_OFF + self._rslot
            mm[waiting] = 1
            with self._fence:
                pass
            generation = generation_word.value
            latest = self.read_latest()
            if latest is not None and int(latest["time_ns"]) > last_seq:
                mm[waiting] = 0
                return latest
            self._spare_sample()
            # A write after the generation was read changes it: the futex does not sleep.
            woken = _futex_wait(self._generation_addr, generation,
                                min(remaining, WAKE_SLICE_S))
            mm[waiting] = 0  # a writer need not wake us again
            if woken and generation_word.value == generation:
                # The writer wakes before it publishes: poll for the publish, bounded.
                spin_end_ns = time.monotonic_ns() + SPIN_AFTER_WAKE_NS
                while generation_word.value == generation and time.monotonic_ns() < spin_end_ns:
                    pass
            if generation_word.value != generation:
                # Fast path: the slot published last, the newest one.
                i = mm[_LAST_SLOT_OFF]
                if i < MAX_WRITERS:
                    row = _ROW_Q * i
                    counter = table[row]
                    if not counter & 1 and table[row + 1] > last_seq:
                        latest = self._read_slot(i, counter, table[row + 4] & 1)
                        if latest is not None:
                            return latest
            latest = self.read_latest()

    def close(self) -> None:
        if self._fd < 0:
            return
        if self._rslot is not None:
            self._mm[_WAIT_OFF + self._rslot] = 0
        self._generation = None  # a live ctypes view would keep the mapping from closing
        self._table.release()
        self._waiting.release()
        self._mv.release()
        self._mm.close()
        os.close(self._fd)  # drops every OFD lock of this object
        self._fd = -1

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown: nothing left to do
            pass


def open_channel(
    name: str,
    instance: str = "default",
    *,
    dtype: np.dtype | None = None,
    writer_id: int | None = None,
    in_process: bool = False,
) -> Channel:
    """Open channel ``name`` of daemon ``instance``: shared memory, or in-process."""
    cls = InProcessChannel if in_process else ShmChannel
    return cls(name, instance, dtype=dtype, writer_id=writer_id)


def cleanup_stale(instance: str | None = None) -> list[Path]:
    """Remove channel files that no live process has open.

    Args:
        instance: only this daemon instance's channels; None for every instance.

    Returns:
        The files removed.
    """
    pattern = f"{FILE_PREFIX}{instance}.*" if instance else f"{FILE_PREFIX}*"
    removed = []
    for path in sorted(SHM_DIR.glob(pattern)):
        try:
            fd = os.open(path, os.O_RDWR)
        except FileNotFoundError:
            continue
        try:
            if _ofd_lock(fd, fcntl.F_WRLCK, _LOCK_INIT) and _ofd_lock(
                fd, fcntl.F_WRLCK, _LOCK_PRESENCE
            ):
                path.unlink(missing_ok=True)
                removed.append(path)
        finally:
            os.close(fd)
    if removed:
        log.info("removed %d stale channel file(s): %s", len(removed), [p.name for p in removed])
    return removed
