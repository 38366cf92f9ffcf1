"""``hubo-console``: hubo-ach's console, one command per line on stdin.

    hubo-console [--instance NAME] [--robot R] [-c "CMD; CMD; ..."]

Commands (joint ``J`` by name, ``RSP``, or by 0-based index; names are case-insensitive):

==================  ===========================================================
``homeAll``         home every joint (references ignored for 3 s)
``home J``          home one joint
``goto J RAD``      position mode, reference RAD [rad] (filtered), others unchanged;
                    RAD within the joint's limits
``comp J RAD``      compliant (PWM) around RAD [rad], within the joint's limits
``kp J V``          PWM proportional gain [%/rad], ``0 <= V < 70``
``kd J V``          PWM damping gain [%/(rad/s)], ``0 <= V < 10``
``maxPWM J V``      PWM duty clamp [%], ``0 <= V < 8``
``status J``        one joint's state
``statusAll``       every joint's state
``iniSensors``      zero the FT and IMU offsets (robot hanging still)
``reset J``         reset a joint's board (clears a trip)
``quit``            leave
==================  ===========================================================

Gains outside the thesis manual's safety limits, and ``goto``/``comp`` positions outside
the joint's limits (`robot.limits`, of ``--robot``), are refused here with the joint, the
value and the allowed range, and nothing is sent. The daemon refuses them too: it keeps
the gains, and holds a joint's previous reference when a new one is beyond its limits.
Each command waits until the daemon has ticked past it, so consecutive commands are never
lost on the latest-value channel.

Exit codes: 0 every command done, 1 the daemon did not answer, 2 a command was refused
(unknown command or joint, a value out of range).
"""

from __future__ import annotations

import argparse
import functools
import sys
import time

import numpy as np

from robot.errors import HuboLadderError, InputError, parse_finite, run_cli

__all__ = ["Console", "add_daemon_options", "main"]

ACK_TIMEOUT_S = 1.0  # wait at most this for the daemon to tick past a command [s]
_GAIN_COMMANDS = {"kp": ("kp", 0), "kd": ("kd", 1), "maxpwm": ("max_pwm_pct", 2)}


def _joint(token: str) -> int:
    from robot.joints import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS

    name = token.upper()
    if name in JOINT_INDEX:
        return JOINT_INDEX[name]
    if token.isdigit() and int(token) < NUM_JOINTS:
        return int(token)
    raise InputError(f"unknown joint {token!r}; valid: 0..{NUM_JOINTS - 1} or "
                     f"{' '.join(JOINT_NAMES)}")


def format_joint(s: np.ndarray, j: int) -> str:
    """One joint of a state sample as a line."""
    from daemon.structs import StatusFlag
    from robot.joints import JOINT_NAMES

    flags = StatusFlag(int(s["status"][j]))
    names = "|".join(f.name for f in StatusFlag if f and f in flags) or "OK"
    return (f"{JOINT_NAMES[j]:4s} ref {s['ref'][j]:+8.4f}  pos {s['pos'][j]:+8.4f}  "
            f"vel {s['vel'][j]:+7.3f}  cur {s['cur'][j]:6.2f} A  duty {s['duty'][j]:+5.1f} %  "
            f"comply {int(s['comply'][j])}  active {int(s['active'][j])}  "
            f"zeroed {int(s['zeroed'][j])}  {names}")


