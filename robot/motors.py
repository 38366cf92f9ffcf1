"""The DC-motor model of a Hubo joint: duty cycle → joint torque, and torque → current.

The JMC motor boards drive brushed DC motors through an H-bridge from the battery bus.
In PWM (compliance) mode the daemon sends a duty cycle ``d`` [%]; the motor sees the
mean voltage ``V·d/100``, its current obeys ``V·d/100 = R·I + Ke·ω_motor`` (inductance
neglected: L/R ≈ 0.3 ms ≪ the 5 ms tick) and the joint torque is ``η·gear·Kt·I``.

Sign: hubo-ach's convention (``daemon.pwm``): a *positive* duty drives the joint towards
*negative* angles (a joint below its reference gets a negative duty). With
``ω_motor = −gear·ω`` this gives, per joint::

    τ = −η·gear·Kt·(V·d/100 + Ke·gear·ω) / R            [N·m]

i.e. a torque proportional to duty and battery voltage, plus a back-EMF damping
``η·gear²·Kt·Ke/R`` [N·m·s/rad] (``Ke = Kt`` in SI units).

Motor constants, per joint group. The JMCs drive Maxon brushed motors; the figures are
class-representative catalogue magnitudes of Maxon RE-series 48 V windings (not measured
on a Hubo; every one is a parameter). Gear ratios come from the hubo-ach ``joint.table``
examples (hubo-facts §3: drive/driven pulley × harmonic drive); where no example exists
the ratio is assumed from the joint's torque limit (noted "assumed").

============================  =================  ========  =====  ======  ======
joints                        motor class        Kt N·m/A  R Ω    gear    source of gear
============================  =================  ========  =====  ======  ======
hip pitch, knee               RE 40 150 W 48 V   0.0603    1.16   307.7   RKN 25/13·160
hip roll                      RE 40 150 W 48 V   0.0603    1.16   505.7   RHR 1024/324·160
hip yaw, ankle pitch/roll     RE 40 150 W 48 V   0.0603    1.16   320     assumed 2·160
waist                         RE 40 150 W 48 V   0.0603    1.16   250     assumed as SP
shoulder pitch/roll/yaw       RE 35 90 W 48 V    0.060     2.8    250     LSP 25/10·100
elbow                         RE 35 90 W 48 V    0.060     2.8    200     LEB 20/10·100
wrist yaw/pitch/roll          RE 25 20 W 48 V    0.047     9.3    200     wrist roll 2/1·100
fingers                       RE 13 class 48 V   0.0135    30.0   256     assumed
neck                          RE 13 class 48 V   0.0135    30.0   100     assumed
============================  =================  ========  =====  ======  ======

Gear efficiency ``η = 0.7``: harmonic drives run at 70–80 % at rated load, lower at light
load; the pulley stage costs a few percent more.

What it implies for the DRC default PWM gains (battery 48 V), as a sanity check: a
shoulder at its 7.9 % duty clamp stalls at ``0.7·250·0.060·(3.79 V/2.8 Ω) ≈ 14 N·m``
(half its 27 N·m limit) and runs free at ``3.79/(0.060·250) ≈ 0.25 rad/s``; its PD
stiffness is ``kp·V/100/R·η·gear·Kt ≈ 124 N·m/rad`` against the position loop's
1350 N·m/rad (``robot.mjcf.position_gains``). PWM mode is soft and slow: it cannot
overload a joint, and it tracks an order of magnitude worse (thesis §4.3.4).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robot.joints import JOINT_NAMES, NUM_JOINTS

__all__ = [
    "DEFAULT_BATTERY_V",
    "GEAR_EFFICIENCY",
    "MOTOR_CLASSES",
    "MotorClass",
    "MotorTable",
    "battery_power",
    "motor_table",
    "pwm_torque",
]

DEFAULT_BATTERY_V = 48.0  # [V] DRC-Hubo battery bus
GEAR_EFFICIENCY = 0.7  # [-] harmonic drive + pulley, motor → joint


@dataclass(frozen=True)
class MotorClass:
    """One motor type: torque constant [N·m/A] (= back-EMF constant [V·s/rad]) and
    terminal resistance [Ω]."""

    name: str
    kt_nm_per_a: float
    resistance_ohm: float


MOTOR_CLASSES = {
    "RE40": MotorClass("Maxon RE 40 150 W 48 V", 0.0603, 1.16),
    "RE35": MotorClass("Maxon RE 35 90 W 48 V", 0.060, 2.8),
    "RE25": MotorClass("Maxon RE 25 20 W 48 V", 0.047, 9.3),
    "RE13": MotorClass("Maxon RE 13 class 48 V", 0.0135, 30.0),
}

#: joint suffix (or full name) → (motor class, gear ratio motor:joint)
_BY_SUFFIX = {
    "HP": ("RE40", 307.7), "KN": ("RE40", 307.7), "HR": ("RE40", 505.7),
    "HY": ("RE40", 320.0), "AP": ("RE40", 320.0), "AR": ("RE40", 320.0),
    "SP": ("RE35", 250.0), "SR": ("RE35", 250.0), "SY": ("RE35", 250.0),
    "EB": ("RE35", 200.0), "WY": ("RE25", 200.0), "WP": ("RE25", 200.0),
    "WR": ("RE25", 200.0),
}


def _motor_of(name: str) -> tuple[str, float]:
    if name == "WST":
        return "RE40", 250.0
    if name.startswith("NK"):
        return "RE13", 100.0
    if name[1] == "F":
        return "RE13", 256.0
    return _BY_SUFFIX[name[1:]]


@dataclass(frozen=True, eq=False)
class MotorTable:
    """Per-joint motor constants in trajectory-column order, arrays of shape (40,).

    Attributes:
        kt_nm_per_a: torque constant Kt = back-EMF constant Ke [N·m/A] = [V·s/rad].
        resistance_ohm: terminal resistance R [Ω].
        gear: reduction motor:joint [-].
        efficiency: gear efficiency η [-].
    """

    kt_nm_per_a: np.ndarray
    resistance_ohm: np.ndarray
    gear: np.ndarray
    efficiency: np.ndarray

    def torque_per_duty(self, battery_v: float) -> np.ndarray:
        """Stall torque per percent of duty [N·m/%], hubo-ach sign (negative)."""
        return -self.efficiency * self.gear * self.kt_nm_per_a * battery_v / (
            100.0 * self.resistance_ohm)

    @property
    def back_emf_damping(self) -> np.ndarray:
        """Back-EMF damping η·gear²·Kt·Ke/R [N·m·s/rad] (positive)."""
        return self.efficiency * self.gear**2 * self.kt_nm_per_a**2 / self.resistance_ohm

    def current_a(self, torque_nm: np.ndarray) -> np.ndarray:
        """Motor current that produces a joint torque [A] (signed like the torque)."""
        return torque_nm / (self.efficiency * self.gear * self.kt_nm_per_a)

    def torque_nm(self, current_a: np.ndarray) -> np.ndarray:
        """Joint torque a motor current produces [N·m] (`current_a`'s inverse): how hard a
        joint pushes, from the current its board senses."""
        return current_a * (self.efficiency * self.gear * self.kt_nm_per_a)


def motor_table() -> MotorTable:
    """The motor constants of every column (see the module docstring's table)."""
    kt, r, gear = (np.zeros(NUM_JOINTS) for _ in range(3))
    for j, name in enumerate(JOINT_NAMES):
        cls, g = _motor_of(name)
        kt[j] = MOTOR_CLASSES[cls].kt_nm_per_a
        r[j] = MOTOR_CLASSES[cls].resistance_ohm
        gear[j] = g
    eff = np.full(NUM_JOINTS, GEAR_EFFICIENCY)
    for a in (kt, r, gear, eff):
        a.setflags(write=False)
    return MotorTable(kt, r, gear, eff)


def pwm_torque(duty_pct: np.ndarray, vel_rad_s: np.ndarray, battery_v: float,
               table: MotorTable) -> np.ndarray:
    """Joint torque of a motor driven at ``duty_pct`` [N·m] (module docstring formula).

    Args:
        duty_pct: duty [%], hubo-ach sign, shape (40,).
        vel_rad_s: joint velocity [rad/s], shape (40,).
        battery_v: bus voltage [V].
        table: motor constants.
    """
    return table.torque_per_duty(battery_v) * duty_pct - table.back_emf_damping * vel_rad_s


def battery_power(torque_nm: np.ndarray, vel_rad_s: np.ndarray, battery_v: float,
                  table: MotorTable) -> tuple[float, float]:
    """Battery current [A] and power [W] drawn by the motors.

    Each motor's electrical power is ``I·(R·I + Ke·ω_motor)`` with ``I`` the current that
    makes its torque; regeneration is not returned to the battery (the H-bridges of the
    time dumped it), so negative powers count as 0. Electronics are not modelled.
    """
    current = table.current_a(torque_nm)
    emf = table.kt_nm_per_a * table.gear * vel_rad_s
    power = np.maximum(current * (table.resistance_ohm * current + emf), 0.0)
    p_w = float(power.sum())
    return p_w / battery_v, p_w
