"""The per-joint control law: filter state, PWM joints, limp joints, rigid return, clamps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from daemon.control_modes import RefMode
from daemon.joint_control import (
    ComplianceState,
    ControlInputError,
    JointController,
    default_compliance_capable,
)
from daemon.pwm import PwmGains, default_drc_gains
from robot.joints import FINGER_JOINTS, JOINT_INDEX

N = 40
J = JOINT_INDEX
ZERO = np.zeros(N)
RIGID = np.zeros(N, bool)


def _comply(*names: str) -> np.ndarray:
    mask = np.zeros(N, bool)
    for n in names:
        mask[J[n]] = True
    return mask


def test_wrist_roll_and_fingers_cannot_comply():
    capable = default_compliance_capable()
    assert not capable[J["RWR"]] and not capable[J["LWR"]]
    assert not any(capable[J[n]] for n in FINGER_JOINTS["left"] + FINGER_JOINTS["right"])
    assert capable[J["RSP"]] and capable[J["LWP"]] and capable[J["RKN"]]
    assert capable.sum() == 40 - 2 - 10


def test_first_tick_starts_the_filter_at_the_measured_pose():
    c = JointController()
    pos = np.full(N, 0.2)
    pos[J["REB"]] = pos[J["LEB"]] = -0.2  # elbows are <= 0
    out = c.tick(pos, RefMode.FILTER, RIGID, pos, ZERO, default_drc_gains())
    np.testing.assert_allclose(out.ref_sent_rad, pos)
    assert not out.pwm.any() and not out.duty_pct.any()


def test_filter_mode_ticks_by_hand():
    c = JointController()
    c.reset(ZERO)
    ref = np.zeros(N)
    ref[J["RSP"]] = 0.1
    n = 40
    for _ in range(n):
        out = c.tick(ref, RefMode.FILTER, RIGID, ZERO, ZERO, default_drc_gains())
    assert out.ref_sent_rad[J["RSP"]] == pytest.approx(0.1 * (1 - (39 / 40) ** n), rel=1e-12)
    assert (out.state == ComplianceState.RIGID).all()


def test_a_reference_beyond_a_limit_is_rejected_and_the_previous_one_held():
    c = JointController()
    c.reset(ZERO)
    ref = np.zeros(N)
    ref[J["REB"]] = -0.4
    ref[J["RSP"]] = 0.3
    c.tick(ref, RefMode.DIRECT, RIGID, ZERO, ZERO, default_drc_gains())
    ref[J["REB"]] = 0.5  # upper limit 0: rejected, REB keeps -0.4
    ref[J["RKN"]] = 3.0  # upper limit 2.61: rejected, RKN keeps 0
    ref[J["RSP"]] = 0.2
    out = c.tick(ref, RefMode.DIRECT, RIGID, ZERO, ZERO, default_drc_gains())
    assert out.ref_sent_rad[J["REB"]] == -0.4 and out.ref_sent_rad[J["RKN"]] == 0.0
    assert out.ref_sent_rad[J["RSP"]] == 0.2  # the other joints of the sample are followed
    assert np.flatnonzero(out.limit_rejected).tolist() == sorted([J["REB"], J["RKN"]])
    assert not out.limit_clamped.any()
    ref[J["REB"]], ref[J["RKN"]] = -0.1, 1.0  # back within the limits: followed again
    out = c.tick(ref, RefMode.DIRECT, RIGID, ZERO, ZERO, default_drc_gains())
    assert out.ref_sent_rad[J["REB"]] == -0.1 and out.ref_sent_rad[J["RKN"]] == 1.0
    assert not out.limit_rejected.any()


def test_float_noise_at_a_limit_is_clamped_not_rejected():
    c = JointController()
    ref = np.zeros(N)
    ref[J["RKN"]] = -1e-10  # lower limit 0
    ref[J["REB"]] = 1.6e-6  # upper limit 0: a computed straight elbow, as the motion layer's
    ref[J["LEB"]] = 9e-4  # within REF_CLAMP_TOLERANCE_RAD (1e-3)
    out = c.tick(ref, RefMode.DIRECT, RIGID, ZERO, ZERO, default_drc_gains())
    for name in ("RKN", "REB", "LEB"):
        assert out.ref_sent_rad[J[name]] == 0.0 and out.limit_clamped[J[name]]
    assert not out.limit_rejected.any()
    ref[J["LEB"]] = 2e-3  # beyond it: rejected, LEB keeps 0
    out = c.tick(ref, RefMode.DIRECT, RIGID, ZERO, ZERO, default_drc_gains())
    assert out.limit_rejected[J["LEB"]] and out.ref_sent_rad[J["LEB"]] == 0.0


def test_encoder_following_modes_are_clamped_too():
    c = JointController()
    pos = np.zeros(N)
    pos[J["REB"]] = 0.3  # measured beyond the limit (e.g. a bad encoder)
    out = c.tick(ZERO, RefMode.ENCODER_FILTER, RIGID, pos, ZERO, default_drc_gains())
    assert out.ref_sent_rad[J["REB"]] == 0.0 and out.limit_clamped[J["REB"]]


def test_pwm_joint_duty_from_the_sent_reference():
    gains = default_drc_gains().with_joint("RSP", kd=5.0)
    c = JointController()
    ref, vel = np.zeros(N), np.zeros(N)
    ref[J["RSP"]] = 0.05
    ref[J["LSP"]] = 0.2
    vel[J["RSP"]] = 0.1
    out = c.tick(ref, RefMode.DIRECT, _comply("RSP", "LSP"), ZERO, vel, gains)
    assert out.pwm[J["RSP"]] and out.pwm[J["LSP"]] and out.pwm.sum() == 2
    assert out.duty_pct[J["RSP"]] == pytest.approx(-(69 * 0.05 - 5.0 * 0.1))  # -2.95 %
    assert out.duty_pct[J["LSP"]] == pytest.approx(-7.9) and out.duty_saturated[J["LSP"]]
    assert not out.duty_saturated[J["RSP"]]
    assert np.count_nonzero(out.duty_pct) == 2  # position joints get no duty
    assert out.state[J["RSP"]] == ComplianceState.COMPLIANT


def test_compliant_mode_leaves_only_damping():
    # mode COMPLIANT: f = pos, so the kp term vanishes.
    c = JointController()
    pos = np.zeros(N)
    pos[J["RSP"]] = 0.4
    out = c.tick(ZERO, RefMode.COMPLIANT, _comply("RSP"), pos, ZERO, default_drc_gains())
    assert out.ref_sent_rad[J["RSP"]] == 0.4
    assert out.duty_pct[J["RSP"]] == 0.0


def test_zero_gain_joint_in_pwm_is_limp():
    c = JointController()
    ref = np.full(N, 0.3)
    out = c.tick(ref, RefMode.DIRECT, _comply("RKN", "RSP"), ZERO, ZERO, default_drc_gains())
    assert out.pwm[J["RKN"]] and out.limp[J["RKN"]] and out.duty_pct[J["RKN"]] == 0.0
    assert not out.limp[J["RSP"]] and out.duty_pct[J["RSP"]] != 0.0


def test_wrist_roll_stays_in_position_mode():
    c = JointController()
    ref = np.zeros(N)
    ref[J["RWR"]] = 0.2
    gains = default_drc_gains().with_joint("RWR", kp=30.0, max_pwm_pct=3.0)
    out = c.tick(ref, RefMode.DIRECT, _comply("RWR"), ZERO, ZERO, gains)
    assert not out.pwm[J["RWR"]] and out.comply_unsupported[J["RWR"]]
    assert out.ref_sent_rad[J["RWR"]] == 0.2 and out.duty_pct[J["RWR"]] == 0.0
    assert out.state[J["RWR"]] == ComplianceState.RIGID


@pytest.mark.parametrize("mode", [RefMode.DIRECT, RefMode.FILTER])
def test_rigid_return_l400_until_within_tolerance_then_commanded_mode(mode):
    c = JointController()
    gains = default_drc_gains()
    pos = np.zeros(N)
    pos[J["RSP"]] = 0.3  # the compliant arm was pushed 0.3 rad off its reference 0
    for _ in range(5):
        c.tick(ZERO, mode, _comply("RSP"), pos, ZERO, gains)
    # Leaving compliance: this tick sends the measured position, in position mode.
    out = c.tick(ZERO, mode, RIGID, pos, ZERO, gains)
    assert out.ref_sent_rad[J["RSP"]] == 0.3
    assert out.returning[J["RSP"]] and not out.pwm[J["RSP"]] and out.duty_pct[J["RSP"]] == 0
    # Hand count: smallest n with 0.3 * (399/400)^n <= 0.0075.
    n_return = math.ceil(math.log(0.0075 / 0.3) / math.log(399 / 400))
    assert n_return == 1474
    for n in range(1, n_return + 1):
        out = c.tick(ZERO, mode, RIGID, pos, ZERO, gains)
        assert out.returning[J["RSP"]], n
        if n in (1, 100, n_return):
            assert out.ref_sent_rad[J["RSP"]] == pytest.approx(0.3 * (399 / 400) ** n, rel=1e-9)
    last = out.ref_sent_rad[J["RSP"]]
    assert last <= 0.0075 < 0.3 * (399 / 400) ** (n_return - 1)
    # Within tolerance: rigid again, and the commanded mode acts on this same tick.
    out = c.tick(ZERO, mode, RIGID, pos, ZERO, gains)
    assert not out.returning[J["RSP"]] and out.state[J["RSP"]] == ComplianceState.RIGID
    expected = 0.0 if mode == RefMode.DIRECT else last * 39 / 40
    assert out.ref_sent_rad[J["RSP"]] == pytest.approx(expected)


def test_comply_again_during_return_goes_straight_back_to_pwm():
    c = JointController()
    pos = np.zeros(N)
    pos[J["LSP"]] = 0.3
    gains = default_drc_gains()
    c.tick(ZERO, RefMode.FILTER, _comply("LSP"), pos, ZERO, gains)
    c.tick(ZERO, RefMode.FILTER, RIGID, pos, ZERO, gains)
    assert c.state[J["LSP"]] == ComplianceState.RETURNING
    out = c.tick(ZERO, RefMode.FILTER, _comply("LSP"), pos, ZERO, gains)
    assert out.pwm[J["LSP"]] and out.state[J["LSP"]] == ComplianceState.COMPLIANT


def test_bad_inputs_are_refused_without_changing_state():
    c = JointController()
    c.reset(ZERO)
    ref = np.zeros(N)
    ref[J["LAP"]] = np.nan
    with pytest.raises(ControlInputError, match="ref_rad is not finite for LAP"):
        c.tick(ref, RefMode.FILTER, RIGID, ZERO, ZERO, PwmGains.zeros())
    with pytest.raises(ControlInputError, match=r"pos_rad has shape \(3,\)"):
        c.tick(ZERO, RefMode.FILTER, RIGID, np.zeros(3), ZERO, PwmGains.zeros())
    np.testing.assert_array_equal(c.ref_sent_rad, ZERO)


def test_tick_feedforward_adds_to_the_gains_command_and_is_bounded():
    c = JointController()
    gains = default_drc_gains().with_joint("LSP", pwm_command_pct=1.0)
    command = np.zeros(N)
    command[J["LSP"]] = -2.5
    out = c.tick(ZERO, RefMode.FILTER, _comply("LSP"), ZERO, ZERO, gains, command)
    assert out.duty_pct[J["LSP"]] == pytest.approx(1.5)  # −(0 − 0 + (1.0 − 2.5))
    out = c.tick(ZERO, RefMode.FILTER, _comply("LSP"), ZERO, ZERO, gains)
    assert out.duty_pct[J["LSP"]] == pytest.approx(-1.0)  # without it, the gains' command
    sent = c.ref_sent_rad
    command[J["LEB"]] = 150.0
    with pytest.raises(ControlInputError, match="feedforward_pct of LEB is outside"):
        c.tick(ZERO, RefMode.FILTER, _comply("LSP"), ZERO, ZERO, gains, command)
    np.testing.assert_array_equal(c.ref_sent_rad, sent)
