"""``hubo-neck``: turn the head from the keyboard, to watch each grasp on the head camera.

    hubo-neck [--instance NAME] [--robot R] [--keys KEYS] [--step RAD] [--yaw-step RAD]

The thesis's operator watched every grasp through the head camera and turned the head
with this tool (hubo-facts, "The operator"). Single keys, no Enter; ``--keys`` applies
its keys in order and exits (scripts, tests):

=====  =========================================================================
``w``  tilt the head up: ``NK1`` (neck pitch) − step
``s``  tilt it down: ``NK1`` + step
``a``  lean it to the robot's left: ``NK2`` (neck roll) − step
``d``  lean it to the robot's right: ``NK2`` + step
``q``  turn it to the robot's left: ``NKY`` (neck yaw) + yaw step
``e``  turn it to the robot's right: ``NKY`` − yaw step
``c``  centre: every neck joint to 0 rad (within its limits)
``x``  quit (Ctrl-C too)
=====  =========================================================================

Axes, from `robot.kinematic_tree` (x forward, z up): ``NKY`` turns about z, then ``NK1``
about y (the pitch: positive tips the face down), then ``NK2`` about x (the roll:
positive tips the top of the head to the robot's right). The step is 0.3 rad
(``--step``, allowed (0, 0.5]), the yaw step 1 rad (``--yaw-step``, allowed (0, 1.5]).

A key's goal is the joint's commanded goal plus the step, clamped to the joint's limits
(`robot.limits.joint_limits` of ``--robot``): the head stops at a limit, and a key that
would push it further sends nothing and says the joint is at its limit. The commanded
goal is the newest ``ref-neck`` sample since the daemon started, else the neck entries of
the newest ``ref`` sample, else the state's sent reference.

Goals go on the daemon's ``ref-neck`` channel (hubo-ach's ``hubo-ref-neck``), which the
daemon lays over the neck joints of the newest ``ref`` sample: the head turns while a
player plays (the operator's use), and hubo-neck never writes the other 37 joints. The
daemon follows a neck goal only on top of a ``ref`` sample; when none was written since it
started, hubo-neck first sends the hold ``hubo-console goto`` sends (every joint at its
sent reference). Once a neck goal is sent, the neck follows ``ref-neck`` (a later
``hubo-console goto NKY`` is overridden) until the daemon restarts. Each key waits until
the daemon has ticked past it, as the console's commands do.

Exit codes: 0 done, 1 the daemon did not answer, 2 refused (a flag out of range, an
unknown key in ``--keys``, no terminal): nothing is sent.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from daemon.console import Console, add_daemon_options
from daemon.loop import NECK_JOINTS
from robot.errors import InputError, parse_finite, run_cli
from robot.joints import JOINT_INDEX, JOINT_NAMES
from robot.limits import JointLimits

__all__ = ["NeckConfig", "NeckKey", "NeckLink", "NeckMove", "default_config", "main",
           "next_goals"]

#: The neck joints, in trajectory-file order: yaw, pitch, roll.
NECK_NAMES: tuple[str, ...] = tuple(JOINT_NAMES[j] for j in NECK_JOINTS)
#: Allowed steps, as (exclusive lower, inclusive upper) bounds [rad].
STEP_RANGE_RAD = (0.0, 0.5)
YAW_STEP_RANGE_RAD = (0.0, 1.5)
CENTRE_KEY = "c"
QUIT_KEY = "x"


class NeckKey(NamedTuple):
    """What a movement key does: step ``joint`` by ``sign`` times the (yaw) step."""

    joint: str  # NKY, NK1 or NK2
    sign: int  # +1 or -1
    yaw: bool  # True: the yaw step, False: the step


MOVE_KEYS: dict[str, NeckKey] = {
    "w": NeckKey("NK1", -1, False), "s": NeckKey("NK1", +1, False),
    "a": NeckKey("NK2", -1, False), "d": NeckKey("NK2", +1, False),
    "q": NeckKey("NKY", +1, True), "e": NeckKey("NKY", -1, True),
}
KEYS = "".join(MOVE_KEYS) + CENTRE_KEY + QUIT_KEY


@dataclass(frozen=True)
class NeckConfig:
    """Step sizes [rad]."""

    step_rad: float = 0.3  # NK1 and NK2, per key press
    yaw_step_rad: float = 1.0  # NKY, per key press


def default_config() -> NeckConfig:
    """The thesis tool's steps: 0.3 rad in pitch and roll, 1 rad in yaw."""
    return NeckConfig()


