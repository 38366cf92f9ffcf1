"""Wrist-roll relief: a gripping arm's rigid wrist roll gives way to the grip."""

from __future__ import annotations

import numpy as np
import pytest

from execute.motion.wrist_relief import WRIST_ROLL, WristRelief
from robot.joints import NUM_JOINTS
from robot.limits import joint_limits

TICK_S = 0.005
ROLL = WRIST_ROLL["right"]


def _torque(share: float) -> np.ndarray:
    tau = np.zeros(NUM_JOINTS)
    tau[ROLL] = share * joint_limits().torque_max_nm[ROLL]
    return tau


def test_a_holding_roll_gives_way_against_its_torque_above_the_fraction():
    relief = WristRelief(relief_fraction=0.1, relief_speed_rad_s=0.3, max_offset_rad=0.6)
    for _ in range(200):  # 1 s pushing with +τ: the reference walks to −0.3 rad
        relief.update(ROLL, True, _torque(0.15), TICK_S)
    assert relief.offset_rad[ROLL] == pytest.approx(-0.3)
    for _ in range(200):  # below the fraction: kept where it is while the hand holds
        relief.update(ROLL, True, _torque(0.05), TICK_S)
    assert relief.offset_rad[ROLL] == pytest.approx(-0.3)
    for _ in range(800):  # pushing the other way for 4 s: bounded at +0.6 rad
        relief.update(ROLL, True, _torque(-0.5), TICK_S)
    assert relief.offset_rad[ROLL] == pytest.approx(0.6)


def test_the_offset_unwinds_once_the_hand_lets_go():
    relief = WristRelief()
    for _ in range(100):
        relief.update(ROLL, True, _torque(0.2), TICK_S)
    held = relief.offset_rad[ROLL]
    assert held < 0.0
    for _ in range(50):  # in the air, whatever the torque: back towards 0 at the speed
        relief.update(ROLL, False, _torque(0.2), TICK_S)
    assert relief.offset_rad[ROLL] == pytest.approx(min(0.0, held + 50 * TICK_S * 0.3))
    for _ in range(400):
        relief.update(ROLL, False, _torque(0.0), TICK_S)
    assert relief.offset_rad[ROLL] == 0.0


def test_the_default_fraction_keeps_the_grip_from_bending():
    """The default gives way above 0.1 of the roll's limit: its torque is bending on the
    grip (module docstring); a torque at a fifth of the limit moves the reference."""
    relief = WristRelief()
    relief.update(ROLL, True, _torque(0.2), TICK_S)
    assert relief.offset_rad[ROLL] < 0.0
