"""PWM duty, gains, their safety limits and the DRC default-gain decision."""

from __future__ import annotations

import numpy as np
import pytest

from daemon.pwm import (
    PwmGainError,
    PwmGains,
    default_drc_gains,
    duty_to_board_units,
    feedforward_duty_pct,
    pwm_duty,
    validate_pwm_gains,
)
from robot.errors import InputError
from robot.joints import JOINT_INDEX, JOINT_NAMES
from robot.motors import motor_table, pwm_torque
from robot.pwm_gains import (
    DRC_DOCUMENTED_GAINS,
    KD_LIMIT,
    KP_LIMIT,
    MAX_PWM_LIMIT_PCT,
    PWM_COMMAND_LIMIT_PCT,
)

N = 40
J = JOINT_INDEX
ZERO_N = np.zeros(N)


def test_documented_table_is_kept_verbatim():
    assert DRC_DOCUMENTED_GAINS["RSP"] == (80, 0, 8)
    assert DRC_DOCUMENTED_GAINS["LSR"] == (80, 0, 8)
    assert DRC_DOCUMENTED_GAINS["RSY"] == (70, 0, 7)
    assert DRC_DOCUMENTED_GAINS["LEB"] == (40, 0, 4)
    assert DRC_DOCUMENTED_GAINS["REB"] == (50, 0, 5)
    assert DRC_DOCUMENTED_GAINS["LWY"] == (50, 0, 5)
    assert DRC_DOCUMENTED_GAINS["RWP"] == (40, 0, 4)
    assert "RWR" not in DRC_DOCUMENTED_GAINS and "RKN" not in DRC_DOCUMENTED_GAINS


def test_documented_defaults_break_the_safety_rules_and_are_refused():
    # The conflict this module resolves: the DRC defaults violate kp < 70 and max_pwm < 8.
    with pytest.raises(PwmGainError) as err:
        PwmGains.from_table(DRC_DOCUMENTED_GAINS)
    msg = str(err.value)
    assert "RSP kp = 80 is outside the allowed range [0, 70) %/rad" in msg
    assert "RSY kp = 70 is outside the allowed range [0, 70)" in msg
    assert "LSP max_pwm_pct = 8 is outside the allowed range [0, 8) %" in msg
    assert "LEB" not in msg  # 40/0/4 is fine
    assert len(err.value.problems) == 10  # 6 shoulder kp + 4 shoulder max_pwm


def test_safe_defaults_clip_each_field_to_the_largest_allowed_value():
    g = default_drc_gains()
    for side in "RL":
        for joint in ("SP", "SR"):
            j = J[side + joint]
            assert (g.kp[j], g.kd[j], g.max_pwm_pct[j]) == (69.0, 0.0, 7.9)
        j = J[side + "SY"]
        assert (g.kp[j], g.kd[j], g.max_pwm_pct[j]) == (69.0, 0.0, 7.0)
        assert (g.kp[J[side + "WY"]], g.max_pwm_pct[J[side + "WY"]]) == (50.0, 5.0)
        assert (g.kp[J[side + "WP"]], g.max_pwm_pct[J[side + "WP"]]) == (40.0, 4.0)
        assert g.kp[J[side + "WR"]] == 0.0
    assert (g.kp[J["REB"]], g.max_pwm_pct[J["REB"]]) == (50.0, 5.0)
    assert (g.kp[J["LEB"]], g.max_pwm_pct[J["LEB"]]) == (40.0, 4.0)
    assert (g.kp < KP_LIMIT).all() and (g.kd < KD_LIMIT).all()
    assert (g.max_pwm_pct < MAX_PWM_LIMIT_PCT).all()
    listed = [J[n] for n in DRC_DOCUMENTED_GAINS]
    others = np.setdiff1d(np.arange(N), listed)
    assert not g.kp[others].any() and not g.max_pwm_pct[others].any()
    assert not g.pwm_command_pct.any()


@pytest.mark.parametrize(
    ("field", "value", "allowed"),
    [
        ("kp", 70.0, "[0, 70) %/rad"),
        ("kp", -1.0, "[0, 70) %/rad"),
        ("kd", 10.0, "[0, 10) %/(rad/s)"),
        ("max_pwm_pct", 8.0, "[0, 8) %"),
        ("max_pwm_pct", float("nan"), "[0, 8) %"),
        ("pwm_command_pct", 101.0, "[-100, 100] %"),
    ],
)
def test_validation_refuses_and_names_joint_field_value_range(field, value, allowed):
    gains = {"kp": 10.0, "kd": 1.0, "max_pwm_pct": 5.0, "pwm_command_pct": 0.0}
    gains[field] = value
    with pytest.raises(PwmGainError) as err:
        validate_pwm_gains(**gains, joints=("LSY",))
    assert f"LSY {field} = {value:g} is outside the allowed range {allowed}" in str(err.value)
    assert isinstance(err.value, InputError)  # CLI exit code 2


def test_validation_accepts_values_just_inside():
    validate_pwm_gains(69.99, 9.99, 7.99, -100.0)


