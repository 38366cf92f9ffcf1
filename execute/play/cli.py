"""``play-trajectory``: hubo-read-trajectory's flags, playing a 40-column file to the daemon.

    play-trajectory -n FILE [-f 10|25|50|100|200|500] [-i] [-c|-cl|-cr] [-nf] [-p]
                    [-line N] [--open-loop] [--no-auto-modes] [--instance NAME] [--robot R]
                    [--clamp-limits TOL] [--max-reach-correction M] [--grasp-retries N]
                    [--holding-arm-stiffness S] [--replan-beyond M [--measured-ladder F]]

Before anything is sent, the whole file is checked (`robot.trajectory_file`): a bad file
exits 2 naming ``FILE:LINE:COLUMN``, and the ``ref`` channel is never written. Values
beyond a joint limit are refused too, unless ``--clamp-limits TOL`` [rad] is given: then
values at most TOL beyond a limit are moved onto it (files written for the original player
overshoot the knee's 0 lower limit by up to 0.07 rad), and a per-joint report says which
lines moved and the largest overshoot; farther values are still refused. The sidecar
``FILE.plan.json``, when present, gives the rate (unless ``-f``), the per-arm
position/PWM schedule and the compliant arms' feed-forward (unless ``--no-auto-modes``);
``-c``, ``-cl``, ``-cr`` force an arm compliant for the whole file. The feed-forward
torques go out as each ``ref`` sample's ``pwm_command`` duty, at the battery voltage the
daemon reports (as ``validate-plan`` plays them).

One player at a time: before touching a channel it takes the instance's player lock
(`execute.play.lock`); a second player on the same daemon exits 2 naming the first one's
pid. A lock left by a killed player is recovered.

Then it waits for a running ``hubo-daemon`` on ``--instance`` (its ``state`` channel
ticking), refuses joints that are not homed, waits for a homing in progress to end, and
without ``-i`` refuses to start when the robot stands farther than ``--line-tolerance``
from the start line (``-line N``, 1-based). With ``-i`` it first moves there smoothly
(minimum jerk, ``--init-s``, 3 s).

With a sidecar, playback is closed loop by default: the motion layer (`execute.motion`)
reads the daemon's ``state`` channel every tick, checks every grasp from the finger
encoders before the plan loads it, re-reaches a miss, re-targets later reaches and
compensates the compliant arms' gravity; it first sets the arms' PWM clamps to the
safety ceiling on the daemon's ``pwm-gains`` channel (`execute.motion.gains`). If a
grasp cannot be made it stops and holds (exit 1). Its flags are `validate-plan`'s
(`execute.motion.config.add_motion_arguments`). With ``--replan-beyond M``, when the
first two grasps find the plan's holds more than M from the real ones, it stops before the
ladder takes any weight, writes the ladder as the hands found it (``--measured-ladder``),
opens the hands, retraces the plan to its first line (`execute.motion.retract`) and prints
the ``plan-ladder`` command for a new plan (exit 1). ``--open-loop`` plays the file as
hubo-read-trajectory did.

It streams one ``ref`` sample per 5 ms (absolute deadlines), ``playing`` set, and shows
the line, the time and the arms' modes. With ``-p``: the ``p`` key (when stdin is a
terminal) and SIGUSR1 toggle pause; resuming continues where it stopped (no catch-up).
At the end, and on Ctrl-C / SIGTERM, the last reference stays on the channel with
``playing`` cleared: the robot holds it.

Exit codes: 0 played to the end, 1 refused or failed (no daemon, not homed, too far from
the start line, a grasp the motion layer could not make), 2 bad input or another player
on the instance, 130 stopped by Ctrl-C (holding).
"""

from __future__ import annotations

import argparse
import logging
import os
import select
import signal
import sys
import time
from pathlib import Path

import numpy as np

from execute.motion.config import add_motion_arguments, motion_config_from_args
from robot.errors import HuboLadderError, InputError, run_cli
from robot.vocabulary import FailureCause

__all__ = ["main"]

log = logging.getLogger("play-trajectory")

TICK_NS = 5_000_000
DAEMON_WAIT_S = 3.0  # how long to wait for the daemon's state channel [s]
HOMING_WAIT_S = 4.0  # how long to wait for a homing in progress to end [s]


