"""Joint and sensor tables: shipped files, validation messages, encoder conversions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from daemon.tables import (
    TABLE_DIR,
    TableError,
    load_joint_table,
    load_sensor_table,
    parse_joint_table,
    parse_sensor_table,
)
from robot.errors import InputError
from robot.joints import JOINT_NAMES

SHIPPED = (TABLE_DIR / "drc-hubo" / "joint.table").read_text()


def _replace_row(name: str, new: str) -> str:
    lines = SHIPPED.splitlines()
    i = next(k for k, line in enumerate(lines) if line.split()[:1] == [name])
    lines[i] = new
    return "\n".join(lines) + "\n", i + 1


def test_shipped_tables_load():
    t = load_joint_table()
    assert [j.name for j in t.joints] == list(JOINT_NAMES)
    assert t["LSP"].jmc == 10 and t["LSP"].can == 1
    assert t["WST"].jmc == 0x23 and t["WST"].can == 0
    assert t["RWR"].jmc == 0x24 and t["LWR"].jmc == 0x25
    assert t["REB"].kp == 50 and t["LEB"].kp == 40
    assert t.boards()[(0, 0)] == (0, 1)  # JMC0: RHY, RHR
    s = load_sensor_table()
    assert [x.board for x in s.of_kind("ft")] == [1, 2, 6, 7]
    assert s["IMU"].board == 3 and s["IMU"].can == 0
    assert s["POWER"].board == 0x0E


def test_given_gearing_and_formula():
    t = load_joint_table()
    assert t["LSP"].rad_per_count == pytest.approx(10 / 25 / 100 / 4000 * 2 * math.pi)
    assert t["RHR"].rad_per_count == pytest.approx(324 / 1024 / 160 / 4000 * 2 * math.pi)
    assert t["LWR"].rad_per_count == pytest.approx(-1 / 2 / 100 / 128 * 2 * math.pi)


def test_encoder_round_trip_is_exact():
    t = load_joint_table()
    rng = np.random.default_rng(0)
    counts = rng.integers(-(1 << 22), 1 << 22, size=(200, 40))
    for row in counts:
        assert np.array_equal(t.rad_to_enc(t.enc_to_rad(row)), row)
    rad = rng.uniform(-3, 3, size=40)
    back = t.enc_to_rad(t.rad_to_enc(rad))
    assert np.all(np.abs(back - rad) <= np.abs(t.rad_per_count) / 2 + 1e-15)
    idx = np.array([3, 17])
    assert np.array_equal(t.rad_to_enc(t.enc_to_rad(counts[0, idx], idx), idx), counts[0, idx])


@pytest.mark.parametrize(
    "row,column,message",
    [
        ("RKN 0 0 13 25 160 4000 1 0x02 1 0 1 0 0 0", "zeroed", "expected 16 columns"),
        ("RKN 0 0 13 25 160 4000 1 0x02 1 0 1 0 0 0 0 7", "zeroed", "got 17"),
        ("RKN 0 0 13 x25 160 4000 1 0x02 1 0 1 0 0 0 0", "driven", "'x25' is not a number"),
        ("RKN 0 0 13 25 160 4000 1 0x30 1 0 1 0 0 0 0", "jmc", "48 out of range [0, 0x2f]"),
        ("RKN 0 0 13 25 160 4000 1 0x02 1 2 1 0 0 0 0", "can", "2 out of range [0, 1]"),
        ("RKN 0 0 13 25 160 4000 0 0x02 1 0 1 0 0 0 0", "dir", "0 not in [-1, 1]"),
        ("RKN 0 0 13 25 160 4000 1 0x02 1 0 1 0 0 200 0", "maxPWM", "out of range [0, 100]"),
        ("RAR 1 0 16 25 160 4000 1 0x03 1 0 3 0 0 0 0", "numMot", "numMot=2"),
        ("RKN 0 0 13 25 160 4000 1 0x00 1 0 2 0 0 0 0", "motNo", "already used by RHY"),
        ("XYZ 0 0 13 25 160 4000 1 0x02 1 0 1 0 0 0 0", "name", "unknown joint 'XYZ'"),
    ],
)
def test_joint_table_errors_name_file_line_column(row, column, message):
    text, lineno = _replace_row("RAR" if row.startswith("RAR") else "RKN", row)
    with pytest.raises(TableError) as exc:
        parse_joint_table(text, "joint.table")
    first = exc.value.problems[0]
    assert first.startswith(f"joint.table:{lineno}: column '{column}': ")
    assert message in first
    assert isinstance(exc.value, InputError)


def test_duplicate_and_missing_joints():
    lines = SHIPPED.splitlines()
    rkn = next(line for line in lines if line.startswith("RKN"))
    with pytest.raises(TableError, match=r"t:\d+: column 'name': duplicate joint 'RKN' \(first"):
        parse_joint_table(SHIPPED + rkn + "\n", "t")
    text = "\n".join(line for line in lines if not line.startswith("LF5"))
    with pytest.raises(TableError, match="missing joints: LF5"):
        parse_joint_table(text, "t")


def test_sensor_table_errors():
    good = "RFFT 0 1 1 1 1 1\n"
    assert parse_sensor_table(good)["RFFT"].sign == (1, 1, 1)
    with pytest.raises(TableError, match=r"s:2: column 'board': 'b' is not an integer"):
        parse_sensor_table("# c\nRFFT 0 1 b 1 1 1\n", "s")
    with pytest.raises(TableError, match=r"s:1: column 'name': unknown sensor 'FOO'"):
        parse_sensor_table("FOO 0 1 1 1 1 1\n", "s")
    with pytest.raises(TableError, match=r"s:1: column 'z-sign': 2 not in \[-1, 1\]"):
        parse_sensor_table("RFFT 0 1 1 1 1 2\n", "s")
    with pytest.raises(TableError, match=r"s:2: column 'name': duplicate sensor"):
        parse_sensor_table(good + good, "s")


def test_unreadable_file_is_input_error(tmp_path):
    with pytest.raises(InputError, match="cannot read table"):
        load_joint_table(tmp_path / "nope.table")
