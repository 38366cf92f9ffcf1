"""The channel structs: packed layout, documented sizes, shared header."""

from __future__ import annotations

import numpy as np
import pytest

from daemon import structs
from daemon.structs import (
    BOARD_CMD_DTYPE,
    CHANNEL_DTYPES,
    PWM_GAINS_DTYPE,
    REF_DTYPE,
    STATE_DTYPE,
    BoardCommandType,
    StatusFlag,
    describe,
    new_sample,
)


@pytest.mark.parametrize(
    "dtype,size",
    [(REF_DTYPE, 741), (BOARD_CMD_DTYPE, 76), (PWM_GAINS_DTYPE, 1300), (STATE_DTYPE, 2200)],
)
def test_sizes_match_the_docstring(dtype, size):
    assert dtype.itemsize == size
    assert f"| {size} |" in structs.__doc__


@pytest.mark.parametrize("name", sorted(CHANNEL_DTYPES))
def test_packed_and_header_first(name):
    dt = CHANNEL_DTYPES[name]
    assert sum(dt.fields[f][0].itemsize for f in dt.names) == dt.itemsize  # no padding
    assert [dt.fields[f][1] for f in ("writer_id", "seq", "time_ns")] == [0, 4, 12]


def test_sample_fields_per_joint_and_sensors():
    s = new_sample(STATE_DTYPE)
    assert s.shape == ()
    assert s["pos"].shape == (40,)
    assert s["ft"].shape == (4,)
    assert s["imu"]["wz"].shape == (3,)
    s["status"][3] = StatusFlag.NO_REPLY | StatusFlag.NOT_HOMED
    assert StatusFlag(int(s["status"][3])) & StatusFlag.NOT_HOMED
    s["power"]["V"] = 48.0
    assert float(s["power"]["V"]) == 48.0


def test_board_commands_and_describe():
    assert BoardCommandType.HOME_ALL == 2
    c = new_sample(BOARD_CMD_DTYPE)
    c["type"] = BoardCommandType.SET_GAINS
    c["dvalues"][:3] = (60.0, 5.0, 6.0)
    assert BoardCommandType(int(c["type"])) is BoardCommandType.SET_GAINS
    text = describe(STATE_DTYPE)
    assert text.startswith("2200 bytes")
    assert "ft: mx,my,fz[4]" in text
    assert np.dtype(REF_DTYPE).fields["ref"][0].shape == (40,)