def _parser() -> argparse.ArgumentParser:
    from execute.play.player import ALLOWED_RATES_HZ

    p = argparse.ArgumentParser(prog="play-trajectory", allow_abbrev=False,
                                description=__doc__.split("\n\n")[0])
    p.add_argument("-n", dest="file", required=True, metavar="FILE",
                   help="the 40-column trajectory file (.gz: gzip-compressed)")
    p.add_argument("-f", dest="rate", type=int, choices=ALLOWED_RATES_HZ, metavar="HZ",
                   help="line rate: 10, 25, 50, 100, 200 or 500 Hz (default: the "
                        "sidecar's, else 25)")
    p.add_argument("-i", dest="init", action="store_true",
                   help="go to the start line smoothly first")
    arms = p.add_mutually_exclusive_group()
    arms.add_argument("-c", dest="c", action="store_true", help="both arms compliant")
    arms.add_argument("-cl", dest="cl", action="store_true", help="left arm compliant")
    arms.add_argument("-cr", dest="cr", action="store_true", help="right arm compliant")
    p.add_argument("-nf", dest="no_filter", action="store_true",
                   help="direct reference mode: no daemon-side filter")
    p.add_argument("-p", dest="pause", action="store_true",
                   help="pause feature: key p (terminal) or SIGUSR1 toggles pause")
    p.add_argument("-line", dest="line", type=int, default=1, metavar="N",
                   help="start at 1-based line N")
    p.add_argument("--open-loop", action="store_true",
                   help="play the file as hubo-read-trajectory did; by default a plan with a "
                        "sidecar plays through the motion layer (grasp checks, re-reach, "
                        "reach correction, gravity compensation) on the daemon's state")
    p.add_argument("--no-auto-modes", action="store_true",
                   help="ignore the sidecar's per-arm position/PWM schedule and "
                        "feed-forward")
    p.add_argument("--instance", default="default", help="daemon instance (default)")
    p.add_argument("--robot", default=None, help="robot (default: the sidecar's or drc-hubo)")
    p.add_argument("--init-s", type=float, default=3.0, metavar="S",
                   help="duration of the -i move [s] (default 3)")
    p.add_argument("--line-tolerance", type=float, default=0.05, metavar="RAD",
                   help="without -i: largest joint distance to the start line [rad]")
    p.add_argument("--clamp-limits", type=float, default=None, metavar="TOL",
                   help="clamp values at most TOL [rad] (up to 0.1) beyond a joint limit onto "
                        "it, with a per-joint report; farther ones are refused (default: "
                        "strict, every value within the limits)")
    add_motion_arguments(p)
    p.add_argument("--measured-ladder", metavar="SPEC.yaml", default=None,
                   help="with --replan-beyond: where to write the ladder as the hands found "
                        "it (default: beside FILE, FILE's name with .measured-ladder.yaml)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress line")
    return p


def _load(args):
    """Everything that can be refused before a channel is touched."""
    from execute.play.player import (
        PlayerOptions,
        TrajectoryPlayer,
        compliant_arms_from_flags,
    )
    from robot.plan_sidecar import check_line_count, read_sidecar, sidecar_path
    from robot.trajectory_file import format_clamps, read_trajectory, read_trajectory_clamped

    path = Path(args.file)
    side = sidecar_path(path)
    sidecar = read_sidecar(side) if side.exists() else None
    rate = args.rate or (int(round(sidecar.rate_hz)) if sidecar else 25)
    if sidecar and args.rate and args.rate != round(sidecar.rate_hz):
        log.warning("%s was timed for %g Hz; playing it at %d Hz changes its speed", path,
                    sidecar.rate_hz, args.rate)
    robot = args.robot or (sidecar.robot if sidecar else "drc-hubo")
    args.robot = robot
    if args.clamp_limits is None:
        traj = read_trajectory(path, rate, robot)
    else:
        traj, clamps = read_trajectory_clamped(path, rate, args.clamp_limits, robot)
        if clamps:
            print(f"play-trajectory: {format_clamps(str(path), clamps, args.clamp_limits)}",
                  file=sys.stderr, flush=True)
    if sidecar:
        check_line_count(path, len(traj), sidecar)
    auto = sidecar is not None and not args.no_auto_modes
    schedule = sidecar.arm_modes if auto else None
    opts = PlayerOptions(rate_hz=rate, go_to_init=args.init, go_to_init_s=args.init_s,
                         compliant_arms=compliant_arms_from_flags(args.c, args.cl, args.cr),
                         no_filter=args.no_filter, start_line=args.line)
    if not (np.isfinite(args.line_tolerance) and args.line_tolerance > 0):
        raise InputError(f"--line-tolerance {args.line_tolerance}: must be > 0 [rad]")
    player = TrajectoryPlayer(traj, opts, schedule, sidecar.arm_feedforward if auto else None)
    config = motion_config_from_args(args)
    motion = None
    if auto and not args.open_loop:
        from execute.motion.layer import MotionLayer
        from execute.validate.cli import ladder_from_sidecar

        ladder = ladder_from_sidecar(sidecar.ladder, f"{side}: ladder")
        motion = MotionLayer(player, traj, sidecar, ladder, robot, config)
    return traj, player, auto, motion