class Console:
    """The console's commands on one daemon instance (see the module docstring)."""

    def __init__(self, instance: str = "default", out=sys.stdout, err=sys.stderr,
                 robot: str = "drc-hubo"):
        from daemon.channels import open_channel
        from robot.limits import joint_limits

        self.instance = instance
        self.limits = joint_limits(robot)
        self.out, self.err = out, err
        self.cmd = open_channel("board-cmd", instance)
        self.ref = open_channel("ref", instance)
        self.state = open_channel("state", instance)

    def close(self) -> None:
        for c in (self.cmd, self.ref, self.state):
            c.close()

    def state_now(self) -> np.ndarray:
        """The daemon's newest state sample.

        Raises:
            HuboLadderError: no sample, or the newest is over 0.5 s old (no daemon ticks).
        """
        s = self.state.read_latest()
        if s is None or time.monotonic_ns() - int(s["time_ns"]) > 500_000_000:
            raise HuboLadderError(f"no hubo-daemon is ticking on instance {self.instance!r}")
        return s

    def wait_ticks(self, since: np.ndarray, ticks: int = 2) -> None:
        """Wait until the daemon has ticked ``ticks`` times past the state sample ``since``,
        so a command written after ``since`` has been seen (latest-value channels keep only
        the newest sample).

        Raises:
            HuboLadderError: it did not within `ACK_TIMEOUT_S`.
        """
        target = int(since["tick"]) + ticks
        deadline = time.monotonic() + ACK_TIMEOUT_S
        s = since
        while int(s["tick"]) < target:
            left = deadline - time.monotonic()
            if left <= 0:
                raise HuboLadderError("the daemon did not tick past the command in "
                                      f"{ACK_TIMEOUT_S:g} s")
            s = self.state.wait_newer(int(s["time_ns"]), left) or s

    def board_command(self, kind, joint: int = -1, params=(), dvalues=()) -> None:
        """Send one board command and wait until the daemon has seen it."""
        from daemon.structs import BOARD_CMD_DTYPE, new_sample

        before = self.state_now()
        c = new_sample(BOARD_CMD_DTYPE)
        c["type"], c["joint"] = int(kind), joint
        c["params"][: len(params)] = params
        c["dvalues"][: len(dvalues)] = dvalues
        self.cmd.write(c)
        self.wait_ticks(before)

    def reference(self, joint: int, rad: float, comply: bool) -> None:
        """Command one joint to ``rad`` [rad], every other joint where it is."""
        from daemon.control_modes import RefMode
        from daemon.structs import REF_DTYPE, new_sample

        before = self.state_now()
        r = new_sample(REF_DTYPE)
        r["ref"] = before["ref"]
        r["comply"] = before["comply"]
        r["mode"] = RefMode.FILTER
        r["ref"][joint] = rad
        r["comply"][joint] = comply
        r["playing"] = 0
        self.ref.write(r)
        self.wait_ticks(before)

    def execute(self, line: str) -> bool:
        """Run one command line; False on ``quit``.

        Raises:
            InputError: unknown command, joint or a value out of range (nothing sent).
            HuboLadderError: the daemon did not answer.
        """
        from daemon.pwm import GAIN_LIMITS
        from daemon.structs import BoardCommandType as T

        words = line.split("#", 1)[0].split()
        if not words:
            return True
        cmd, rest = words[0].lower(), words[1:]
        need = {"homeall": 0, "home": 1, "goto": 2, "comp": 2, "kp": 2, "kd": 2, "maxpwm": 2,
                "status": 1, "statusall": 0, "inisensors": 0, "reset": 1, "quit": 0,
                "exit": 0, "help": 0}
        if cmd not in need:
            raise InputError(f"unknown command {words[0]!r}; commands: homeAll, home J, "
                             "goto J rad, comp J rad, kp J v, kd J v, maxPWM J v, status J, "
                             "statusAll, iniSensors, reset J, quit")
        if len(rest) != need[cmd]:
            raise InputError(f"{words[0]} takes {need[cmd]} argument(s), got {len(rest)}")
        if cmd in ("quit", "exit"):
            return False
        if cmd == "help":
            print(__doc__.split("\n\n")[2], file=self.out)
        elif cmd == "homeall":
            self.board_command(T.HOME_ALL)
            print("homing every joint (references ignored for 3 s)", file=self.out)
        elif cmd == "home":
            j = _joint(rest[0])
            self.board_command(T.HOME, j)
        elif cmd in ("goto", "comp"):
            from robot.joints import JOINT_NAMES
            from robot.limits import LIMIT_TOLERANCE_RAD

            j = _joint(rest[0])
            rad = parse_finite(rest[1], f"{words[0]} {JOINT_NAMES[j]}: position")
            lo, hi = float(self.limits.lower_rad[j]), float(self.limits.upper_rad[j])
            if not lo - LIMIT_TOLERANCE_RAD <= rad <= hi + LIMIT_TOLERANCE_RAD:
                raise InputError(f"{words[0]} {JOINT_NAMES[j]} {rad:g} refused: "
                                 f"{JOINT_NAMES[j]} is allowed [{lo:.4g}, {hi:.4g}] rad on "
                                 f"{self.limits.robot}; nothing sent")
            self.reference(j, min(max(rad, lo), hi), cmd == "comp")
        elif cmd in _GAIN_COMMANDS:
            from robot.joints import JOINT_NAMES

            j = _joint(rest[0])
            field, bit = _GAIN_COMMANDS[cmd]
            v = parse_finite(rest[1], words[0])
            limit = GAIN_LIMITS[field]
            if not limit.contains(np.array([v]))[0]:
                raise InputError(f"{words[0]} {v:g} for {JOINT_NAMES[j]} refused: allowed "
                                 f"{limit} (thesis manual: kp < 70, kd < 10, max_pwm < 8)")
            dvalues = [0.0, 0.0, 0.0]
            dvalues[bit] = v
            self.board_command(T.SET_GAINS, j, params=[1 << bit], dvalues=dvalues)
        elif cmd == "status":
            print(format_joint(self.state_now(), _joint(rest[0])), file=self.out)
        elif cmd == "statusall":
            s = self.state_now()
            print(f"tick {int(s['tick'])}  overruns {int(s['overruns'])}  "
                  f"refs rejected {int(s['refs_rejected'])}  "
                  f"t {float(s['time_s']):.2f} s", file=self.out)
            for j in range(len(s["ref"])):
                print(format_joint(s, j), file=self.out)
        elif cmd == "inisensors":
            self.board_command(T.INIT_SENSORS)
        elif cmd == "reset":
            self.board_command(T.RESET, _joint(rest[0]))
        return True


