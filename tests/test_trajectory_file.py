"""40-column trajectory files: exact round trip, and every malformation refused with its line."""

import numpy as np
import pytest

from robot.errors import InputError, TrajectoryFileError
from robot.joints import JOINT_INDEX, JOINT_NAMES
from robot.limits import joint_limits
from robot.trajectory_file import (
    DECIMALS,
    format_clamps,
    format_trajectory,
    read_trajectory,
    read_trajectory_clamped,
    write_trajectory,
)


def _smooth_trajectory(n=50, seed=3):
    rng = np.random.default_rng(seed)
    lim = joint_limits("drc-hubo")
    lo, hi = np.maximum(lim.lower_rad, -1.0), np.minimum(lim.upper_rad, 1.0)
    a, b = rng.uniform(lo, hi), rng.uniform(lo, hi)
    s = np.linspace(0, 1, n)[:, None]
    return a + (b - a) * s  # at most 2 rad over 49 steps at 25 Hz ≈ 1 rad/s


def _write_lines(tmp_path, lines):
    path = tmp_path / "bad.traj"
    path.write_text("\n".join(lines) + "\n")
    return path


def _fail(path, rate=25.0):
    with pytest.raises(TrajectoryFileError) as err:
        read_trajectory(path, rate)
    return str(err.value)


@pytest.mark.parametrize("name", ["climb.traj", "climb.traj.gz"])
def test_round_trip_is_within_a_microradian_then_exact(tmp_path, name):
    q = _smooth_trajectory()
    q[3, 5] += 1 / 3000  # a value with no short decimal form
    q[4, 6] = -1e-13  # rounds to 0, written "0.0" (not "-0.0")
    path = tmp_path / name
    write_trajectory(path, q)
    back = read_trajectory(path, 25.0)
    assert back.shape == (50, 40)
    assert np.abs(back - q).max() <= 0.5e-6
    assert np.array_equal(back, np.round(q, DECIMALS) + 0.0)
    again = tmp_path / ("again-" + name)
    write_trajectory(again, back)
    assert again.read_bytes() == path.read_bytes()  # what was read writes back bit for bit
    assert max(len(v.split(".")[-1]) for v in format_trajectory(q).split()) <= DECIMALS


@pytest.mark.parametrize("text", ["plain", "tabs and 17 digits", "crlf", "last line bare"])
def test_a_good_file_reads_the_same_at_once_and_line_by_line(monkeypatch, text):
    """numpy reads a plainly good file at once; the line-by-line reader (which names
    problems) gives the same array, bit for bit."""
    import robot.trajectory_file as tf

    q = _smooth_trajectory(200)
    body = format_trajectory(q)
    if text == "tabs and 17 digits":
        body = "\n".join("\t".join(repr(float(v)) for v in row) for row in q) + "\n"
    elif text == "crlf":
        body = body.replace("\n", "\r\n")
    elif text == "last line bare":
        body = body.rstrip("\n")
    at_once = tf.parse_trajectory(body, "x.traj", 25.0)
    plain = tf._parse_plain(body, joint_limits("drc-hubo"), 25.0, True)
    assert (plain is None) == (text == "crlf")  # a CR goes line by line
    monkeypatch.setattr(tf, "_parse_plain", lambda *args: None)
    assert np.array_equal(at_once, tf.parse_trajectory(body, "x.traj", 25.0))


def test_gz_is_the_same_text_compressed_and_deterministic(tmp_path):
    import gzip

    q = _smooth_trajectory()
    write_trajectory(tmp_path / "a.traj.gz", q)
    write_trajectory(tmp_path / "b.traj.gz", q)
    write_trajectory(tmp_path / "a.traj", q)
    raw = (tmp_path / "a.traj.gz").read_bytes()
    assert raw[:2] == b"\x1f\x8b" and raw == (tmp_path / "b.traj.gz").read_bytes()
    assert gzip.decompress(raw) == (tmp_path / "a.traj").read_bytes()
    # a gzip file is read as such whatever its name; a broken one is named
    (tmp_path / "named-plain.traj").write_bytes(raw)
    assert np.array_equal(read_trajectory(tmp_path / "named-plain.traj", 25.0),
                          read_trajectory(tmp_path / "a.traj", 25.0))
    (tmp_path / "cut.traj.gz").write_bytes(raw[:40])
    with pytest.raises(TrajectoryFileError, match="cut.traj.gz: not a readable gzip file"):
        read_trajectory(tmp_path / "cut.traj.gz", 25.0)
    # errors in a compressed file name its lines as in the plain one
    lines = format_trajectory(q).splitlines()
    lines[6] = lines[6].replace(" ", " x ", 1)
    (tmp_path / "bad.traj.gz").write_bytes(gzip.compress(("\n".join(lines) + "\n").encode()))
    assert "bad.traj.gz:7:" in _fail(tmp_path / "bad.traj.gz")