def _wait_for_daemon(state, instance: str) -> np.ndarray:
    from daemon.structs import StatusFlag
    from robot.joints import JOINT_NAMES

    deadline = time.monotonic() + DAEMON_WAIT_S
    s = None
    while time.monotonic() < deadline:
        s = state.wait_newer(0 if s is None else int(s["time_ns"]), 0.2)
        if s is not None and time.monotonic_ns() - int(s["time_ns"]) < 200_000_000:
            break
    else:
        raise HuboLadderError(f"no hubo-daemon is running on instance {instance!r} (its "
                              "state channel is silent); start it first")
    unhomed = [JOINT_NAMES[j] for j in np.flatnonzero(np.asarray(s["zeroed"]) == 0)]
    if unhomed:
        raise HuboLadderError(f"joints not homed: {' '.join(unhomed)}; run "
                              "`hubo-console` homeAll first")
    deadline = time.monotonic() + HOMING_WAIT_S
    while np.any(np.asarray(s["status"]) & int(StatusFlag.NOT_HOMED)):
        if time.monotonic() > deadline:
            raise HuboLadderError("the daemon still ignores references (homing or control "
                                  "off); try again when `hubo-console statusAll` is clear")
        time.sleep(0.05)
        s = state.read_latest()
    return s


def _check_start(traj, line: int, pos: np.ndarray, tol: float) -> None:
    from robot.joints import JOINT_NAMES

    dev = np.abs(pos - traj[line - 1])
    j = int(np.argmax(dev))
    if dev[j] > tol:
        raise HuboLadderError(
            f"the robot is {dev[j]:.3f} rad from line {line} at {JOINT_NAMES[j]} (tolerance "
            f"{tol:g} rad); move it there first or add -i to go there smoothly")


class _Keys:
    """``p`` key presses on a terminal stdin in cbreak mode (restored on close)."""

    def __init__(self) -> None:
        import termios
        import tty

        self.fd = sys.stdin.fileno()
        self._saved = termios.tcgetattr(self.fd)
        tty.setcbreak(self.fd)

    def presses(self) -> int:
        n = 0
        while select.select([self.fd], [], [], 0)[0]:
            data = os.read(self.fd, 64)
            if not data:
                break
            n += data.lower().count(b"p")
        return n

    def close(self) -> None:
        import termios

        termios.tcsetattr(self.fd, termios.TCSADRAIN, self._saved)


def _send_gains(gains, instance: str) -> None:
    """Write the motion layer's arm gains on the daemon's ``pwm-gains`` channel (the
    daemon checks them against the safety limits like any writer's)."""
    from daemon.channels import open_channel
    from daemon.structs import PWM_GAINS_DTYPE, new_sample

    channel = open_channel("pwm-gains", instance)
    try:
        sample = new_sample(PWM_GAINS_DTYPE)
        sample["kp"], sample["kd"] = gains.kp, gains.kd
        sample["max_pwm"], sample["pwm_command"] = gains.max_pwm_pct, gains.pwm_command_pct
        channel.write(sample)
    finally:
        channel.close()


