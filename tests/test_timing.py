"""planner.timing: toppra parameterisation within the limits, dwell, degenerate segments,
toppra failures."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from synthetic_plan import synthetic_plan  # noqa: E402

from planner import timing  # noqa: E402
from planner.output import segment_paths  # noqa: E402
from planner.timing import (  # noqa: E402
    SegmentPath,
    TimingConfig,
    TimingError,
    time_parameterize,
)
from robot.joints import JOINT_INDEX  # noqa: E402
from robot.limits import joint_limits  # noqa: E402

LIMITS = joint_limits("drc-hubo")
RATE_HZ = 200.0


def _ramp(label: str, start: np.ndarray, joint: str, delta_rad: float, n: int,
          dwell_after: bool = False) -> SegmentPath:
    cols = np.repeat(start[None], n, axis=0)
    cols[:, JOINT_INDEX[joint]] += np.linspace(0.0, delta_rad, n)
    return SegmentPath(label, cols, dwell_after=dwell_after)


@pytest.fixture(scope="module")
def synthetic():
    planner, result, q0 = synthetic_plan()
    paths = segment_paths(result, planner.kin, q0)
    timed = time_parameterize(paths, LIMITS, TimingConfig(rate_hz=RATE_HZ),
                              planner.kin.q_index_of_column)
    return planner, result, paths, timed


def test_samples_respect_nominal_velocity_and_acceleration(synthetic):
    _, _, _, timed = synthetic
    q = timed.columns_rad
    vel = np.abs(np.diff(q, axis=0)) * RATE_HZ
    acc = np.abs(np.diff(q, n=2, axis=0)) * RATE_HZ**2
    assert np.all(vel <= LIMITS.velocity_nominal_rad_s * (1 + 1e-6))
    assert np.all(acc <= LIMITS.accel_nominal_rad_s2 * (1 + 1e-6))
    # toppra is time-optimal: some joint gets close to its (scaled) limit.
    assert (vel / LIMITS.velocity_nominal_rad_s).max() > 0.5
    assert np.all(q >= LIMITS.lower_rad) and np.all(q <= LIMITS.upper_rad)


def test_lines_follow_the_dense_path_and_keep_their_configurations(synthetic):
    planner, result, paths, timed = synthetic
    kin = planner.kin
    # Line 1 is the start; each timed segment ends exactly on its last configuration.
    np.testing.assert_array_equal(timed.columns_rad[0], paths[0].columns_rad[0])
    for i, seg in enumerate(result.segments):
        lines = np.flatnonzero(timed.segment_of_line == i)
        if len(lines) == 0:
            continue
        np.testing.assert_allclose(timed.columns_rad[lines[-1]], kin.columns(seg.configs[-1]),
                                   atol=1e-12)
        np.testing.assert_allclose(timed.configs[lines[-1], :3], seg.configs[-1][:3],
                                   atol=1e-9)
    # Each line's configuration carries the line's joints and a unit base quaternion.
    np.testing.assert_array_equal(np.array([kin.columns(q) for q in timed.configs]),
                                  timed.columns_rad)
    np.testing.assert_allclose(np.linalg.norm(timed.configs[:, 3:7], axis=1), 1.0)


def test_dwell_after_each_step(synthetic):
    _, result, _, timed = synthetic
    n_dwell = round(0.5 * RATE_HZ)
    assert timed.dwell.sum() == 2 * n_dwell  # two steps
    starts = np.flatnonzero(np.diff(timed.dwell.astype(int)) == 1) + 1
    for s in starts:
        block = timed.columns_rad[s:s + n_dwell]
        assert timed.dwell[s:s + n_dwell].all()
        np.testing.assert_array_equal(block, np.repeat(timed.columns_rad[s - 1:s], n_dwell, 0))
    assert timed.dwell[-1]  # the plan ends with the last step's dwell
    # The dwell of step 1 follows its last segment (index 0).
    assert timed.segment_of_line[starts[0]] == 0


def test_no_motion_segment_is_skipped(synthetic):
    _, result, _, timed = synthetic
    assert timed.skipped == [2]  # the one-configuration body segment
    assert 2 not in set(timed.segment_of_line.tolist())


def test_two_point_and_repeated_point_segments():
    start = np.zeros(40)
    start[JOINT_INDEX["RKN"]] = start[JOINT_INDEX["LKN"]] = 0.5
    two = _ramp("two", start, "RSP", -0.3, 2)
    rep_cols = np.vstack([two.columns_rad[-1:], two.columns_rad[-1:],
                          _ramp("r", two.columns_rad[-1], "LSP", 0.2, 5).columns_rad])
    rep = SegmentPath("repeated", rep_cols, dwell_after=True)
    still = SegmentPath("still", rep_cols[-1:].repeat(3, axis=0))
    timed = time_parameterize([two, rep, still], LIMITS, TimingConfig(rate_hz=100.0,
                                                                      dwell_s=0.2))
    assert timed.skipped == [2]
    assert set(timed.durations_s) == {0, 1}
    # A 0.3 rad move at 0.9 × the arm's nominal speed and acceleration takes at least this.
    i = JOINT_INDEX["RSP"]
    v, a = 0.9 * LIMITS.velocity_nominal_rad_s[i], 0.9 * LIMITS.accel_nominal_rad_s2[i]
    t_min = max(2 * np.sqrt(0.3 / a), 0.3 / v)
    assert timed.durations_s[0] >= t_min * 0.99
    np.testing.assert_array_equal(timed.columns_rad[-1], rep_cols[-1])
    assert timed.dwell.sum() == 20
    assert timed.configs is None


def test_first_segment_without_motion_keeps_the_start_line():
    start = np.zeros(40)
    timed = time_parameterize([SegmentPath("still", start[None]),
                               _ramp("move", start, "WST", 0.1, 4)], LIMITS)
    np.testing.assert_array_equal(timed.columns_rad[0], start)
    assert timed.segment_of_line[0] == 0 and timed.skipped == [0]


def test_toppra_returning_none_falls_back_to_a_trapezoid_within_the_limits(monkeypatch):
    """toppra reports failure by returning None; the segment is then timed rest to rest by
    the conservative trapezoid, and its samples still meet the nominal limits."""
    monkeypatch.setattr(timing, "_toppra_trajectory", lambda *a, **k: None)
    seg = _ramp("moveLHand@rung2/limb", np.zeros(40), "LSP", 0.2, 10)
    timed = time_parameterize([seg], LIMITS)
    lines = timed.columns_rad
    np.testing.assert_array_equal(lines[0], np.zeros(40))
    assert lines[-1, JOINT_INDEX["LSP"]] == pytest.approx(0.2)
    timing._check_samples("fallback", lines, 200.0, LIMITS, 1e-6)
    # Rest to rest: a 0.2 rad move at ≤ 0.9 × 0.8 rad/s² takes at least 2·sqrt(0.2 / 0.72) s.
    assert timed.durations_s[0] >= 2 * np.sqrt(0.2 / (0.9 * 0.8)) * 0.99


def test_trapezoid_respects_curvature_and_speed_bounds():
    s = np.linspace(0.0, 1.0, 11)
    way = np.zeros((11, 40))
    way[:, JOINT_INDEX["LSP"]] = np.sin(3 * s)  # a curved path in one joint
    way[:, JOINT_INDEX["LEB"]] = -s
    traj = timing._TrapezoidTrajectory(s, way, LIMITS.velocity_nominal_rad_s,
                                       LIMITS.accel_nominal_rad_s2)
    ts = np.linspace(0.0, traj.duration, int(traj.duration * 200) + 1)
    lines = traj(ts)
    timing._check_samples("trapezoid", lines, 200.0, LIMITS, 1e-3)
    np.testing.assert_allclose(lines[-1], way[-1], atol=1e-9)


def test_sample_check_names_segment_line_and_joint():
    lines = np.zeros((3, 40))
    lines[1, JOINT_INDEX["LEB"]] = 0.1  # 20 rad/s at 200 Hz
    with pytest.raises(TimingError, match=r"seg: sample 1 moves LEB at 20 rad/s"):
        timing._check_samples("seg", lines, 200.0, LIMITS, 1e-6)


def test_samples_breaking_a_limit_are_timed_again_then_refused(monkeypatch):
    calls = []
    real = timing._check_samples

    def strict(label, lines, rate_hz, limits, tol, v_max=None):
        calls.append(len(lines))
        if len(calls) < 3:
            raise TimingError("too fast")
        real(label, lines, rate_hz, limits, tol, v_max)

    monkeypatch.setattr(timing, "_check_samples", strict)
    seg = _ramp("s", np.zeros(40), "WST", 0.2, 6)
    timing._time_segment(seg, LIMITS, TimingConfig())
    assert len(calls) == 3 and calls[2] > calls[0]  # slower limits: more lines
    calls.clear()
    with pytest.raises(TimingError, match="too fast"):
        timing._time_segment(seg, LIMITS, TimingConfig(retries=1))


def test_bad_rate_is_refused():
    with pytest.raises(ValueError, match="rate"):
        time_parameterize([], LIMITS, TimingConfig(rate_hz=0.0))


def test_spline_overshoot_at_a_limit_is_bounded_smoothly():
    # A knee driven onto its lower limit (0 rad) and held there: the spline rings past it.
    k = JOINT_INDEX["RKN"]
    lo = LIMITS.lower_rad[k]
    n = 60
    cols = np.zeros((n, 40))
    cols[:, k] = np.maximum(lo, np.linspace(0.3, -0.3, n))
    cols[:, JOINT_INDEX["RSP"]] = np.linspace(0.0, -0.6, n)  # keeps the path moving
    timed = time_parameterize([SegmentPath("knee", cols)], LIMITS,
                              TimingConfig(rate_hz=RATE_HZ))
    q = timed.columns_rad
    assert q[:, k].min() >= lo
    acc = np.abs(np.diff(q, n=2, axis=0)) * RATE_HZ**2
    assert np.all(acc <= LIMITS.accel_nominal_rad_s2 * (1 + 1e-6))
    np.testing.assert_array_equal(q[[0, -1]], cols[[0, -1]])


def test_limit_smoothing_is_a_convex_blend_with_exact_ends():
    k = JOINT_INDEX["LHP"]
    lines = np.zeros((200, 40))
    lines[:, k] = LIMITS.lower_rad[k] + 0.01 * np.sin(np.linspace(0, 12, 200)) - 0.002
    out = timing._limit_positions(lines, LIMITS)
    assert out[:, k].min() >= LIMITS.lower_rad[k]
    np.testing.assert_array_equal(out[[0, -1], k], np.clip(lines[[0, -1], k],
                                                           LIMITS.lower_rad[k], None))
    np.testing.assert_array_equal(np.delete(out, k, axis=1), np.delete(lines, k, axis=1))


def test_a_segment_velocity_limit_slows_only_that_segment():
    start = np.zeros(40)
    fast = time_parameterize([_ramp("free", start, "LSP", 0.3, 30)], LIMITS,
                             TimingConfig(rate_hz=RATE_HZ))
    cap = LIMITS.velocity_nominal_rad_s.copy()
    cap[JOINT_INDEX["LSP"]] = 0.05
    held = _ramp("held", start, "LSP", 0.3, 30)
    held.velocity_max_rad_s = cap
    slow = time_parameterize([held], LIMITS, TimingConfig(rate_hz=RATE_HZ))
    vel = np.abs(np.diff(slow.columns_rad[:, JOINT_INDEX["LSP"]])) * RATE_HZ
    assert vel.max() <= 0.05 * (1 + 1e-6)
    assert slow.duration_s >= 0.3 / 0.05 > 2 * fast.duration_s