def test_with_joint_is_the_console_path_and_validates():
    g = default_drc_gains()
    g2 = g.with_joint("REB", kp=30.0, kd=2.0)
    assert g2.kp[J["REB"]] == 30.0 and g2.kd[J["REB"]] == 2.0
    assert g2.max_pwm_pct[J["REB"]] == 5.0
    assert g.kp[J["REB"]] == 50.0  # the original is unchanged
    with pytest.raises(PwmGainError, match=r"LSP kp = 75 is outside the allowed range \[0, 70\)"):
        g.with_joint("LSP", kp=75.0)
    with pytest.raises(InputError, match="unknown joint 'XXX'.*RSP"):
        g.with_joint("XXX", kp=1.0)


def test_gains_are_read_only_and_compare_by_value():
    g = default_drc_gains()
    with pytest.raises(ValueError):
        g.kp[0] = 1.0
    assert g == default_drc_gains()
    assert g != PwmGains.zeros()


def _gains(kp=0.0, kd=0.0, max_pwm=0.0, cmd=0.0) -> PwmGains:
    return PwmGains(np.full(N, kp), np.full(N, kd), np.full(N, max_pwm), np.full(N, cmd))


def test_duty_formula_and_sign_by_hand():
    g = _gains(kp=50.0, kd=5.0, max_pwm=7.9, cmd=1.0)
    ref, pos, vel = np.zeros(N), np.zeros(N), np.zeros(N)
    ref[0] = 0.1  # below the reference: negative duty (hubo-ach sign)
    ref[1] = -0.1  # above it: positive duty
    vel[2] = 0.4  # moving: kd term enters with +
    duty, sat = pwm_duty(ref, pos, vel, g)
    assert duty[0] == pytest.approx(-(50 * 0.1 + 1.0))  # -6.0
    assert duty[1] == pytest.approx(-(50 * -0.1 + 1.0))  # +4.0
    assert duty[2] == pytest.approx(-(0 - 5.0 * 0.4 + 1.0))  # +1.0
    assert duty[3] == pytest.approx(-1.0)  # feed-forward only
    assert not sat.any()


def test_duty_clamps_to_max_pwm():
    g = default_drc_gains()
    ref = np.zeros(N)
    ref[J["RSP"]] = 1.0  # 69 %/rad * 1 rad = 69 % -> clamped to 7.9 %
    ref[J["LEB"]] = -1.0  # +40 % -> clamped to +4 %
    ref[J["RWY"]] = 0.02  # -1 %: inside
    duty, sat = pwm_duty(ref, np.zeros(N), np.zeros(N), g)
    assert duty[J["RSP"]] == -7.9 and sat[J["RSP"]]
    assert duty[J["LEB"]] == 4.0 and sat[J["LEB"]]
    assert duty[J["RWY"]] == pytest.approx(-1.0) and not sat[J["RWY"]]
    assert (np.abs(duty) <= g.max_pwm_pct).all()


def test_duty_in_board_units_of_0_1_percent():
    np.testing.assert_array_equal(duty_to_board_units(np.array([-7.9, 5.04, 0.0])), [-79, 50, 0])


def test_repr_lists_active_joints():
    r = repr(default_drc_gains())
    assert "RSP=69/0/7.9" in r and "RKN" not in r
    assert JOINT_NAMES[0] not in repr(PwmGains.zeros())


def test_feedforward_duty_gives_the_torque_at_rest_and_moving():
    """pwm_command from `feedforward_duty_pct` makes the motor model give the torque asked,
    at rest and at the planned velocity (back-EMF fed forward), at any battery voltage."""
    table = motor_table()
    g = default_drc_gains()
    want = np.zeros(N)
    want[J["LSP"]], want[J["REB"]], want[J["LWP"]] = -4.0, 2.5, 0.8
    vel = np.zeros(N)
    vel[J["LSP"]], vel[J["REB"]] = 0.05, -0.02
    for volts in (48.0, 42.0):
        for v in (np.zeros(N), vel):
            command = feedforward_duty_pct(want, volts, v, table)
            duty, sat = pwm_duty(ZERO_N, ZERO_N, v, g, command)  # on the reference, kd = 0
            assert not sat.any()
            np.testing.assert_allclose(pwm_torque(duty, v, volts, table), want, atol=1e-12)
    command = feedforward_duty_pct(want, 48.0)
    np.testing.assert_array_equal(np.sign(command), np.sign(want))  # +command gives +τ


def test_feedforward_duty_stays_within_the_command_limit_and_the_clamp_still_acts():
    huge = np.full(N, 1e4)
    command = feedforward_duty_pct(huge, 48.0)
    assert (np.abs(command) <= PWM_COMMAND_LIMIT_PCT).all()
    duty, sat = pwm_duty(ZERO_N, ZERO_N, ZERO_N, default_drc_gains(), command)
    assert (np.abs(duty) <= default_drc_gains().max_pwm_pct).all() and sat[J["LSP"]]