def _play(args, traj, player, auto, motion=None) -> int:
    """Play to the daemon once it runs, is homed and the robot stands at the start line;
    returns the exit code. The channels are closed and the terminal restored on exit."""
    from daemon.channels import open_channel
    from robot.limits import joint_limits

    limits = joint_limits(args.robot)

    ref = open_channel("ref", args.instance)
    state = open_channel("state", args.instance)
    keys = None
    try:
        s = _wait_for_daemon(state, args.instance)
        if not args.init:
            _check_start(traj, args.line, np.asarray(s["pos"]), args.line_tolerance)
        if motion is not None:
            _send_gains(motion.pwm_gains, args.instance)
        signals = _Signals(args.pause)
        if args.pause and sys.stdin.isatty():
            keys = _Keys()
        if not args.quiet:
            modes = "sidecar arm modes" if auto else "no sidecar arm modes"
            print(f"play-trajectory: {args.file}: {player.num_lines} lines at "
                  f"{player.options.rate_hz} Hz, {player.duration_s:.1f} s, {modes}"
                  + ("; p pauses" if args.pause else ""), file=sys.stderr, flush=True)
        return _stream(args, player, motion, ref, state, limits, signals, keys)
    finally:
        if keys is not None:
            keys.close()
        ref.close()
        state.close()


class _Signals:
    """What the signals asked of the playback loop: stop (SIGINT, SIGTERM) and, with
    ``-p``, pause toggles (SIGUSR1; the ``p`` key adds its presses)."""

    def __init__(self, pause: bool) -> None:
        self.stop = False
        self.toggles = 0
        signal.signal(signal.SIGINT, self._on_stop)
        signal.signal(signal.SIGTERM, self._on_stop)
        if pause:
            signal.signal(signal.SIGUSR1, self._on_usr1)

    def _on_stop(self, signum, frame) -> None:
        self.stop = True

    def _on_usr1(self, signum, frame) -> None:
        self.toggles += 1


