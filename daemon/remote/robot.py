"""The robot side of the bridge: the daemon's channels on the network, through zenoh.

One `RobotBridge` per daemon instance, on the robot's computer:

- **state out**: the first ``state`` sample the daemon writes after each period
  (``rate_hz``) is put on ``hubo/<instance>/state``, as soon as it is written (the bridge
  sleeps on the channel's futex, it does not poll). A daemon that stops ticking publishes
  nothing: the bridge never re-sends an old sample.
- **references in**: each ``ref`` sample from a writer is written once into the local
  ``ref`` channel, where the daemon applies to it what it applies to every writer (the
  joint limits, finite values, modes, feed-forward bounds; `daemon.loop`). The bridge
  never repeats a sample: when the link drops, the channel ages and the daemon's watchdog
  holds the robot, as for a player that died.
- **commands in** (zenoh queries, each answered): the board commands allowed over the
  network, neck keys and the player's pause and stop, through `daemon.local_commands`
  (the same code and refusals as ``hubo-console``, ``hubo-neck`` and the local page).

Freshness. Every sample and command carries the ``time_ns`` of the newest state its
sender had (`daemon.remote.keys`); one older than ``1 / rate_hz + max_delay_s`` on the
robot's clock is dropped and counted, not played late. Zenoh's side: state and references
are best-effort, express (not batched) and dropped rather than queued under congestion;
references go through a one-slot latest-value hand-over.

Who may write is zenoh's access control (`daemon.remote.session_config`): the commands
of a peer that is not configured are dropped by zenoh before the bridge sees them. The
bridge counts and logs such peers when they connect (`BridgeStats.readonly_peers`).
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from dataclasses import dataclass, field

import numpy as np

from daemon.player_control import PlayerCommand
from daemon.remote.keys import COMMANDS, Topic, decode_stamp, key
from daemon.remote.session_config import TlsFiles, check_endpoint, open_session, robot_config
from daemon.structs import REF_DTYPE
from robot.errors import HuboLadderError, InputError

__all__ = ["BridgeStats", "RobotBridge", "RobotBridgeConfig", "default_config"]

log = logging.getLogger(__name__)

#: Allowed state publication rates [Hz], inclusive: the daemon's 200 Hz is the ceiling;
#: below 1 Hz the operator acts on a view of the joints over a second old.
RATE_RANGE_HZ = (1.0, 200.0)
#: Allowed link allowance on top of one state period [s], (exclusive, inclusive].
MAX_DELAY_RANGE_S = (0.0, 1.0)
#: Board commands of hubo-console that may come over the network (lower case).
REMOTE_CONSOLE_COMMANDS = ("homeall", "home", "reset", "inisensors", "kp", "kd", "maxpwm")
COMMAND_QUEUE = 8  #: commands waiting for the worker at most; more are answered "busy"


@dataclass(frozen=True)
class RobotBridgeConfig:
    """What a robot bridge serves, and to whom.

    Attributes:
        tls: the robot's TLS files.
        listen: zenoh endpoint, ``tls/HOST:PORT``.
        writers: certificate common names of the peers allowed to write.
        instance: the daemon instance.
        robot: robot whose joint limits the console and neck commands respect.
        rate_hz: state publication rate [Hz], within `RATE_RANGE_HZ`.
        max_delay_s: link allowance [s]: a command may be at most ``1 / rate_hz +
            max_delay_s`` older than the robot state its sender had seen.
    """

    tls: TlsFiles
    listen: str = "tls/0.0.0.0:7447"
    writers: tuple[str, ...] = ()
    instance: str = "default"
    robot: str = "drc-hubo"
    rate_hz: float = 10.0
    max_delay_s: float = 0.1

    def __post_init__(self) -> None:
        lo, hi = RATE_RANGE_HZ
        if not (np.isfinite(self.rate_hz) and lo <= self.rate_hz <= hi):
            raise InputError(f"--rate-hz {self.rate_hz:g} refused: allowed [{lo:g}, {hi:g}] Hz "
                             "(the daemon's rate is the ceiling)")
        lo, hi = MAX_DELAY_RANGE_S
        if not (np.isfinite(self.max_delay_s) and lo < self.max_delay_s <= hi):
            raise InputError(f"--max-delay-s {self.max_delay_s:g} refused: allowed "
                             f"({lo:g}, {hi:g}] s")
        check_endpoint("--listen", self.listen)

    @property
    def max_age_s(self) -> float:
        """The oldest state a command may have been sent on [s]."""
        return 1.0 / self.rate_hz + self.max_delay_s


def default_config(tls: TlsFiles) -> RobotBridgeConfig:
    """10 Hz state (hubo-init's default pull), 0.1 s link allowance, no writers."""
    return RobotBridgeConfig(tls)


@dataclass
class BridgeStats:
    """Counters of a robot bridge's run."""

    states_published: int = 0
    state_bytes: int = 0  # payload bytes put [B]
    refs_written: int = 0
    refs_dropped: int = 0  # sent on too old a state, overtaken, or out of order
    refs_malformed: int = 0
    commands_done: int = 0
    commands_refused: int = 0  # refused by the console's, the neck's or the player's checks
    commands_stale: int = 0
    commands_failed: int = 0  # the daemon did not answer
    readonly_peers: int = 0  # connections of peers not allowed to write
    peers: set[str] = field(default_factory=set)  # names of the peers connected now

    def line(self) -> str:
        """One line for the operator's terminal and the log."""
        return (f"states {self.states_published} ({self.state_bytes} B), refs "
                f"{self.refs_written} (dropped {self.refs_dropped}, malformed "
                f"{self.refs_malformed}), commands {self.commands_done} (refused "
                f"{self.commands_refused}, stale {self.commands_stale}, failed "
                f"{self.commands_failed}), read-only peers {self.readonly_peers}, "
                f"connected {sorted(self.peers)}")


class RobotBridge:
    """The robot side (see the module docstring). Opens the instance's channels and a
    zenoh session listening on ``config.listen``; `run` publishes until stopped."""

    def __init__(self, config: RobotBridgeConfig):
        import zenoh

        from daemon.channels import open_channel
        from daemon.local_commands import LocalCommands

        self.config = config
        self.stats = BridgeStats()
        self._age_limit_ns = round(config.max_age_s * 1e9)
        self._local = LocalCommands(config.instance, config.robot)
        self._state = open_channel("state", config.instance)
        self._ref = open_channel("ref", config.instance)
        self._ref_lock = threading.Lock()
        self._ref_slot: tuple[bytes, int | None] | None = None  # newest unwritten sample
        self._ref_ready = threading.Event()
        self._ref_seen: dict[int, tuple[int, int]] = {}  # writer → newest (time_ns, seq)
        self._commands: queue.Queue = queue.Queue(COMMAND_QUEUE)
        self._stop = threading.Event()
        self.session = open_session(robot_config(config.listen, config.tls, config.instance,
                                                 config.writers))
        try:
            self._links = self.session.info.declare_link_events_listener(self._on_link,
                                                                         history=True)
            self._publisher = self.session.declare_publisher(
                key(config.instance, Topic.STATE), express=True,
                congestion_control=zenoh.CongestionControl.DROP,
                reliability=zenoh.Reliability.BEST_EFFORT,
                priority=zenoh.Priority.DATA_HIGH)
            self._ref_sub = self.session.declare_subscriber(key(config.instance, Topic.REF),
                                                            self._on_ref)
            self._queryable = self.session.declare_queryable(key(config.instance, COMMANDS),
                                                             self._on_query)
        except BaseException:
            self.close()
            raise
        self._workers = [threading.Thread(target=self._ref_worker, daemon=True),
                         threading.Thread(target=self._command_worker, daemon=True)]
        for w in self._workers:
            w.start()
        log.info("bridge on %s for instance %r: state at %g Hz, writers %s",
                 config.listen, config.instance, config.rate_hz,
                 ", ".join(config.writers) or "none (read-only)")

    # ------------------------------------------------------------------ state out
    def run(self, stop: threading.Event | None = None, duration_s: float | None = None
            ) -> BridgeStats:
        """Publish the state until ``stop`` is set, `close` is called or ``duration_s``
        passed."""
        period_ns = round(1e9 / self.config.rate_hz)
        end = None if duration_s is None else time.monotonic() + duration_s
        last_ns = next_ns = 0
        while not (self._stop.is_set() or (stop is not None and stop.is_set())):
            if end is not None and time.monotonic() >= end:
                break
            # the first sample written at or after the period's end, as soon as written
            s = self._state.wait_newer(max(last_ns, next_ns - 1), 0.1)
            if s is None:
                continue
            payload = s.tobytes()
            self._publisher.put(payload)
            self.stats.states_published += 1
            self.stats.state_bytes += len(payload)
            last_ns = int(s["time_ns"])
            # on a grid of periods (a daemon writing at the same rate, with jitter, is not
            # halved), never two samples within half a period
            next_ns = max(next_ns + period_ns, last_ns + period_ns // 2)
        return self.stats

    # ------------------------------------------------------------------ references in
    def _fresh(self, stamp_ns: int | None) -> bool:
        """Whether a sender that had seen the state of ``stamp_ns`` is recent enough."""
        if stamp_ns is None:
            return False
        age_ns = time.monotonic_ns() - stamp_ns
        return 0 <= age_ns <= self._age_limit_ns

    def _on_ref(self, sample) -> None:
        """zenoh's callback: keep only the newest sample for the writer thread."""
        attachment = sample.attachment
        stamp = decode_stamp(None if attachment is None else attachment.to_bytes())
        with self._ref_lock:
            if self._ref_slot is not None:
                self.stats.refs_dropped += 1  # overtaken before it was written
            self._ref_slot = (sample.payload.to_bytes(), stamp)
        self._ref_ready.set()

    def _ref_worker(self) -> None:
        while not self._stop.is_set():
            if not self._ref_ready.wait(0.1):
                continue
            with self._ref_lock:
                slot, self._ref_slot = self._ref_slot, None
                self._ref_ready.clear()
            if slot is not None:
                self._write_ref(*slot)

    def _write_ref(self, payload: bytes, stamp_ns: int | None) -> None:
        if len(payload) != REF_DTYPE.itemsize:
            self.stats.refs_malformed += 1
            log.warning("ref sample of %d B refused: a ref sample is %d B", len(payload),
                        REF_DTYPE.itemsize)
            return
        sample = np.frombuffer(payload, REF_DTYPE).reshape(())
        writer, order = int(sample["writer_id"]), (int(sample["time_ns"]), int(sample["seq"]))
        if not self._fresh(stamp_ns) or order <= self._ref_seen.get(writer, (0, 0)):
            self.stats.refs_dropped += 1
            return
        self._ref_seen[writer] = order
        self._ref.write(sample)
        self.stats.refs_written += 1

    # ------------------------------------------------------------------ commands in
    def _on_query(self, query) -> None:
        """zenoh's callback: hand the query to the command worker (or answer busy)."""
        try:
            self._commands.put_nowait(query)
        except queue.Full:
            query.reply_err(b"busy: earlier commands are still running; try again")

    def _command_worker(self) -> None:
        while not self._stop.is_set():
            try:
                query = self._commands.get(timeout=0.1)
            except queue.Empty:
                continue
            with query:
                self._answer(query)

    def _answer(self, query) -> None:
        topic = str(query.key_expr).removeprefix(key(self.config.instance, ""))
        text = b"" if query.payload is None else query.payload.to_bytes()
        attachment = query.attachment
        if not self._fresh(decode_stamp(None if attachment is None else attachment.to_bytes())):
            self.stats.commands_stale += 1
            query.reply_err(b"stale: sent on a robot state older than "
                            + f"{self.config.max_age_s:g} s; not done".encode())
            return
        try:
            reply = self.execute(topic, text.decode("utf-8", "replace"))
        except InputError as exc:
            self.stats.commands_refused += 1
            log.warning("remote %s refused: %s", topic, exc)
            query.reply_err(f"refused: {exc}".encode())
        except HuboLadderError as exc:
            self.stats.commands_failed += 1
            query.reply_err(f"failed: {exc}".encode())
        else:
            self.stats.commands_done += 1
            query.reply(query.key_expr, reply.encode())

    def execute(self, topic: str, text: str) -> str:
        """Carry out one command as its local tool would; returns the reply's text.

        Args:
            topic: ``cmd/console``, ``cmd/neck`` or ``cmd/player``.
            text: the console command, the neck key, or ``pause`` / ``stop``.

        Raises:
            InputError: refused (unknown topic, a command not allowed over the network,
                or the tool's own refusal); nothing was sent.
            HuboLadderError: the daemon did not answer.
        """
        if topic == Topic.CONSOLE.value:
            words = text.split()
            if not words or words[0].lower() not in REMOTE_CONSOLE_COMMANDS:
                raise InputError(f"console command {text!r} not allowed over the bridge; "
                                 "allowed: homeAll, home J, reset J, iniSensors, kp J v, "
                                 "kd J v, maxPWM J v")
            return self._local.console(text)
        if topic == Topic.NECK.value:
            return self._local.neck(text)
        if topic == Topic.PLAYER.value:
            try:
                command = PlayerCommand(text.strip().lower())
            except ValueError:
                raise InputError(f"player command {text!r}: use pause or stop") from None
            return self._local.player(command)
        raise InputError(f"unknown command topic {topic!r}")

    # ------------------------------------------------------------------ peers
    def _on_link(self, event) -> None:
        import zenoh

        link = event.link
        name = link.auth_identifier or "?"
        if event.kind == zenoh.SampleKind.PUT:
            self.stats.peers.add(name)
            if name not in self.config.writers:
                self.stats.readonly_peers += 1
                log.warning("peer %r connected from %s: not configured to write; zenoh's "
                            "access control drops its references and commands", name, link.dst)
            else:
                log.info("writer %r connected from %s", name, link.dst)
        else:
            self.stats.peers.discard(name)
            log.info("peer %r disconnected", name)

    def close(self) -> None:
        """Stop the workers, close the zenoh session and the channels; idempotent."""
        self._stop.set()
        for w in getattr(self, "_workers", ()):
            w.join(2.0)
        session = getattr(self, "session", None)
        if session is not None and not session.is_closed():
            session.close()
        self._local.close()
        self._state.close()
        self._ref.close()
