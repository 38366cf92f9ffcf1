"""What the bridge puts on the network: its zenoh key expressions and the freshness stamp.

Keys are ``hubo/<instance>/<topic>``, one instance per daemon as for the channels:

================  =========  =================================================  ==========
topic             zenoh      payload                                            who writes
================  =========  =================================================  ==========
``state``         put        a ``state`` sample, the channel's bytes (2200 B)   robot
``ref``           put        a ``ref`` sample (741 B)                           operator
``cmd/console``   query      a ``hubo-console`` board command, UTF-8 text       operator
``cmd/neck``      query      one ``hubo-neck`` key                              operator
``cmd/player``    query      ``pause`` or ``stop``                              operator
================  =========  =================================================  ==========

Everything an operator sends carries, as its zenoh attachment, the freshness stamp: the
``time_ns`` of the newest ``state`` sample it had received (8 bytes, little-endian),
which is the robot's own ``CLOCK_MONOTONIC``. The robot measures the command's age on
its own clock, so no clock is shared between the two machines: a command sent on a
state older than the bridge's limit, or one that waited in a queue during a link outage,
is dropped instead of played late.
"""

from __future__ import annotations

import enum
import struct

__all__ = ["COMMANDS", "PREFIX", "Topic", "decode_stamp", "encode_stamp", "key"]

PREFIX = "hubo"
_STAMP = struct.Struct("<q")


class Topic(enum.Enum):
    """The bridge's topics (see the module docstring)."""

    STATE = "state"
    REF = "ref"
    CONSOLE = "cmd/console"
    NECK = "cmd/neck"
    PLAYER = "cmd/player"


COMMANDS = "cmd/**"  #: every command topic, for the robot's queryable and its ACL rule


def key(instance: str, topic: Topic | str) -> str:
    """The key expression of ``topic`` (or a pattern such as `COMMANDS`) of ``instance``."""
    return f"{PREFIX}/{instance}/{topic.value if isinstance(topic, Topic) else topic}"


def encode_stamp(state_time_ns: int) -> bytes:
    """The freshness stamp of a command sent knowing the state of ``state_time_ns`` [ns]."""
    return _STAMP.pack(int(state_time_ns))


def decode_stamp(attachment: bytes | None) -> int | None:
    """The state ``time_ns`` [ns] a freshness stamp carries; None if absent or malformed."""
    if attachment is None or len(attachment) != _STAMP.size:
        return None
    return _STAMP.unpack(attachment)[0]
