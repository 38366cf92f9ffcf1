"""Reference modes, the per-tick filter, the rigid-return step and the limit clamp."""

from __future__ import annotations

import numpy as np
import pytest

from daemon.control_modes import (
    TICK_S,
    ReferenceFilterConfig,
    ReferenceModeError,
    RefMode,
    clamp_reference,
    filter_reference,
    rigid_return_step,
    ticks_to_settle,
    validate_modes,
)
from robot.errors import InputError
from robot.joints import JOINT_INDEX
from robot.limits import joint_limits

N = 40


def test_mode_numbers_match_hubo_ach():
    assert [int(m) for m in RefMode] == [0, 1, 2, 3]
    assert RefMode.FILTER == 0 and RefMode.DIRECT == 1
    assert RefMode.COMPLIANT == 2 and RefMode.ENCODER_FILTER == 3


def test_filter_one_tick_by_hand():
    f = filter_reference(np.zeros(N, np.int8), np.full(N, 1.0), np.full(N, 0.2), np.zeros(N))
    np.testing.assert_allclose(f, (0.2 * 39 + 1.0) / 40)  # 0.22


@pytest.mark.parametrize("n", [1, 10, 40, 119])
def test_filter_error_after_n_ticks_is_geometric(n):
    ref, sent, pos = np.ones(N), np.zeros(N), np.zeros(N)
    mode = np.full(N, RefMode.FILTER, np.int8)
    for _ in range(n):
        sent = filter_reference(mode, ref, sent, pos)
    np.testing.assert_allclose(ref - sent, (1 - 1 / 40) ** n, rtol=1e-12)


def test_filter_reaches_95_percent_in_about_0_6_s():
    n = ticks_to_settle(0.95, 40)
    assert n == 119
    assert n * TICK_S == pytest.approx(0.595)
    assert 1 - (39 / 40) ** n >= 0.95 > 1 - (39 / 40) ** (n - 1)
    assert ticks_to_settle(0.5, 1) == 1


def test_direct_compliant_and_encoder_filter_modes_per_joint():
    mode = np.zeros(N, np.int8)
    mode[1], mode[2], mode[3] = RefMode.DIRECT, RefMode.COMPLIANT, RefMode.ENCODER_FILTER
    ref, prev, pos = np.full(N, 1.0), np.full(N, 0.5), np.full(N, 0.2)
    f = filter_reference(mode, ref, prev, pos)
    assert f[0] == pytest.approx((0.5 * 39 + 1.0) / 40)
    assert f[1] == 1.0  # direct: f = r
    assert f[2] == 0.2  # compliant: f = pos
    assert f[3] == pytest.approx((0.2 * 39 + 1.0) / 40)  # encoder filter


def test_validate_modes_broadcasts_and_refuses_bad_values():
    out = validate_modes(RefMode.DIRECT)
    assert out.shape == (N,) and out.dtype == np.int8 and (out == 1).all()
    bad = np.zeros(N, int)
    bad[JOINT_INDEX["LEB"]] = 7
    with pytest.raises(ReferenceModeError, match=r"LEB=7.*0 \(FILTER\)"):
        validate_modes(bad)
    with pytest.raises(ReferenceModeError, match="shape"):
        validate_modes(np.zeros(3, int))


def test_rigid_return_step_uses_l400_until_within_tolerance():
    prev = np.zeros(N)
    prev[0], prev[1], prev[2] = 0.1, 0.0075, 0.0076
    sent, done = rigid_return_step(prev, np.zeros(N))
    assert sent[0] == pytest.approx(0.1 * 399 / 400)
    assert not done[0]
    assert done[1] and sent[1] == 0.0075  # at tolerance: done, unchanged
    assert not done[2] and sent[2] == pytest.approx(0.0076 * 399 / 400)


def test_clamp_reference_to_robot_limits():
    lim = joint_limits("drc-hubo")
    ref = np.zeros(N)
    ref[JOINT_INDEX["REB"]] = 0.5  # elbow upper limit is 0
    ref[JOINT_INDEX["RKN"]] = -0.2  # knee lower limit is 0
    ref[JOINT_INDEX["RSP"]] = 1.0  # inside
    out, clamped = clamp_reference(ref, lim.lower_rad, lim.upper_rad)
    assert out[JOINT_INDEX["REB"]] == lim.upper_rad[JOINT_INDEX["REB"]] == 0.0
    assert out[JOINT_INDEX["RKN"]] == 0.0
    assert out[JOINT_INDEX["RSP"]] == 1.0
    assert set(np.flatnonzero(clamped)) == {JOINT_INDEX["REB"], JOINT_INDEX["RKN"]}


def test_filter_config_validation():
    with pytest.raises(InputError, match="filter_length"):
        ReferenceFilterConfig(filter_length=0)
    with pytest.raises(InputError, match="rigid_return_tolerance_rad"):
        ReferenceFilterConfig(rigid_return_tolerance_rad=-1.0)