@dataclass(frozen=True)
class NeckMove:
    """The neck goals after one key press.

    ``goals_rad`` holds every neck joint's goal [rad]; ``moved`` the joints whose goal
    changed (nothing to send when empty); ``at_limit`` the joints whose step was clamped
    onto a limit (or, for the centre key, whose 0 lies beyond one).
    """

    key: str
    goals_rad: dict[str, float]
    moved: tuple[str, ...]
    at_limit: tuple[str, ...]

    def line(self) -> str:
        """One line for the operator: the joint(s), the new goal [rad], at its limit."""
        joints = (MOVE_KEYS[self.key].joint,) if self.key in MOVE_KEYS else NECK_NAMES
        text = "  ".join(f"{j} goal {self.goals_rad[j]:+.3f} rad"
                         + ("  at its limit" if j in self.at_limit else "") for j in joints)
        return f"{self.key}  {text}" + ("" if self.moved else "  (nothing sent)")


def next_goals(key: str, goals_rad: Mapping[str, float], limits: JointLimits,
               config: NeckConfig) -> NeckMove:
    """The neck goals after pressing ``key`` (a movement key or `CENTRE_KEY`).

    Args:
        key: one of ``w s a d q e c``.
        goals_rad: every neck joint's current commanded goal [rad].
        limits: the robot's joint limits; goals are clamped into them.
        config: the step sizes.
    """
    goals = {j: float(goals_rad[j]) for j in NECK_NAMES}
    if key == CENTRE_KEY:
        targets = dict.fromkeys(NECK_NAMES, 0.0)
    else:
        k = MOVE_KEYS[key]
        step = config.yaw_step_rad if k.yaw else config.step_rad
        targets = {k.joint: goals[k.joint] + k.sign * step}
    new, at_limit = dict(goals), []
    for joint, target in targets.items():
        j = JOINT_INDEX[joint]
        lo, hi = float(limits.lower_rad[j]), float(limits.upper_rad[j])
        new[joint] = min(max(target, lo), hi)
        if new[joint] != target:
            at_limit.append(joint)
    moved = tuple(j for j in NECK_NAMES if new[j] != goals[j])
    return NeckMove(key, new, moved, tuple(at_limit))


class NeckLink:
    """hubo-neck's link to a daemon: a `Console` (its channels, state and acknowledgement
    wait) and the ``ref-neck`` channel."""

    def __init__(self, instance: str = "default", robot: str = "drc-hubo"):
        from daemon.channels import open_channel

        self.console = Console(instance, robot=robot)
        self.limits = self.console.limits
        self.neck = open_channel("ref-neck", instance)

    def close(self) -> None:
        self.neck.close()
        self.console.close()

    def _live(self, channel) -> np.ndarray | None:
        """``channel``'s newest sample if written since the daemon started (older ones the
        daemon ignores)."""
        start_ns = int(self.console.state_now()["start_ns"])
        sample = channel.read_latest()
        return sample if sample is not None and int(sample["time_ns"]) >= start_ns else None

    def goals_rad(self) -> dict[str, float]:
        """Every neck joint's commanded goal [rad] (see the module docstring)."""
        ref, neck = self._live(self.console.ref), self._live(self.neck)
        source = (neck if neck is not None and ref is not None
                  else ref if ref is not None else self.console.state_now())
        return {JOINT_NAMES[j]: float(source["ref"][j]) for j in NECK_JOINTS}

    def send(self, goals_rad: Mapping[str, float]) -> None:
        """Send the neck goals [rad] on ``ref-neck`` (filtered position mode, rigid) and
        wait until the daemon has ticked past them; first the console's hold on ``ref``
        when the daemon has no ``ref`` sample to lay them over."""
        from daemon.control_modes import RefMode
        from daemon.structs import REF_DTYPE, new_sample

        if self._live(self.console.ref) is None:
            j = int(NECK_JOINTS[0])
            self.console.reference(j, float(self.console.state_now()["ref"][j]), False)
        before = self.console.state_now()
        r = new_sample(REF_DTYPE)
        r["mode"][NECK_JOINTS] = RefMode.FILTER
        for joint, rad in goals_rad.items():
            r["ref"][JOINT_INDEX[joint]] = rad
        r["playing"] = 0
        self.neck.write(r)
        self.console.wait_ticks(before)


