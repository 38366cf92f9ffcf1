"""The operator side of the bridge: the robot's state, and commands to it, from Python.

`BridgeOperator` is what ``hubo-bridge operator`` and a web page use on the operator's
computer. It is a zenoh client of the robot's bridge (`daemon.remote.robot`), presenting
the operator's certificate:

- the robot's ``state`` arrives as the daemon's own struct (`latest_state`,
  `wait_state`); an optional callback sees each sample (`daemon.remote.mirror` writes
  them into a local channel);
- `send_ref` puts a ``ref`` sample (a remote player), best-effort and dropped rather
  than queued under congestion: a late reference is worth nothing;
- `command` sends a board command, a neck key or a player control and returns the
  robot's answer, or raises its refusal (`RemoteRefusal`, with the local tool's reason).

Everything sent carries the freshness stamp of `daemon.remote.keys` (the ``time_ns`` of
the newest state received), so nothing can be sent before a first state arrives.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable

import numpy as np

from daemon.remote.keys import Topic, encode_stamp, key
from daemon.remote.session_config import TlsFiles, check_endpoint, open_session, operator_config
from daemon.structs import REF_DTYPE, STATE_DTYPE
from robot.errors import HuboLadderError, InputError

__all__ = ["BridgeOperator", "RemoteRefusal", "wait_first_state"]

COMMAND_TIMEOUT_S = 2.0  #: wait at most this for the robot's answer [s]


class RemoteRefusal(InputError):
    """The robot refused a command (its local tool's check, or a stale command).

    Attributes:
        reason: the robot's words without the topic: the local tool's refusal as that
            tool words it (a page shows it as a local refusal), or ``stale: ...``.
    """

    def __init__(self, topic: Topic, text: str, answer: str):
        self.reason = answer.removeprefix("refused: ")
        super().__init__(f"{topic.value} {text!r}: {answer}")


class BridgeOperator:
    """An operator's link to one robot bridge (see the module docstring).

    Args:
        connect: the robot bridge's endpoint, ``tls/HOST:PORT``.
        tls: this operator's TLS files; its certificate's name must be one of the
            robot's ``--allow-writer`` names for commands to reach it.
        instance: the daemon instance on the robot.
        on_state: called with each state sample as it arrives (zenoh's thread).
        timeout_s: how long `command` waits for the answer [s].
    """

    def __init__(self, connect: str, tls: TlsFiles, instance: str = "default",
                 on_state: Callable[[np.ndarray], None] | None = None,
                 timeout_s: float = COMMAND_TIMEOUT_S):
        import zenoh

        self.instance = instance
        self.timeout_s = timeout_s
        self.states_received = 0
        self.state_bytes = 0  # payload bytes received [B]
        self._on_state_hook = on_state
        self._cond = threading.Condition()
        self._latest: np.ndarray | None = None
        self._ref_seq = self._ref_time_ns = 0
        self.session = open_session(operator_config(check_endpoint("--connect", connect), tls))
        try:
            self._ref_pub = self.session.declare_publisher(
                key(instance, Topic.REF), express=True,
                congestion_control=zenoh.CongestionControl.DROP,
                reliability=zenoh.Reliability.BEST_EFFORT,
                priority=zenoh.Priority.REAL_TIME)
            self._state_sub = self.session.declare_subscriber(key(instance, Topic.STATE),
                                                              self._on_state)
        except BaseException:
            self.session.close()
            raise

    def _on_state(self, sample) -> None:
        payload = sample.payload.to_bytes()
        if len(payload) != STATE_DTYPE.itemsize:
            return
        state = np.frombuffer(payload, STATE_DTYPE).reshape(())
        with self._cond:
            self._latest = state
            self.states_received += 1
            self.state_bytes += len(payload)
            self._cond.notify_all()
        if self._on_state_hook is not None:
            self._on_state_hook(state)

    def latest_state(self) -> np.ndarray | None:
        """The newest state sample received (read-only), or None."""
        with self._cond:
            return self._latest

    def wait_state(self, newer_than_ns: int = 0, timeout_s: float = 1.0) -> np.ndarray | None:
        """The newest state once one with ``time_ns`` > ``newer_than_ns`` [ns] has arrived;
        None after ``timeout_s`` [s]."""
        def newer() -> bool:
            return self._latest is not None and int(self._latest["time_ns"]) > newer_than_ns

        with self._cond:
            return self._latest if self._cond.wait_for(newer, timeout_s) else None

    def _stamp(self) -> bytes:
        state = self.latest_state()
        if state is None:
            raise HuboLadderError("no state from the robot bridge yet: nothing is sent "
                                  "before the robot has been seen")
        return encode_stamp(int(state["time_ns"]))

    def send_ref(self, sample: np.ndarray) -> None:
        """Put one ``ref`` sample (the daemon's `REF_DTYPE`) towards the robot, its header
        stamped by this operator (process id, sequence number, clock), by which the robot
        drops samples that arrive out of order."""
        stamp = self._stamp()
        out = np.array(sample, dtype=REF_DTYPE).reshape(())
        self._ref_seq += 1
        self._ref_time_ns = max(time.monotonic_ns(), self._ref_time_ns + 1)
        out["writer_id"], out["seq"], out["time_ns"] = os.getpid(), self._ref_seq, \
            self._ref_time_ns
        self._ref_pub.put(out.tobytes(), attachment=stamp)

    def command(self, topic: Topic, text: str) -> str:
        """Send a command and return the robot's answer.

        Args:
            topic: `Topic.CONSOLE` (``homeAll``, ``home RSP``, ``kp RSP 20``, ...),
                `Topic.NECK` (one key of ``wasdqec``) or `Topic.PLAYER` (``pause``,
                ``stop``).
            text: the command.

        Raises:
            RemoteRefusal: the robot refused it (the reason is its local tool's).
            HuboLadderError: no answer in ``timeout_s`` (not connected, or this
                operator is not allowed to write: zenoh drops its commands), or the
                daemon did not answer the robot.
        """
        stamp = self._stamp()
        replies = self.session.get(key(self.instance, topic), payload=text.encode(),
                                   attachment=stamp, timeout=self.timeout_s)
        for reply in replies:
            if reply.ok is not None:
                return reply.ok.payload.to_bytes().decode()
            reason = reply.err.payload.to_bytes().decode()
            if reason.startswith(("refused:", "stale:")):
                raise RemoteRefusal(topic, text, reason)
            raise HuboLadderError(f"{topic.value} {text!r}: {reason}")
        raise HuboLadderError(f"{topic.value} {text!r}: no answer from the robot bridge in "
                              f"{self.timeout_s:g} s (not connected, or this operator may "
                              "not write)")

    def close(self) -> None:
        """Close the zenoh session; idempotent."""
        if not self.session.is_closed():
            self.session.close()

    def __enter__(self) -> BridgeOperator:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def wait_first_state(operator: BridgeOperator, timeout_s: float) -> np.ndarray:
    """The first state from the robot, or a `HuboLadderError` after ``timeout_s`` [s]."""
    t0 = time.monotonic()
    state = operator.wait_state(0, timeout_s)
    if state is None:
        raise HuboLadderError(f"no state from the robot bridge in {time.monotonic() - t0:.1f} s "
                              f"(instance {operator.instance!r}; is the bridge running, and "
                              "the daemon ticking?)")
    return state