def _stream(args, player, motion, ref, state, limits, signals: _Signals, keys) -> int:
    """One ``ref`` sample per `TICK_NS` on absolute deadlines, until the file ends (0),
    the motion layer stops and holds (1) or a signal stops it (130, holding)."""
    from daemon.loop import sleep_until_ns
    from daemon.structs import REF_DTYPE, new_sample
    from robot.motors import DEFAULT_BATTERY_V, motor_table

    sample = new_sample(REF_DTYPE)
    sample["playing"] = 1
    motors = motor_table()
    deadline = time.monotonic_ns()
    next_show = 0.0
    t0_s = time.monotonic()
    tick = None
    while True:
        now_s = time.monotonic()
        if keys is not None:
            signals.toggles += keys.presses()
        if signals.stop:
            break
        # The state only matters for go-to-init's start pose and the feed-forward's
        # battery voltage.
        latest = state.read_latest() if (motion is not None or not player.started
                                         or player.has_feedforward) else None
        # go-to-init starts from the measured pose, within the limits (the daemon
        # rejects a reference beyond them; an encoder may read a hair past one)
        pos = np.clip(latest["pos"], limits.lower_rad, limits.upper_rad) \
            if not player.started else None
        if player.started:
            while signals.toggles:
                signals.toggles -= 1
                player.toggle_pause(now_s)
        tick = player.step(now_s, pos) if motion is None else motion.step(now_s, latest)
        if motion is not None and motion.stop is not None:
            sample["playing"] = 0  # hold: every verified grip kept, nothing loaded
            ref.write(sample)
            print(f"\nplay-trajectory: the motion layer stopped at line "
                  f"{motion.stop.line} and holds: {motion.stop.reason}",
                  file=sys.stderr, flush=True)
            if motion.stop.cause is FailureCause.LADDER_MISPLACED:
                return _retreat(args, motion, tick, ref, state, limits, signals, keys)
            return 1
        _fill_ref_sample(sample, tick, player, latest, motors, DEFAULT_BATTERY_V)
        ref.write(sample)
        if not args.quiet and (now_s >= next_show or tick.finished):
            next_show = now_s + 0.25
            _show_progress(tick, now_s - t0_s, player.num_lines)
        if tick.finished:
            if not args.quiet:
                print(file=sys.stderr)
            return 0
        deadline += TICK_NS
        now = time.monotonic_ns()
        if now >= deadline:
            deadline += ((now - deadline) // TICK_NS + 1) * TICK_NS
        sleep_until_ns(deadline)
    sample["playing"] = 0  # stop and hold: the last reference stays
    ref.write(sample)
    where = f"line {tick.line_number}" if tick is not None else "the start"
    print(f"\nplay-trajectory: stopped at {where}; the robot holds the last reference",
          file=sys.stderr, flush=True)
    return 130


def _retreat(args, motion, tick, ref, state, limits, signals: _Signals, keys) -> int:
    """After a ``ladder_misplaced`` stop: write the ladder as the hands found it, then
    retrace the plan to its first line with open hands (`execute.motion.retract`), and
    say how to plan again. Returns 1 (the plan was not played), or 130 if a signal
    stopped the way back (holding)."""
    from execute.motion.replan import ReplanSettings
    from execute.motion.retract import retract_lines
    from execute.play.arm_modes import ArmModeSchedule
    from execute.play.player import PlayerOptions, TrajectoryPlayer
    from ladders.loader import dump_ladder
    from robot.plan_sidecar import sidecar_path

    stem = str(sidecar_path(Path(args.file))).removesuffix(".plan.json")
    spec_path = Path(args.measured_ladder or f"{stem}.measured-ladder.yaml")
    try:  # first: the measurement is kept even if the way back is interrupted
        dump_ladder(motion.measured_ladder, spec_path)
        print(f"play-trajectory: wrote the ladder as the hands found it to {spec_path}",
              file=sys.stderr, flush=True)
    except OSError as exc:
        print(f"play-trajectory: could not write {spec_path} ({exc.strerror}); the "
              f"placement is in the message above", file=sys.stderr, flush=True)
    rate = motion.player.options.rate_hz
    lines = retract_lines(motion.trajectory_rad, tick.line_number - 1,
                          motion.last_reference_rad, rate)
    back = TrajectoryPlayer(lines, PlayerOptions(rate_hz=rate),
                            ArmModeSchedule.all_position(len(lines)))
    print(f"play-trajectory: opening the hands and retracing the plan to its first line "
          f"({back.duration_s:.1f} s, position mode)", file=sys.stderr, flush=True)
    code = _stream(args, back, None, ref, state, limits, signals, keys)
    if code != 0:
        return code
    new = f"{stem}.replanned.traj"
    print("play-trajectory: back at the plan's start, weight on the floor. Plan again for "
          f"the measured ladder, then play the new plan:\n  "
          f"{ReplanSettings.of(motion.sidecar).command(str(spec_path), new)}\n  "
          f"play-trajectory -n {new} -i", file=sys.stderr, flush=True)
    return 1


def _fill_ref_sample(sample, tick, player, latest, motors, default_battery_v: float) -> None:
    """A tick's references, modes and compliance into the ``ref`` sample, with the
    feed-forward as PWM duty at the battery voltage the daemon reports (the default
    [V] while it reports none)."""
    sample["ref"] = tick.ref_rad
    sample["mode"] = tick.mode
    sample["comply"] = tick.comply
    if player.has_feedforward:
        volts = float(latest["power"]["V"])
        sample["pwm_command"] = player.feedforward_duty(
            tick, volts if volts > 0 else default_battery_v, motors)
    if tick.finished:
        sample["playing"] = 0


def _show_progress(tick, t_s: float, n: int) -> None:
    """The progress line: line, time since the start [s], the arms' modes, the phase."""
    phase = "done" if tick.finished else "paused" if tick.paused else \
        "init" if tick.going_to_init else "play"
    print(f"\rline {tick.line_number:5d}/{n}  t {t_s:6.2f} s  "
          f"left {tick.arm_modes['left']:8s}  right {tick.arm_modes['right']:8s}"
          f"  {phase:6s}", end="", file=sys.stderr, flush=True)


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``play-trajectory``; returns the exit code."""
    args = _parser().parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(name)s: %(message)s")
    def job() -> int:
        from execute.play.lock import PlayerLock

        traj, player, auto, motion = _load(args)
        with PlayerLock(args.instance):  # one player per daemon; before any channel
            return _play(args, traj, player, auto, motion)

    try:
        return run_cli("play-trajectory", job)
    except KeyboardInterrupt:  # before playback started: nothing was sent
        print("play-trajectory: interrupted before playing", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
