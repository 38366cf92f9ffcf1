"""Motor-board protection: a board trips when one of its joints stays overloaded.

The JMC boards (hubo-facts §4) cut their motors and raise a status flag when a motor sat
at its current limit too long; the daemon then reports the joints inactive until the
board is reset. We model the overload with the joint torque: a joint is *overloaded*
while ``|τ| ≥ saturation_fraction · τ_max``, which in position mode is the board's own
torque saturation and in PWM mode the over-current that produces the same torque
(``τ = η·gear·Kt·I``, so both are one current threshold). A board trips when any of its
joints has been overloaded continuously for ``trip_after_s``.

Why 0.5 s: following a trajectory through the daemon's reference filter (τ ≈ 0.2 s) a
joint saturates for at most a couple of filter time constants on a step, and a stiff arm
pressing on a rigid rail stays saturated indefinitely; 0.5 s separates the two while
staying well inside the motors' thermal time constants (tens of seconds), which is what
the real protection exists for. It is a parameter.

Boards (hubo-facts §4), DRC-Hubo. The wrist roll shares ``EJMC4``/``EJMC5`` with the
fingers of its hand, so overloading a wrist roll drops that hand's grip.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from robot.joints import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS

__all__ = ["BOARDS", "BoardTripConfig", "BoardTripMonitor", "TripEvent", "board_of_joint"]

#: Board name → joints it drives.
BOARDS = MappingProxyType({
    "JMC0": ("RHY", "RHR"), "JMC1": ("RHP",), "JMC2": ("RKN",), "JMC3": ("RAP", "RAR"),
    "JMC4": ("LHY", "LHR"), "JMC5": ("LHP",), "JMC6": ("LKN",), "JMC7": ("LAP", "LAR"),
    "EJMC3": ("WST",),
    "JMC8": ("RSP", "RSR"), "JMC9": ("RSY", "REB"), "JMC10": ("LSP", "LSR"),
    "JMC11": ("LSY", "LEB"),
    "EJMC0": ("RWY", "RWP"), "EJMC1": ("LWY", "LWP"), "EJMC2": ("NKY", "NK1", "NK2"),
    "EJMC4": ("RWR", "RF1", "RF2", "RF3", "RF4", "RF5"),
    "EJMC5": ("LWR", "LF1", "LF2", "LF3", "LF4", "LF5"),
})


def board_of_joint() -> dict[str, str]:
    """Joint name → board name."""
    return {j: b for b, joints in BOARDS.items() for j in joints}


@dataclass(frozen=True)
class BoardTripConfig:
    """Attributes:
        trip_after_s: continuous overload before a board trips [s].
        saturation_fraction: ``|τ|/τ_max`` at or above which a joint counts as
            overloaded [-] (slightly below 1 so a clamped torque counts).
    """

    trip_after_s: float = 0.5
    saturation_fraction: float = 0.99


@dataclass(frozen=True)
class TripEvent:
    """A board tripped at ``time_s`` because ``joint`` was overloaded for ``overload_s``.

    ``peak_torque_nm`` is that joint's largest |τ| since the simulation started;
    ``threshold_nm`` the |τ| it was held at or above (``saturation_fraction`` of
    ``torque_limit_nm``).
    """

    board: str
    joint: str
    time_s: float
    overload_s: float
    torque_limit_nm: float
    peak_torque_nm: float
    threshold_nm: float | None = None

    def __str__(self) -> str:
        limit = self.torque_limit_nm
        held = self.threshold_nm if self.threshold_nm is not None else limit
        of = (f"{held:.3g} N·m ({held / limit:.0%} of its {limit:g} N·m limit)"
              if limit > 0 and held != limit else f"its {limit:g} N·m limit")
        return (f"board {self.board} tripped at t = {self.time_s:.2f} s: {self.joint} held "
                f"|τ| ≥ {of} for {self.overload_s:.2f} s (peak {self.peak_torque_nm:.1f} N·m)")


class BoardTripMonitor:
    """Integrates per-joint overload time and trips boards.

    Args:
        torque_max_nm: per-column torque limit [N·m], shape (40,).
        config: thresholds.
        exempt: bool (40,), joints whose stall is normal operation and never trips
            (default: the fingers, see below).

    Fingers are exempt: a finger closing on a rail stalls against it at its current
    limit, which is how a current-limited grip works; the protection that matters on the
    shared EJMC4/5 board is the wrist roll's.
    """

    def __init__(self, torque_max_nm: np.ndarray, config: BoardTripConfig | None = None,
                 exempt: np.ndarray | None = None):
        self.config = config or BoardTripConfig()
        self.torque_max_nm = np.asarray(torque_max_nm, dtype=float)
        if exempt is None:
            exempt = np.array([n[0] in "RL" and n[1] == "F" for n in JOINT_NAMES])
        self.exempt = np.asarray(exempt, dtype=bool)
        self._board_names = list(BOARDS)
        self._board_of = np.full(NUM_JOINTS, -1)
        for b, joints in enumerate(self._board_names):
            for j in BOARDS[joints]:
                self._board_of[JOINT_INDEX[j]] = b
        # Per-tick thresholds, once (limits, exemptions and config are fixed from here).
        self._overload_nm = self.config.saturation_fraction * self.torque_max_nm
        self._watched = (self.torque_max_nm > 0) & ~self.exempt
        self._trip_s = self.config.trip_after_s - 1e-12
        self.reset()

    def reset(self) -> None:
        """No overload, no board tripped."""
        self.overload_s = np.zeros(NUM_JOINTS)
        self.peak_torque_nm = np.zeros(NUM_JOINTS)
        self.tripped = np.zeros(NUM_JOINTS, dtype=bool)  # per joint: its board is off
        self.events: list[TripEvent] = []

    def update(self, torque_nm: np.ndarray, dt_s: float, time_s: float) -> list[TripEvent]:
        """Accounts ``dt_s`` of the joint torques ``torque_nm`` [N·m]; returns new trips."""
        mag = np.abs(torque_nm)
        np.maximum(self.peak_torque_nm, mag, out=self.peak_torque_nm)
        over = (mag >= self._overload_nm) & self._watched & ~self.tripped
        if not over.any():  # the common step: nothing near its limit
            self.overload_s.fill(0.0)
            return []
        self.overload_s = np.where(over, self.overload_s + dt_s, 0.0)
        new: list[TripEvent] = []
        for j in np.flatnonzero(self.overload_s >= self._trip_s):
            b = self._board_of[j]
            if b < 0 or self.tripped[j]:
                continue
            name = self._board_names[b]
            ev = TripEvent(name, JOINT_NAMES[j], time_s, float(self.overload_s[j]),
                           float(self.torque_max_nm[j]), float(self.peak_torque_nm[j]),
                           float(self._overload_nm[j]))
            new.append(ev)
            for jn in BOARDS[name]:
                self.tripped[JOINT_INDEX[jn]] = True
        self.overload_s[self.tripped] = 0.0
        self.events += new
        return new
