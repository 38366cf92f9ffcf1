"""The per-joint control law of the daemon, vectorised over the 40 joints.

:class:`JointController` is what the daemon runs every 5 ms tick, in all three places
(lock-step validator, real-time sim daemon, CAN daemon). It owns the only state of the
control law, per joint:

- the reference sent on the previous tick (the filter state);
- the compliance state: ``RIGID`` (board in position mode), ``COMPLIANT`` (board in
  PWM mode) or ``RETURNING`` (back in position mode, slowly filtering towards the
  commanded reference, hubo-facts §3).

One tick, per joint, as hubo-ach did it:

1. A commanded reference outside the joint limits of the robot description (by more than
   `robot.limits.REF_CLAMP_TOLERANCE_RAD`, 1 mrad) is rejected: that joint keeps its previous
   accepted reference, and :attr:`ControlOutput.limit_rejected` names it. hubo-ach
   clamped it instead, which moved the joint to its limit: a ``goto RKN 3.0`` drove the
   knee to 2.61 rad, and the simulated robot fell. Values within the tolerance (the
   float noise of computed references) are clamped.
2. The sent reference ``f`` is filtered by the joint's reference mode
   (``daemon.control_modes``).
3. Compliance:

   - ``comply`` set and the joint can comply: the board runs PWM, with the duty of
     ``daemon.pwm`` computed from ``f`` (so a compliant joint in mode FILTER follows the
     filtered reference; in mode COMPLIANT ``f = pos`` and only damping and feed-forward
     act). A joint whose gains are all zero gets duty 0: it is limp, as on the robot.
   - ``comply`` cleared on a compliant joint: on that tick ``f = pos`` and the board goes
     back to position mode; from the next tick, while ``|f − r| > 0.0075 rad``,
     ``f = (f·399 + r)/400``; once within tolerance the joint is rigid again and its
     mode's filter takes over on that same tick.

4. The sent reference is clamped into the joint limits again (modes COMPLIANT and
   ENCODER_FILTER follow the encoder, which may be outside them).

Capability: the original daemon put a joint in PWM mode only on 1- and 2-channel boards.
The wrist roll shares a 3-channel board with two fingers, so it could not comply; the
fingers (5-channel board) could not either. :func:`default_compliance_capable` models
that, and a joint asked to comply without the capability stays in position mode and is
flagged in :attr:`ControlOutput.comply_unsupported`.

Not modelled here (daemon or backend concerns): homing / "zeroed" gating of the switch to
PWM, and hubo-ach's rule that both joints of a 2-channel board must be commanded rigid
before that board leaves PWM mode.

No I/O, no clock, numpy only.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

import numpy as np

from daemon.control_modes import (
    ReferenceFilterConfig,
    clamp_reference,
    default_filter_config,
    filter_reference,
    rigid_return_step,
    validate_modes,
)
from daemon.pwm import PwmGains, pwm_duty
from robot.errors import InputError
from robot.joints import ARM_JOINTS, FINGER_JOINTS, JOINT_INDEX, JOINT_NAMES, NUM_JOINTS
from robot.limits import REF_CLAMP_TOLERANCE_RAD, JointLimits, joint_limits
from robot.pwm_gains import PWM_COMMAND_LIMIT_PCT

__all__ = [
    "ComplianceState",
    "ControlInputError",
    "ControlOutput",
    "JointController",
    "default_compliance_capable",
]


class ComplianceState(IntEnum):
    """Per-joint compliance state of the controller."""

    RIGID = 0  #: position mode, reference by the joint's mode
    COMPLIANT = 1  #: PWM mode
    RETURNING = 2  #: position mode, slow return towards the reference (L = 400)


#: The states as plain ints for the per-tick array operations: given an enum member,
#: numpy looks attributes up on its class, which costs more than the operation.
_RIGID = ComplianceState.RIGID.value
_COMPLIANT = ComplianceState.COMPLIANT.value
_RETURNING = ComplianceState.RETURNING.value


class ControlInputError(InputError):
    """A tick input has the wrong shape or a non-finite value; names the joints."""


def default_compliance_capable() -> np.ndarray:
    """Which joints the original daemon could put in PWM mode, shape (40,) bool.

    False for both wrist rolls (3-channel board shared with fingers) and the fingers
    (5-channel board); True everywhere else.
    """
    capable = np.ones(NUM_JOINTS, dtype=bool)
    for side in ("right", "left"):
        capable[JOINT_INDEX[ARM_JOINTS[side][5]]] = False  # RWR / LWR
        for name in FINGER_JOINTS[side]:
            capable[JOINT_INDEX[name]] = False
    capable.setflags(write=False)
    return capable


@dataclass(frozen=True, eq=False)
class ControlOutput:
    """What one tick of the control law sends to the boards, plus per-joint flags.

    All arrays have shape (40,).

    Attributes:
        ref_sent_rad: position reference [rad] for joints in position mode; for PWM
            joints, the reference their duty was computed from (also what ``hubo-state``
            reports as ``ref``).
        duty_pct: PWM duty [%] for PWM joints (hubo-ach sign); 0 elsewhere.
        pwm: the board drives this joint in PWM mode this tick.
        returning: rigid return in progress (position mode, L = 400).
        limp: PWM joint whose gains are all zero, or whose max_pwm is 0.
        duty_saturated: the ±max_pwm clamp acted.
        limit_rejected: the commanded reference was outside the joint limits; the joint
            kept its previous accepted reference.
        limit_clamped: the sent reference was outside the joint limits and was clamped
            (encoder-following modes, float slack of the commanded reference).
        comply_unsupported: comply requested on a joint that cannot comply.
        state: :class:`ComplianceState` per joint after this tick (int8).
    """

    ref_sent_rad: np.ndarray
    duty_pct: np.ndarray
    pwm: np.ndarray
    returning: np.ndarray
    limp: np.ndarray
    duty_saturated: np.ndarray
    limit_clamped: np.ndarray
    comply_unsupported: np.ndarray
    state: np.ndarray
    limit_rejected: np.ndarray = field(default_factory=lambda: np.zeros(NUM_JOINTS, bool))

    def __repr__(self) -> str:
        def names(mask: np.ndarray) -> str:
            return ",".join(JOINT_NAMES[i] for i in np.flatnonzero(mask)) or "-"

        return (
            f"ControlOutput(pwm={names(self.pwm)} returning={names(self.returning)} "
            f"limp={names(self.limp)} saturated={names(self.duty_saturated)} "
            f"clamped={names(self.limit_clamped)} "
            f"rejected={names(self.limit_rejected)})"
        )


def _vector(name: str, value: np.ndarray, dtype: type = float) -> np.ndarray:
    arr = np.asarray(value, dtype=dtype)
    if arr.shape != (NUM_JOINTS,):
        raise ControlInputError(f"{name} has shape {arr.shape}; expected ({NUM_JOINTS},)")
    if dtype is float and not np.isfinite(arr).all():
        bad = ", ".join(JOINT_NAMES[i] for i in np.flatnonzero(~np.isfinite(arr)))
        raise ControlInputError(f"{name} is not finite for {bad}")
    return arr


class JointController:
    """Stateful per-joint control law of the 200 Hz daemon (see the module docstring).

    Args:
        limits: joint limits; those of ``robot`` when None.
        robot: robot name for the limits when ``limits`` is None.
        config: reference-filter tunables; hubo-ach values when None.
        compliance_capable: bool (40,) of joints that can switch to PWM;
            :func:`default_compliance_capable` when None.
    """

    def __init__(
        self,
        limits: JointLimits | None = None,
        robot: str = "drc-hubo",
        config: ReferenceFilterConfig | None = None,
        compliance_capable: np.ndarray | None = None,
    ):
        self.limits = limits if limits is not None else joint_limits(robot)
        self.config = config or default_filter_config()
        capable = (
            default_compliance_capable()
            if compliance_capable is None
            else _vector("compliance_capable", compliance_capable, bool)
        )
        self.compliance_capable = np.array(capable, dtype=bool)
        self.compliance_capable.setflags(write=False)
        self._sent_rad: np.ndarray | None = None
        self._ref_rad: np.ndarray | None = None  # last accepted commanded reference
        self._state = np.zeros(NUM_JOINTS, dtype=np.int8)

    def reset(self, pos_rad: np.ndarray) -> None:
        """Starts over: every joint rigid, filter state at the measured position.

        Args:
            pos_rad: measured joint positions [rad], shape (40,).
        """
        pos = _vector("pos_rad", pos_rad)
        self._sent_rad = clamp_reference(pos, self.limits.lower_rad, self.limits.upper_rad)[0]
        self._ref_rad = self._sent_rad.copy()
        self._state[:] = ComplianceState.RIGID

    @property
    def state(self) -> np.ndarray:
        """:class:`ComplianceState` per joint, shape (40,) int8 (a copy)."""
        return self._state.copy()

    @property
    def ref_sent_rad(self) -> np.ndarray | None:
        """Reference sent on the last tick [rad] (a copy), None before the first tick."""
        return None if self._sent_rad is None else self._sent_rad.copy()

    def tick(
        self,
        ref_rad: np.ndarray,
        mode: int | np.ndarray,
        comply_mask: np.ndarray,
        pos_rad: np.ndarray,
        vel_rad_s: np.ndarray,
        gains: PwmGains,
        feedforward_pct: np.ndarray | None = None,
    ) -> ControlOutput:
        """Runs one 5 ms tick of the control law.

        Args:
            ref_rad: commanded reference r [rad], shape (40,).
            mode: :class:`~daemon.control_modes.RefMode` per joint (or one for all).
            comply_mask: bool (40,): joints asked to be compliant (PWM).
            pos_rad: measured position [rad], shape (40,).
            vel_rad_s: measured velocity [rad/s], shape (40,).
            gains: validated PWM gains.
            feedforward_pct: the player's feed-forward duty for this tick [%], shape
                (40,), within ``±PWM_COMMAND_LIMIT_PCT``, added to the gains' constant
                ``pwm_command_pct`` (the sum is clipped to that limit too).

        Returns:
            The references, duties and flags to send this tick.

        Raises:
            ControlInputError: a wrong shape or a non-finite value (nothing is changed).
            ReferenceModeError: a mode outside 0..3.
        """
        ref_in = _vector("ref_rad", ref_rad)
        modes = validate_modes(mode)
        comply = _vector("comply_mask", comply_mask, bool)
        pos = _vector("pos_rad", pos_rad)
        vel = _vector("vel_rad_s", vel_rad_s)
        command = _pwm_command(gains, feedforward_pct)
        if self._sent_rad is None:
            self.reset(pos)
        ref, rejected, ref_clamped = self._accept_reference(ref_in)
        state = self._state

        want_pwm = comply & self.compliance_capable
        leaving = (state == _COMPLIANT) & ~want_pwm
        returning = (state == _RETURNING) & ~want_pwm
        sent, sent_clamped, still_returning = self._sent_reference(modes, ref, pos, leaving,
                                                                   returning)

        duty, saturated = pwm_duty(sent, pos, vel, gains, command)
        duty = np.where(want_pwm, duty, 0.0)
        saturated &= want_pwm
        limp = want_pwm & (((gains.kp == 0) & (gains.kd == 0)) | (gains.max_pwm_pct == 0))

        new_state = np.full(NUM_JOINTS, _RIGID, dtype=np.int8)
        new_state[want_pwm] = _COMPLIANT
        new_state[leaving | still_returning] = _RETURNING

        self._sent_rad = sent
        self._state = new_state
        return ControlOutput(
            ref_sent_rad=sent.copy(),
            duty_pct=duty,
            pwm=want_pwm.copy(),
            returning=new_state == _RETURNING,
            limp=limp,
            duty_saturated=saturated,
            limit_clamped=ref_clamped | sent_clamped,
            comply_unsupported=comply & ~self.compliance_capable,
            state=new_state.copy(),
            limit_rejected=rejected,
        )

    def _accept_reference(self, ref_in: np.ndarray
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Step 1: a commanded reference beyond a joint limit by more than the tolerance
        keeps that joint's previous accepted reference; one within it is clamped.

        Returns:
            The accepted reference [rad] (kept for the next tick), the rejected joints and
            the clamped ones.
        """
        lower, upper = self.limits.lower_rad, self.limits.upper_rad
        rejected = ((ref_in < lower - REF_CLAMP_TOLERANCE_RAD)
                    | (ref_in > upper + REF_CLAMP_TOLERANCE_RAD))
        ref, ref_clamped = clamp_reference(np.where(rejected, self._ref_rad, ref_in), lower,
                                           upper)
        ref_clamped &= ~rejected
        self._ref_rad = ref
        return ref, rejected, ref_clamped

    def _sent_reference(self, modes: np.ndarray, ref: np.ndarray, pos: np.ndarray,
                        leaving: np.ndarray, returning: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Steps 2 to 4: the reference filtered by each joint's mode; a joint leaving PWM
        starts from its encoder, a returning one takes a rigid-return step; then clamped
        into the limits.

        Returns:
            The sent reference [rad], the joints it clamped and those still returning.
        """
        prev = self._sent_rad
        sent = filter_reference(modes, ref, prev, pos, self.config.filter_length)
        still_returning = returning  # the two steps below only on ticks that need them
        if returning.any():
            back_sent, back_done = rigid_return_step(prev, ref, self.config)
            still_returning = returning & ~back_done
            sent = np.where(still_returning, back_sent, sent)
        if leaving.any():
            sent = np.where(leaving, pos, sent)  # first tick out of PWM starts from the encoder
        sent, sent_clamped = clamp_reference(sent, self.limits.lower_rad, self.limits.upper_rad)
        return sent, sent_clamped, still_returning


def _pwm_command(gains: PwmGains, feedforward_pct: np.ndarray | None) -> float | np.ndarray:
    """The constant duty ``pwm_command_pct`` of the gains plus the player's feed-forward
    [%], each within and the sum clipped to ``±PWM_COMMAND_LIMIT_PCT``."""
    command = gains.pwm_command_pct
    if feedforward_pct is not None:
        feedforward = _vector("feedforward_pct", feedforward_pct)
        bad = np.abs(feedforward) > PWM_COMMAND_LIMIT_PCT
        if bad.any():
            names = ", ".join(JOINT_NAMES[i] for i in np.flatnonzero(bad))
            raise ControlInputError(f"feedforward_pct of {names} is outside "
                                    f"±{PWM_COMMAND_LIMIT_PCT:g} %")
        command = np.clip(command + feedforward, -PWM_COMMAND_LIMIT_PCT,
                          PWM_COMMAND_LIMIT_PCT)
    return command
