"""PWM (compliance) mode: the per-joint PD duty, its gains and their safety limits.

In PWM mode hubo-ach switched the motor board's position loop off and drove the motor
with an open-loop duty cycle it computed every tick (hubo-facts §3)::

    duty = −(kp·(r − pos) − kd·vel + pwm_command),   clamped to ±max_pwm

Units, as hubo-ach defined them:

- ``kp``: percent duty per radian of error [%/rad];
- ``kd``: percent duty removed per rad/s of joint velocity [%/(rad/s)];
- ``pwm_command``: a constant feed-forward (gravity) duty [%];
- ``max_pwm``: the clamp [%].

The C code multiplied every term by 10 and worked in integer 0.1 % units, the resolution
of the board's high-resolution PWM frame; we compute in percent as floats and
:func:`duty_to_board_units` converts for a CAN backend. The sign is hubo-ach's: a joint
below its reference (``r > pos``) gets a negative duty. A backend (CAN frame direction
bit, MuJoCo motor model) must apply that same motor-direction convention.

``r`` is the reference the daemon sends this tick (after the reference filter of
``daemon.control_modes``): hubo-ach computed the duty from the joint's sent reference, so
a compliant arm in mode FILTER follows the filtered trajectory, and in mode COMPLIANT
(``r = pos``) only damping and feed-forward act.

Safety limits (thesis manual): ``kp < 70``, ``kd < 10``, ``max_pwm < 8``. The original
code checked none of them; here every path that sets gains (CLI, console, channel) goes
through :func:`validate_pwm_gains`, and :class:`PwmGains` cannot hold unsafe values.

The limits and the documented and safe default gain tables are robot data
(`robot.pwm_gains`); the planner reads them too.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from robot.errors import InputError
from robot.joints import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS
from robot.motors import MotorTable, motor_table
from robot.pwm_gains import (
    KD_LIMIT,
    KP_LIMIT,
    MAX_PWM_LIMIT_PCT,
    PWM_COMMAND_LIMIT_PCT,
    safe_default_gain_table,
)

__all__ = [
    "GAIN_LIMITS",
    "GainLimit",
    "PwmGainError",
    "PwmGains",
    "default_drc_gains",
    "duty_to_board_units",
    "feedforward_duty_pct",
    "pwm_duty",
    "validate_pwm_gains",
]


@dataclass(frozen=True)
class GainLimit:
    """Allowed interval of one gain field: ``low <= value`` and ``value < high``.

    ``high_inclusive`` turns the upper bound into ``value <= high``.
    """

    low: float
    high: float
    high_inclusive: bool = False
    unit: str = ""

    def contains(self, values: np.ndarray) -> np.ndarray:
        """Elementwise membership (NaN is never inside)."""
        upper = values <= self.high if self.high_inclusive else values < self.high
        return (values >= self.low) & upper

    def __str__(self) -> str:
        return f"[{self.low:g}, {self.high:g}{']' if self.high_inclusive else ')'} {self.unit}"


#: Allowed range of each field of :class:`PwmGains`, by field name.
GAIN_LIMITS: Mapping[str, GainLimit] = MappingProxyType(
    {
        "kp": GainLimit(0.0, KP_LIMIT, unit="%/rad"),
        "kd": GainLimit(0.0, KD_LIMIT, unit="%/(rad/s)"),
        "max_pwm_pct": GainLimit(0.0, MAX_PWM_LIMIT_PCT, unit="%"),
        "pwm_command_pct": GainLimit(-PWM_COMMAND_LIMIT_PCT, PWM_COMMAND_LIMIT_PCT, True, "%"),
    }
)


class PwmGainError(InputError):
    """PWM gains outside the safety limits; every problem names joint, field, value, range."""

    def __init__(self, problems: list[str]):
        self.problems = problems
        super().__init__(
            "\n".join(problems)
            + "\n(thesis manual safety rules: kp < 70, kd < 10, max_pwm < 8; gains refused)"
        )


def _per_joint(name: str, value: float | np.ndarray, joints: tuple[str, ...]) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        return np.full(len(joints), float(arr))
    if arr.shape != (len(joints),):
        raise PwmGainError([f"{name} has shape {arr.shape}; expected () or ({len(joints)},)"])
    return arr


def validate_pwm_gains(
    kp: float | np.ndarray,
    kd: float | np.ndarray,
    max_pwm_pct: float | np.ndarray,
    pwm_command_pct: float | np.ndarray = 0.0,
    joints: Iterable[str] | None = None,
) -> None:
    """Refuses PWM gains outside the safety limits. Every path that sets gains calls this.

    Limits: ``0 <= kp < 70`` [%/rad], ``0 <= kd < 10`` [%/(rad/s)],
    ``0 <= max_pwm < 8`` [%], ``|pwm_command| <= 100`` [%]; NaN and inf are refused.

    Args:
        kp: proportional gain [%/rad], a scalar or one value per joint.
        kd: damping gain [%/(rad/s)], a scalar or one value per joint.
        max_pwm_pct: duty clamp [%], a scalar or one value per joint.
        pwm_command_pct: feed-forward duty [%], a scalar or one value per joint.
        joints: the joint names the values belong to; all 40 in file order when None.

    Raises:
        PwmGainError: one line per offending joint and field, e.g.
            ``RSP kp = 80 is outside the allowed range [0, 70) %/rad``.
        InputError: an unknown joint name.
    """
    names = JOINT_NAMES if joints is None else tuple(joints)
    unknown = [n for n in names if n not in JOINT_INDEX]
    if unknown:
        raise InputError(f"unknown joint(s) {unknown}; valid names: {' '.join(JOINT_NAMES)}")
    fields = {"kp": kp, "kd": kd, "max_pwm_pct": max_pwm_pct, "pwm_command_pct": pwm_command_pct}
    problems: list[str] = []
    for field, value in fields.items():
        arr = _per_joint(field, value, names)
        limit = GAIN_LIMITS[field]
        for i in np.flatnonzero(~limit.contains(arr)):
            problems.append(f"{names[i]} {field} = {arr[i]:g} is outside the allowed range {limit}")
    if problems:
        raise PwmGainError(problems)


def _frozen(values: float | np.ndarray) -> np.ndarray:
    arr = np.array(np.broadcast_to(np.asarray(values, dtype=float), (NUM_JOINTS,)))
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class PwmGains:
    """PWM gains of all 40 joints, validated on construction (``hubo-pwm-gains``).

    Attributes:
        kp: proportional gain [%/rad], shape (40,).
        kd: damping gain [%/(rad/s)], shape (40,).
        max_pwm_pct: duty clamp [%], shape (40,).
        pwm_command_pct: feed-forward duty [%], shape (40,).
    """

    kp: np.ndarray
    kd: np.ndarray
    max_pwm_pct: np.ndarray
    pwm_command_pct: np.ndarray

    def __post_init__(self) -> None:
        validate_pwm_gains(self.kp, self.kd, self.max_pwm_pct, self.pwm_command_pct)
        for field in ("kp", "kd", "max_pwm_pct", "pwm_command_pct"):
            object.__setattr__(self, field, _frozen(getattr(self, field)))

    @classmethod
    def zeros(cls) -> PwmGains:
        """All gains zero: every compliant joint is limp."""
        return cls(
            np.zeros(NUM_JOINTS), np.zeros(NUM_JOINTS), np.zeros(NUM_JOINTS), np.zeros(NUM_JOINTS)
        )

    @classmethod
    def from_table(cls, table: Mapping[str, tuple[float, float, float]]) -> PwmGains:
        """Gains from ``joint → (kp, kd, max_pwm %)``; unlisted joints get 0/0/0.

        Raises:
            PwmGainError: a value is outside the safety limits.
            InputError: an unknown joint name.
        """
        names = tuple(table)
        values = np.array([table[n] for n in names], dtype=float).reshape(len(names), 3)
        validate_pwm_gains(values[:, 0], values[:, 1], values[:, 2], 0.0, joints=names)
        kp, kd, max_pwm = (np.zeros(NUM_JOINTS) for _ in range(3))
        for name, (p, d, m) in zip(names, values, strict=True):
            j = JOINT_INDEX[name]
            kp[j], kd[j], max_pwm[j] = p, d, m
        return cls(kp, kd, max_pwm, np.zeros(NUM_JOINTS))

    def with_joint(
        self,
        joint: str,
        *,
        kp: float | None = None,
        kd: float | None = None,
        max_pwm_pct: float | None = None,
        pwm_command_pct: float | None = None,
    ) -> PwmGains:
        """A copy with one joint's gains changed (the console / channel path).

        Raises:
            PwmGainError: a new value is outside the safety limits.
            InputError: an unknown joint name.
        """
        if joint not in JOINT_INDEX:
            raise InputError(f"unknown joint {joint!r}; valid names: {' '.join(JOINT_NAMES)}")
        j = JOINT_INDEX[joint]
        new = {}
        for field, value in (
            ("kp", kp),
            ("kd", kd),
            ("max_pwm_pct", max_pwm_pct),
            ("pwm_command_pct", pwm_command_pct),
        ):
            arr = np.array(getattr(self, field))
            if value is not None:
                arr[j] = value
            new[field] = arr
        validate_pwm_gains(
            new["kp"][j],
            new["kd"][j],
            new["max_pwm_pct"][j],
            new["pwm_command_pct"][j],
            joints=(joint,),
        )
        return PwmGains(**new)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, PwmGains):
            return NotImplemented
        return all(
            np.array_equal(getattr(self, f), getattr(other, f))
            for f in ("kp", "kd", "max_pwm_pct", "pwm_command_pct")
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        active = [
            f"{JOINT_NAMES[j]}={self.kp[j]:g}/{self.kd[j]:g}/{self.max_pwm_pct[j]:g}"
            for j in np.flatnonzero((self.kp != 0) | (self.kd != 0) | (self.max_pwm_pct != 0))
        ]
        return f"PwmGains(kp/kd/max_pwm%: {', '.join(active) or 'all zero'})"


def default_drc_gains() -> PwmGains:
    """The safe DRC-Hubo default gains (`robot.pwm_gains.safe_default_gain_table`)."""
    return PwmGains.from_table(safe_default_gain_table())


def feedforward_duty_pct(torque_nm: np.ndarray, battery_v: float,
                         vel_rad_s: np.ndarray | None = None,
                         table: MotorTable | None = None) -> np.ndarray:
    """The feed-forward duty (``pwm_command`` [%]) with which a joint on its reference,
    moving at ``vel_rad_s``, gives ``torque_nm``; within ``±PWM_COMMAND_LIMIT_PCT``.

    On the reference the duty is ``−pwm_command + kd·vel`` and the motor gives
    ``torque_per_duty·duty − b·vel`` (`robot.motors`, b the back-EMF damping), so
    ``pwm_command = −(τ + b·vel) / torque_per_duty`` with kd = 0. Planned velocities are
    fed forward, not measured ones: cancelling the back-EMF with the measured velocity
    would take the arm's damping away.

    Args:
        torque_nm: wanted joint torque [N·m], shape (40,).
        battery_v: bus voltage [V].
        vel_rad_s: planned joint velocity [rad/s], shape (40,); at rest when None.
        table: motor constants; the robot's when None.
    """
    motors = table or motor_table()
    torque = np.asarray(torque_nm, dtype=float)
    if vel_rad_s is not None:
        torque = torque + motors.back_emf_damping * np.asarray(vel_rad_s, dtype=float)
    duty = -torque / motors.torque_per_duty(battery_v)
    return np.clip(duty, -PWM_COMMAND_LIMIT_PCT, PWM_COMMAND_LIMIT_PCT)


def pwm_duty(
    ref_rad: np.ndarray,
    pos_rad: np.ndarray,
    vel_rad_s: np.ndarray,
    gains: PwmGains,
    pwm_command_pct: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The PWM duty of every joint, hubo-ach's formula and sign.

    ``duty = −(kp·(r − pos) − kd·vel + pwm_command)``, clamped to ``±max_pwm``.

    Args:
        ref_rad: reference r the joint should hold [rad], shape (40,).
        pos_rad: measured position [rad], shape (40,).
        vel_rad_s: measured velocity [rad/s], shape (40,).
        gains: validated gains.
        pwm_command_pct: feed-forward duty [%] replacing ``gains.pwm_command_pct``.

    Returns:
        ``(duty_pct, saturated)``: duty [%] in ``[−max_pwm, max_pwm]`` and a bool mask of
        the joints where the clamp acted.
    """
    command = gains.pwm_command_pct if pwm_command_pct is None else pwm_command_pct
    raw = -(gains.kp * (ref_rad - pos_rad) - gains.kd * vel_rad_s + command)
    duty = np.clip(raw, -gains.max_pwm_pct, gains.max_pwm_pct)
    return duty, duty != raw


def duty_to_board_units(duty_pct: np.ndarray) -> np.ndarray:
    """Duty in the motor board's integer 0.1 % units (what hubo-ach put in the CAN frame).

    Args:
        duty_pct: duty [%].

    Returns:
        int32 array, ``round(10·duty)`` [0.1 %].
    """
    return np.rint(np.asarray(duty_pct, dtype=float) * 10.0).astype(np.int32)