def add_daemon_options(p: argparse.ArgumentParser, limited: str) -> None:
    """Add the options every `Console` user takes: ``--instance`` (the daemon's channel
    namespace) and ``--robot`` (whose joint limits the commands named ``limited``
    respect)."""
    p.add_argument("--instance", default="default", help="daemon instance (default)")
    p.add_argument("--robot", default="drc-hubo", choices=("drc-hubo", "hubo2plus"),
                   help=f"robot whose joint limits {limited} respect (default drc-hubo)")


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``hubo-console``; returns the exit code."""
    p = argparse.ArgumentParser(prog="hubo-console", description=__doc__.split("\n\n")[0])
    add_daemon_options(p, "goto and comp")
    p.add_argument("-c", dest="commands", metavar="CMDS",
                   help="run these ';'-separated commands instead of reading stdin")
    args = p.parse_args(argv)
    return run_cli("hubo-console", lambda: _run(args))


def _run(args: argparse.Namespace) -> int:
    """Run the commands of ``-c`` or stdin until ``quit`` or the end, each through
    `run_cli`: a refused command is reported and the next one runs. Returns the worst
    command's exit code (2 refused, 1 the daemon did not answer)."""
    lines = args.commands.split(";") if args.commands is not None else None
    console = Console(args.instance, robot=args.robot)
    code = 0
    quit_ = False

    def command(line: str) -> int:
        nonlocal quit_
        quit_ = not console.execute(line)
        return 0

    tty = lines is None and sys.stdin.isatty()
    try:
        source = lines if lines is not None else sys.stdin
        if tty:
            print("hubo-console: type help for the commands", file=sys.stderr)
        while not quit_:
            if tty:
                print("hubo> ", end="", file=sys.stderr, flush=True)
            line = next(iter(source), None) if lines is None else (
                lines.pop(0) if lines else None)
            if line is None:
                break
            code = max(code, run_cli("hubo-console", functools.partial(command, line)))
    except KeyboardInterrupt:
        pass
    finally:
        console.close()
    return code


if __name__ == "__main__":
    sys.exit(main())