def press(link: NeckLink, key: str, config: NeckConfig, out=None) -> bool:
    """Apply one key on the daemon and print its line (to ``out``, default stdout);
    False on the quit key.

    Raises:
        InputError: an unknown key.
        HuboLadderError: the daemon did not answer.
    """
    key = key.lower()
    if key == QUIT_KEY:
        return False
    if key not in MOVE_KEYS and key != CENTRE_KEY:
        raise InputError(f"unknown key {key!r}; keys: {' '.join(KEYS)}")
    move = next_goals(key, link.goals_rad(), link.limits, config)
    if move.moved:
        link.send(move.goals_rad)
    print(move.line(), file=out or sys.stdout, flush=True)
    return True


@contextmanager
def single_keys(fd: int) -> Iterator[Callable[[], str]]:
    """Read a terminal key by key, without Enter: ``fd`` in cbreak mode (no echo, no line
    buffering; Ctrl-C still interrupts), its settings restored however the block ends.
    Yields a function returning the next key ('' at end of input)."""
    import termios
    import tty

    saved = termios.tcgetattr(fd)
    try:
        tty.setcbreak(fd)
        yield lambda: os.read(fd, 1).decode(errors="replace")
    finally:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)


def _step(flag: str, text: str, allowed: tuple[float, float]) -> float:
    """``text`` as a step [rad] within ``allowed`` (exclusive lower, inclusive upper)."""
    rad = parse_finite(text, flag)
    if not allowed[0] < rad <= allowed[1]:
        raise InputError(f"{flag} {rad:g} refused: allowed ({allowed[0]:g}, {allowed[1]:g}] "
                         "rad; nothing sent")
    return rad


def _run(args: argparse.Namespace) -> int:
    config = NeckConfig(_step("--step", args.step, STEP_RANGE_RAD),
                        _step("--yaw-step", args.yaw_step, YAW_STEP_RANGE_RAD))
    if args.keys is not None:
        bad = [(i, k) for i, k in enumerate(args.keys, 1) if k.lower() not in KEYS]
        if bad:
            raise InputError(f"--keys {args.keys!r}: unknown key {bad[0][1]!r} at position "
                             f"{bad[0][0]}; keys: {' '.join(KEYS)}; nothing sent")
    elif not sys.stdin.isatty():
        raise InputError("stdin is not a terminal: pass the keys with --keys")
    link = NeckLink(args.instance, args.robot)
    try:
        if args.keys is not None:
            for key in args.keys:
                if not press(link, key, config):
                    break
            return 0
        print(f"hubo-neck: {' '.join(KEYS)} (x quits)", file=sys.stderr)
        with single_keys(sys.stdin.fileno()) as read_key:
            while (key := read_key()) and key.lower() != QUIT_KEY:
                if key.lower() in KEYS:
                    press(link, key, config)
                else:
                    print(f"key {key!r}: keys are {' '.join(KEYS)}", file=sys.stderr)
    except KeyboardInterrupt:
        pass
    finally:
        link.close()
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``hubo-neck``; returns the exit code."""
    p = argparse.ArgumentParser(prog="hubo-neck", description=__doc__.split("\n\n")[0])
    add_daemon_options(p, "the neck goals")
    p.add_argument("--keys", help="apply these keys in order and exit (no terminal)")
    p.add_argument("--step", default="0.3", metavar="RAD",
                   help="NK1/NK2 step per key (default 0.3, allowed (0, 0.5]) [rad]")
    p.add_argument("--yaw-step", default="1.0", metavar="RAD",
                   help="NKY step per key (default 1.0, allowed (0, 1.5]) [rad]")
    args = p.parse_args(argv)
    return run_cli("hubo-neck", lambda: _run(args))


if __name__ == "__main__":
    sys.exit(main())