def test_sidecar_of_a_gz_trajectory_sits_next_to_it():
    from robot.plan_sidecar import sidecar_path

    assert sidecar_path("out/drc.traj.gz").as_posix() == "out/drc.plan.json"
    assert sidecar_path("out/drc.traj").as_posix() == "out/drc.plan.json"
    assert sidecar_path("out/drc.txt").as_posix() == "out/drc.txt.plan.json"


def test_written_lines_are_what_the_original_player_reads(tmp_path):
    text = format_trajectory(_smooth_trajectory(5))
    lines = text.split("\n")
    assert lines[-1] == "" and len(lines) == 6
    for line in lines[:-1]:
        assert len(line) < 999  # fgets(buf, 1000)
        assert len(line.split(" ")) == 40


def test_short_line_is_refused_with_its_line(tmp_path):
    q = _smooth_trajectory(5)
    lines = format_trajectory(q).splitlines()
    lines[2] = " ".join(lines[2].split()[:31])  # real files with 31 columns exist
    msg = _fail(_write_lines(tmp_path, lines))
    assert "bad.traj:3:" in msg and "31 columns; expected 40" in msg


def test_header_line_is_refused(tmp_path):
    lines = [" ".join(JOINT_NAMES)] + format_trajectory(_smooth_trajectory(3)).splitlines()
    msg = _fail(_write_lines(tmp_path, lines))
    assert "bad.traj:1:1: column 1 (RHY): 'RHY' is not a number" in msg
    assert "header" in msg


@pytest.mark.parametrize("token", ["nan", "inf", "-inf", "NaN"])
def test_non_finite_values_are_refused(tmp_path, token):
    lines = format_trajectory(_smooth_trajectory(4)).splitlines()
    cols = lines[1].split()
    cols[7] = token
    lines[1] = " ".join(cols)
    msg = _fail(_write_lines(tmp_path, lines))
    assert "bad.traj:2:" in msg and "column 8 (LHR)" in msg and "not finite" in msg


def test_overlong_line_is_refused(tmp_path):
    lines = format_trajectory(_smooth_trajectory(3)).splitlines()
    lines[1] = lines[1] + " " + "0.0" * 400  # the original split this line in two
    msg = _fail(_write_lines(tmp_path, lines))
    assert "bad.traj:2:999:" in msg and "at most 998" in msg


def test_two_rad_jump_is_refused(tmp_path):
    q = np.zeros((4, 40))
    q[2:, JOINT_NAMES.index("RSP")] = -2.0
    path = tmp_path / "bad.traj"
    write_trajectory(path, q)
    msg = _fail(path, rate=25.0)
    assert "bad.traj:3:" in msg and "(RSP)" in msg and "50 rad/s" in msg


def test_value_outside_joint_limit_is_refused(tmp_path):
    q = np.zeros((2, 40))
    q[:, JOINT_NAMES.index("LKN")] = -0.2  # knees do not bend backwards
    path = tmp_path / "bad.traj"
    write_trajectory(path, q)
    msg = _fail(path)
    assert "bad.traj:1:" in msg and "(LKN)" in msg and "[0, 2.61]" in msg


