"""Reference modes and the per-tick reference filter of the daemon (hubo-facts §3).

Every 5 ms tick the daemon turns the commanded reference ``r`` on ``hubo-ref`` into the
reference it sends to the motor boards, ``f``, per joint and by the joint's mode:

====  ==================  =====================================
mode  name                sent reference
====  ==================  =====================================
0     ``FILTER``          ``f = (f·(L−1) + r) / L``, L = 40
1     ``DIRECT``          ``f = r``
2     ``COMPLIANT``       ``f = pos``
3     ``ENCODER_FILTER``  ``f = (pos·(L−1) + r) / L``
====  ==================  =====================================

The "filter" is exponential, not linear (the thesis calls it linear): after n ticks the
remaining error is ``(1 − 1/L)^n``, τ ≈ L·5 ms ≈ 0.2 s, 95 % reached after 119 ticks
(≈ 0.6 s); see :func:`ticks_to_settle`.

Leaving compliance (PWM back to rigid), the daemon starts from the measured position and
filters with ``L = 400`` (≈ 2 s) while ``|f − r| > 0.0075 rad``, then hands the joint back
to its mode (:func:`rigid_return_step`; the per-joint state machine lives in
``daemon.joint_control``).

Everything here is pure numpy on arrays of shape (40,): no I/O, no clock, no state. The
same functions run in the lock-step validator, the real-time sim daemon and the CAN
daemon.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from robot.constants import DAEMON_RATE_HZ, TICK_S  # re-exported: the daemon's rate
from robot.errors import InputError
from robot.joints import JOINT_NAMES, NUM_JOINTS

__all__ = [
    "DAEMON_RATE_HZ",
    "TICK_S",
    "RefMode",
    "ReferenceFilterConfig",
    "ReferenceModeError",
    "clamp_reference",
    "default_filter_config",
    "filter_reference",
    "rigid_return_step",
    "ticks_to_settle",
    "validate_modes",
]

class RefMode(IntEnum):
    """Reference mode of one joint, as on the ``hubo-ref`` channel (hubo-ach numbering)."""

    FILTER = 0  #: exponential filter towards the commanded reference
    DIRECT = 1  #: the commanded reference is sent unchanged (``-nf``)
    COMPLIANT = 2  #: the sent reference follows the encoder
    ENCODER_FILTER = 3  #: filter from the encoder position towards the reference


#: The mode values, for membership tests on mode arrays.
_MODE_VALUES = np.array([m.value for m in RefMode])


class ReferenceModeError(InputError):
    """A reference mode outside 0..3 (or a malformed mode array) reached the control law."""


@dataclass(frozen=True)
class ReferenceFilterConfig:
    """Tunables of the reference filter and of the rigid return.

    Attributes:
        filter_length: L of modes FILTER and ENCODER_FILTER [ticks] (hubo-ach: 40).
        rigid_return_filter_length: L while returning from compliance [ticks]
            (hubo-ach: 10 × 40 = 400, ≈ 2 s).
        rigid_return_tolerance_rad: the return ends once ``|f − r|`` is at most this [rad]
            (hubo-ach: 0.0075).
    """

    filter_length: int = 40
    rigid_return_filter_length: int = 400
    rigid_return_tolerance_rad: float = 0.0075

    def __post_init__(self) -> None:
        for name in ("filter_length", "rigid_return_filter_length"):
            value = getattr(self, name)
            if not isinstance(value, int | np.integer) or value < 1:
                raise InputError(f"{name} = {value!r}: must be an integer >= 1 [ticks]")
        tol = self.rigid_return_tolerance_rad
        if not (math.isfinite(tol) and tol > 0.0):
            raise InputError(f"rigid_return_tolerance_rad = {tol!r}: must be > 0 [rad]")


def default_filter_config() -> ReferenceFilterConfig:
    """The hubo-ach values: L = 40, L = 400 on the rigid return, 0.0075 rad tolerance."""
    return ReferenceFilterConfig()


def validate_modes(mode: int | np.ndarray) -> np.ndarray:
    """Checks reference modes and broadcasts them to one per joint.

    Args:
        mode: one mode for every joint, or an array of shape (40,).

    Returns:
        An int8 array of shape (40,).

    Raises:
        ReferenceModeError: a value is not one of 0..3, or the shape is wrong; the
            message names the joint.
    """
    arr = np.asarray(mode)
    if arr.ndim == 0:
        arr = np.full(NUM_JOINTS, arr)
    if arr.shape != (NUM_JOINTS,):
        raise ReferenceModeError(f"mode has shape {arr.shape}; expected () or ({NUM_JOINTS},)")
    valid = (arr[:, None] == _MODE_VALUES).any(axis=1)  # np.isin's test, without its setup
    if not valid.all():
        bad = [f"{JOINT_NAMES[i]}={arr[i].item()!r}" for i in np.flatnonzero(~valid)]
        raise ReferenceModeError(
            f"reference mode out of range for {', '.join(bad)}; allowed: "
            + ", ".join(f"{m.value} ({m.name})" for m in RefMode)
        )
    return arr.astype(np.int8)


def filter_reference(
    mode: np.ndarray,
    ref_rad: np.ndarray,
    prev_sent_rad: np.ndarray,
    pos_rad: np.ndarray,
    filter_length: int = 40,
) -> np.ndarray:
    """One tick of the per-joint reference filter (hubo-ach ``refFilterMode``).

    Args:
        mode: reference mode per joint, values of :class:`RefMode`, shape (40,).
        ref_rad: commanded reference r [rad], shape (40,).
        prev_sent_rad: reference sent on the previous tick f [rad], shape (40,).
        pos_rad: measured joint position [rad], shape (40,).
        filter_length: L [ticks].

    Returns:
        The reference to send this tick [rad], shape (40,).
    """
    keep = (filter_length - 1.0) / filter_length
    gain = 1.0 / filter_length
    # Chained np.where rather than np.select (a quarter of the time per tick); plain ints
    # (`.value`) spare numpy the enum class's attribute lookups. Any value outside
    # FILTER, DIRECT, COMPLIANT gets ENCODER_FILTER.
    sent = np.where(mode == RefMode.COMPLIANT.value, pos_rad, pos_rad * keep + ref_rad * gain)
    sent = np.where(mode == RefMode.DIRECT.value, ref_rad, sent)
    return np.where(mode == RefMode.FILTER.value, prev_sent_rad * keep + ref_rad * gain, sent)


def rigid_return_step(
    prev_sent_rad: np.ndarray,
    ref_rad: np.ndarray,
    config: ReferenceFilterConfig | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """One tick of the slow return from compliance to rigid.

    While ``|f − r| > tolerance`` the sent reference is filtered with the long filter
    (L = 400); a joint already within tolerance is done and keeps ``f`` (the caller then
    hands it back to its reference mode on this same tick, as hubo-ach did).

    Args:
        prev_sent_rad: reference sent on the previous tick [rad], shape (40,).
        ref_rad: commanded reference [rad], shape (40,).
        config: filter tunables; hubo-ach values when None.

    Returns:
        ``(sent_rad, done)``: the reference to send [rad] and a bool mask of the joints
        whose return has ended.
    """
    cfg = config or default_filter_config()
    length = cfg.rigid_return_filter_length
    done = np.abs(prev_sent_rad - ref_rad) <= cfg.rigid_return_tolerance_rad
    stepped = (prev_sent_rad * (length - 1.0) + ref_rad) / length
    return np.where(done, prev_sent_rad, stepped), done


def clamp_reference(
    ref_rad: np.ndarray, lower_rad: np.ndarray, upper_rad: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Clamps a reference into the joint limits of the robot description.

    Args:
        ref_rad: reference [rad], shape (40,).
        lower_rad: lower position limit [rad], shape (40,).
        upper_rad: upper position limit [rad], shape (40,).

    Returns:
        ``(clamped_rad, was_clamped)``: the clamped reference and a bool mask of the
        joints that were outside their limits.
    """
    clamped = np.clip(ref_rad, lower_rad, upper_rad)
    return clamped, clamped != ref_rad


def ticks_to_settle(fraction: float = 0.95, filter_length: int = 40) -> int:
    """Ticks the exponential filter needs to cover ``fraction`` of a step.

    Solves ``1 − (1 − 1/L)^n ≥ fraction`` for the smallest integer n.

    Args:
        fraction: share of the step to cover, in (0, 1).
        filter_length: L [ticks].

    Returns:
        n [ticks]; multiply by :data:`TICK_S` for seconds (L = 40, 95 %: 119 ticks, 0.595 s).
    """
    if not 0.0 < fraction < 1.0:
        raise InputError(f"fraction = {fraction!r}: must be in (0, 1)")
    if filter_length == 1:
        return 1
    return math.ceil(math.log(1.0 - fraction) / math.log(1.0 - 1.0 / filter_length) - 1e-12)