def test_values_past_a_limit_are_read_as_they_are_without_the_limit_check(monkeypatch,
                                                                           tmp_path):
    """check-plan reads a file once, its values beyond the limits as written: at once and
    line by line alike; other problems are still refused."""
    import robot.trajectory_file as tf

    q = _smooth_trajectory(20)
    q[5:8, JOINT_NAMES.index("LKN")] = -0.2  # knees do not bend backwards
    path = tmp_path / "past.traj"
    write_trajectory(path, q)
    assert "(LKN)" in _fail(path)
    at_once = read_trajectory(path, 25.0, check_speed=False, check_limits=False)
    assert np.array_equal(at_once, np.round(q, DECIMALS) + 0.0)
    monkeypatch.setattr(tf, "_parse_plain", lambda *args: None)
    assert np.array_equal(at_once, read_trajectory(path, 25.0, check_speed=False,
                                                   check_limits=False))
    lines = path.read_text().splitlines()
    lines[2] = "0 0 0"
    with pytest.raises(TrajectoryFileError) as err:
        read_trajectory(_write_lines(tmp_path, lines), 25.0, check_speed=False,
                        check_limits=False)
    assert [p.split(":")[1] for p in err.value.problems] == ["3"]


def test_every_problem_is_reported_not_only_the_first(tmp_path):
    lines = format_trajectory(_smooth_trajectory(6)).splitlines()
    lines[1] = "0 0 0"
    lines[4] = lines[4].replace(lines[4].split()[0], "x", 1)
    with pytest.raises(TrajectoryFileError) as err:
        read_trajectory(_write_lines(tmp_path, lines), 25.0)
    assert [p.split(":")[1] for p in err.value.problems] == ["2", "5"]


def test_empty_and_missing_files(tmp_path):
    empty = tmp_path / "empty.traj"
    empty.write_text("")
    assert "no trajectory lines" in _fail(empty)
    assert "cannot read" in _fail(tmp_path / "missing.traj")


# --clamp-limits: real files of the original player overshoot the knee's 0 lower limit.
def _real_style(tmp_path, right_knee_min, name="squat.traj"):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from real_style_traj import real_style_rows, write_real_style

    rows = real_style_rows(knee_min_rad=(right_knee_min, -0.0004))
    return write_real_style(tmp_path / name, rows), rows


def test_real_style_overshoot_is_refused_by_default(tmp_path):
    path, _ = _real_style(tmp_path, -0.07)
    with pytest.raises(TrajectoryFileError) as err:
        read_trajectory(path, 25.0)
    msg = "\n".join(err.value.problems)
    assert "column 4 (RKN): -0.07 rad is outside the joint limits [0, 2.61] rad" in msg
    assert "squat.traj:60:" in msg and "(LKN): -0.0004 rad" in msg


def test_clamp_limits_moves_small_overshoots_onto_the_limit_and_reports_them(tmp_path):
    path, _ = _real_style(tmp_path, -0.07)
    rows = np.loadtxt(path)  # the values as written (6 decimals)
    q, clamps = read_trajectory_clamped(path, 25.0, 0.1)
    lo = joint_limits("drc-hubo").lower_rad
    assert (q >= lo).all()
    beyond = rows < lo
    assert np.array_equal(q[~beyond], rows[~beyond])  # nothing else changed
    by_joint = {c.joint: c for c in clamps}
    assert sorted(by_joint) == ["LKN", "RKN"]
    rkn = by_joint["RKN"]
    assert rkn.lines == tuple(int(k) + 1 for k in np.flatnonzero(beyond[:, JOINT_INDEX["RKN"]]))
    assert rkn.max_overshoot_rad == pytest.approx(0.07) and rkn.worst_line == 60
    assert by_joint["LKN"].max_overshoot_rad == pytest.approx(0.0004)
    report = format_clamps(str(path), clamps, 0.1)
    assert "RKN:" in report and "largest overshoot 0.07 rad at line 60" in report
    assert "below its lower limit 0 rad" in report


def test_clamp_limits_still_refuses_beyond_the_tolerance(tmp_path):
    path, _ = _real_style(tmp_path, -0.07)
    with pytest.raises(TrajectoryFileError) as err:
        read_trajectory_clamped(path, 25.0, 0.01)
    msg = "\n".join(err.value.problems)
    assert "-0.07 rad is outside the joint limits [0, 2.61] rad by more than the " \
           "--clamp-limits tolerance 0.01 rad" in msg
    assert "(LKN)" not in msg  # -0.0004 is within 0.01: clamped, not refused


@pytest.mark.parametrize("tol", [-0.01, 0.5, float("nan")])
def test_clamp_tolerance_outside_its_range_is_refused(tmp_path, tol):
    path, _ = _real_style(tmp_path, -0.07)
    with pytest.raises(InputError, match="--clamp-limits .*allowed 0 to 0.1 rad"):
        read_trajectory_clamped(path, 25.0, tol)
