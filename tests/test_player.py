"""The trajectory player: timing, go-to-init, start line, pause, per-arm modes, flags."""

from __future__ import annotations

import numpy as np
import pytest

from daemon.control_modes import TICK_S, RefMode
from daemon.joint_control import JointController
from daemon.pwm import default_drc_gains
from execute.play.arm_modes import ArmModeSchedule, ModeScheduleError
from execute.play.player import (
    PlayerOptionError,
    PlayerOptions,
    PlayerStateError,
    TrajectoryPlayer,
    compliant_arms_from_flags,
    min_jerk,
)
from robot.errors import InputError
from robot.joints import ARM_JOINTS, JOINT_INDEX, joint_indices
from robot.plan_sidecar import ArmFeedforward

N = 40
LEFT = joint_indices(ARM_JOINTS["left"])
RIGHT = joint_indices(ARM_JOINTS["right"])


def _ramp(num_lines: int) -> np.ndarray:
    """Row k holds the value 0.01·k in every column (readable line numbers)."""
    return np.repeat(0.01 * np.arange(num_lines, dtype=float)[:, None], N, axis=1)


# ------------------------------------------------------------------ options
def test_default_options_are_the_original_ones():
    o = PlayerOptions()
    assert o.rate_hz == 25 and not o.go_to_init and o.go_to_init_s == 3.0
    assert o.start_line == 1 and not o.no_filter and o.compliant_arms == frozenset()


@pytest.mark.parametrize("rate", [30, 0, 1000, 25.5, True])
def test_other_rates_are_refused(rate):
    with pytest.raises(PlayerOptionError, match="10, 25, 50, 100, 200, 500 Hz"):
        PlayerOptions(rate_hz=rate)


def test_option_errors_name_the_option():
    with pytest.raises(PlayerOptionError, match="start_line = 0"):
        PlayerOptions(start_line=0)
    with pytest.raises(PlayerOptionError, match="compliant_arms"):
        PlayerOptions(compliant_arms={"middle"})
    with pytest.raises(PlayerOptionError, match="go_to_init_s"):
        PlayerOptions(go_to_init_s=0.0)
    with pytest.raises(PlayerOptionError, match=r"start_line = 11 is beyond the last line \(10\)"):
        TrajectoryPlayer(_ramp(10), PlayerOptions(start_line=11))
    with pytest.raises(PlayerOptionError, match=r"shape \(10, 31\)"):
        TrajectoryPlayer(np.zeros((10, 31)))
    bad = _ramp(5)
    bad[3, 7] = np.inf
    with pytest.raises(PlayerOptionError, match="line 4 column 8"):
        TrajectoryPlayer(bad)
    assert issubclass(PlayerOptionError, InputError)


def test_compliance_flags():
    assert compliant_arms_from_flags() == frozenset()
    assert compliant_arms_from_flags(c=True) == {"left", "right"}
    assert compliant_arms_from_flags(cl=True) == {"left"}
    assert compliant_arms_from_flags(cr=True) == {"right"}
    assert compliant_arms_from_flags(cl=True, cr=True) == {"left", "right"}


# ------------------------------------------------------------------ timing
@pytest.mark.parametrize(("rate", "ticks_per_line"), [(25, 8), (200, 1), (10, 20), (100, 2)])
def test_line_k_is_played_at_k_over_f_in_lock_step(rate, ticks_per_line):
    lines = 12
    p = TrajectoryPlayer(_ramp(lines), PlayerOptions(rate_hz=rate))
    for n in range(lines * ticks_per_line + 30):
        t = p.step(n * TICK_S)
        k = min(n // ticks_per_line, lines - 1)
        assert t.line_index == k and t.ref_rad[0] == pytest.approx(0.01 * k), n
        assert t.finished == (n >= lines * ticks_per_line), n
        assert t.mode.tolist() == [RefMode.FILTER] * N
    assert p.duration_s == pytest.approx(lines / rate)


def test_500_hz_plays_more_than_one_line_per_tick():
    p = TrajectoryPlayer(_ramp(50), PlayerOptions(rate_hz=500))
    assert [p.step(n * TICK_S).line_index for n in range(5)] == [0, 2, 5, 7, 10]


def test_real_time_with_any_clock_origin():
    p = TrajectoryPlayer(_ramp(10), PlayerOptions(rate_hz=50))
    t0 = 12345.678
    assert p.step(t0).line_index == 0
    assert p.step(t0 + 0.0199).line_index == 0
    assert p.step(t0 + 0.0201).line_index == 1
    assert p.step(t0 + 0.1).line_index == 5
    assert p.step(t0 + 0.05).line_index == 5  # time never runs backwards
    assert p.time_of_line(7) == pytest.approx(7 / 50)


def test_end_of_file_holds_the_last_reference():
    p = TrajectoryPlayer(_ramp(3), PlayerOptions(rate_hz=10))
    p.step(0.0)
    t = p.step(100.0)
    assert t.finished and t.line_index == 2 and t.line_number == 3
    np.testing.assert_array_equal(t.ref_rad, _ramp(3)[2])


def test_no_filter_sends_direct_mode():
    t = TrajectoryPlayer(_ramp(3), PlayerOptions(no_filter=True)).step(0.0)
    assert (t.mode == RefMode.DIRECT).all()


# ------------------------------------------------------------------ go to init
def test_go_to_init_is_smooth_and_ends_on_line_one():
    traj = _ramp(5) + 0.5
    start = np.full(N, -0.3)
    p = TrajectoryPlayer(traj, PlayerOptions(go_to_init=True))
    ticks = [p.step(n * TICK_S, start) for n in range(601 + 8)]
    refs = np.array([t.ref_rad[0] for t in ticks])
    assert refs[0] == -0.3  # starts where the robot is
    assert all(t.going_to_init for t in ticks[:600]) and not ticks[600].going_to_init
    assert refs[300] == pytest.approx(-0.3 + 0.8 * 0.5)  # half-way at 1.5 s
    assert refs[600] == 0.5 and ticks[600].line_index == 0  # line 1 at 3 s
    assert ticks[608].line_index == 1  # line 2 one period later
    vel = np.diff(refs[:601]) / TICK_S
    acc = np.diff(vel) / TICK_S
    assert abs(vel[0]) < 1e-4 and abs(vel[-1]) < 1e-4  # starts and ends at rest
    assert np.all(vel >= 0)  # monotonic, no overshoot
    assert vel.max() == pytest.approx(1.875 * 0.8 / 3.0, rel=1e-3)  # min-jerk peak
    assert np.abs(acc).max() < 5.8 * 0.8 / 9.0 * 1.01  # bounded: 5.77·Δ/T² for min-jerk
    assert min_jerk(0.0) == 0.0 and min_jerk(1.0) == 1.0 and min_jerk(0.5) == 0.5


def test_go_to_init_needs_the_current_pose():
    p = TrajectoryPlayer(_ramp(5), PlayerOptions(go_to_init=True))
    with pytest.raises(PlayerOptionError, match="current pose"):
        p.step(0.0)


def test_start_line_plays_from_that_line_and_init_targets_it():
    p = TrajectoryPlayer(_ramp(20), PlayerOptions(start_line=5, rate_hz=25))
    assert p.step(0.0).line_index == 4 and p.step(0.0).line_number == 5
    assert p.step(0.04).line_index == 5
    assert p.duration_s == pytest.approx(16 / 25)
    q = TrajectoryPlayer(_ramp(20), PlayerOptions(start_line=5, go_to_init=True, go_to_init_s=1.0))
    q.step(0.0, np.zeros(N))
    t = q.step(1.0)
    assert t.line_index == 4 and t.ref_rad[0] == pytest.approx(0.04)


# ------------------------------------------------------------------ pause
def test_pause_holds_and_shifts_the_schedule_without_catch_up():
    p = TrajectoryPlayer(_ramp(50), PlayerOptions(rate_hz=25))
    assert p.step(0.0).line_index == 0
    assert p.step(0.1).line_index == 2
    p.pause(0.1)
    held = [p.step(0.1 + k * 0.1) for k in range(11)]  # paused for 1 s
    assert all(t.paused and t.line_index == 2 for t in held)
    p.resume(1.1)
    t = p.step(1.1)
    assert not t.paused and t.line_index == 2  # continues where it stopped
    assert p.step(1.1199).line_index == 2
    assert p.step(1.12).line_index == 3  # line 3 at 0.12 s + 1 s of pause
    assert p.step(1.6).line_index == 15  # floor((1.6 − 1.0)·25), no catch-up


def test_pause_during_go_to_init_freezes_the_blend():
    p = TrajectoryPlayer(_ramp(5) + 1.0, PlayerOptions(go_to_init=True, go_to_init_s=2.0))
    p.step(0.0, np.zeros(N))
    before = p.step(1.0).ref_rad[0]
    assert p.toggle_pause(1.0) is True
    assert p.step(5.0).ref_rad[0] == before
    assert p.toggle_pause(5.0) is False
    assert p.step(5.0).ref_rad[0] == before
    assert p.step(6.0).going_to_init is False


def test_pause_before_start_is_refused():
    with pytest.raises(PlayerStateError):
        TrajectoryPlayer(_ramp(3)).pause(0.0)


# ------------------------------------------------------------------ per-arm modes
SCHEDULE = {
    "left": [(1, 5, "position"), (6, 12, "pwm"), (13, 20, "position")],
    "right": [(1, 20, "position")],
}


def _modes_per_line(player: TrajectoryPlayer, lines: int, ticks_per_line: int = 8):
    seen = {}
    for n in range(lines * ticks_per_line):
        t = player.step(n * TICK_S)
        seen.setdefault(t.line_number, set()).add(
            (
                t.arm_modes["left"],
                t.arm_modes["right"],
                bool(t.comply[LEFT].all()),
                bool(t.comply[LEFT].any()),
                bool(t.comply[RIGHT].all()),
                bool(t.comply[RIGHT].any()),
                int(t.comply.sum()),
            )
        )
    return seen


def test_arm_modes_switch_exactly_at_the_scheduled_lines():
    seen = _modes_per_line(TrajectoryPlayer(_ramp(20), schedule=SCHEDULE), 20)
    for line in range(1, 21):
        pwm = 6 <= line <= 12
        expected = (
            "pwm" if pwm else "position",
            "position",
            pwm,
            pwm,
            False,
            False,
            7 if pwm else 0,
        )
        assert seen[line] == {expected}, line


def test_switch_happens_on_the_first_tick_of_the_line():
    p = TrajectoryPlayer(_ramp(20), schedule=SCHEDULE)
    modes = [p.step(n * TICK_S).arm_modes["left"] for n in range(100)]
    assert modes.index("pwm") == 5 * 8  # line 6 starts at 5/25 s = tick 40
    assert modes.index("position", 40) == 12 * 8  # line 13 at tick 96


def test_flags_override_the_schedule_for_that_arm_only():
    opts = PlayerOptions(compliant_arms=compliant_arms_from_flags(cr=True))
    seen = _modes_per_line(TrajectoryPlayer(_ramp(20), opts, SCHEDULE), 20)
    for line in range(1, 21):
        pwm = 6 <= line <= 12
        assert {s[:2] for s in seen[line]} == {("pwm" if pwm else "position", "pwm")}
    both = TrajectoryPlayer(_ramp(20), PlayerOptions(compliant_arms={"left", "right"}), SCHEDULE)
    assert both.schedule.to_runs() == {"left": [(1, 20, "pwm")], "right": [(1, 20, "pwm")]}
    t = both.step(0.0)
    assert t.comply.sum() == 14 and t.comply[JOINT_INDEX["RWR"]]


def test_schedule_round_trip_and_absent_arm():
    sched = ArmModeSchedule.from_runs({"left": SCHEDULE["left"]}, 20)
    assert sched.to_runs() == SCHEDULE


@pytest.mark.parametrize(
    ("runs", "message"),
    [
        ({"left": [(1, 5, "position"), (7, 10, "pwm")]}, "lines 6..6 are not covered"),
        ({"left": [(1, 5, "position"), (5, 10, "pwm")]}, "overlaps lines already covered up to 5"),
        ({"left": [(1, 8, "position")]}, "left: lines 9..10 are not covered"),
        ({"left": [(1, 10, "stiff")]}, "mode 'stiff' is not one of position, pwm"),
        ({"right": [(1, 11, "pwm")]}, "needs 1 <= first_line <= last_line <= 10"),
        ({"right": [(0, 10, "pwm")]}, "needs 1 <= first_line"),
        ({"right": [(1, 10)]}, "expected \\(first_line, last_line, mode\\)"),
        ({"right": [(1.0, 10, "pwm")]}, "line numbers must be integers"),
        ({"middle": [(1, 10, "pwm")]}, "unknown arm"),
    ],
)
def test_bad_schedules_are_refused(runs, message):
    with pytest.raises(ModeScheduleError, match=message):
        TrajectoryPlayer(_ramp(10), schedule=runs)


def test_schedule_length_must_match():
    with pytest.raises(ModeScheduleError, match="covers 5 lines; the trajectory has 10"):
        TrajectoryPlayer(_ramp(10), schedule=ArmModeSchedule.all_position(5))


# ------------------------------------------------------------------ with the control law
def test_player_drives_the_control_law_through_a_mode_switch():
    """Player → JointController in lock-step: PWM on line 6, rigid return after line 12."""
    traj = np.zeros((20, N))
    p = TrajectoryPlayer(traj, schedule=SCHEDULE)
    c = JointController()
    gains = default_drc_gains()
    pos = np.zeros(N)
    pos[JOINT_INDEX["LSP"]] = 0.1  # the compliant left shoulder is pushed off its reference
    lsp = JOINT_INDEX["LSP"]
    history = []
    for n in range(20 * 8):
        t = p.step(n * TICK_S, pos)
        out = c.tick(t.ref_rad, t.mode, t.comply, pos, np.zeros(N), gains)
        history.append((t.line_number, bool(out.pwm[lsp]), bool(out.returning[lsp])))
    assert {h[1] for h in history if 6 <= h[0] <= 12} == {True}
    assert {h[1] for h in history if h[0] < 6 or h[0] > 12} == {False}
    first_after = next(h for h in history if h[0] == 13)
    assert first_after == (13, False, True)  # leaves PWM into the rigid return


# ------------------------------------------------------------------ feed-forward
def _feedforward(num_lines: int, every: int) -> ArmFeedforward:
    """Row k: LSP = k N·m, RSP = −k N·m (the other arm joints 0)."""
    probe = ArmFeedforward(every, ("LSP", "RSP"), np.zeros((0, 2)))
    k = np.arange(probe.rows_for(num_lines), dtype=float)
    return ArmFeedforward(every, ("LSP", "RSP"), np.stack([k, -k], axis=1))


def test_feedforward_is_interpolated_between_sampled_lines_for_pwm_joints_only():
    ff = _feedforward(20, 4)
    assert len(ff.torque_nm) == 6  # lines 1, 5, 9, 13, 17, 21 ≥ 20
    p = TrajectoryPlayer(_ramp(20), schedule=SCHEDULE, feedforward=ff)
    lsp, rsp = JOINT_INDEX["LSP"], JOINT_INDEX["RSP"]
    seen = {}
    for n in range(20 * 8):
        t = p.step(n * TICK_S)
        seen[t.line_number] = (t.feedforward_nm[lsp], t.feedforward_nm[rsp])
        assert not t.feedforward_nm[~t.comply].any()
    assert seen[6] == pytest.approx((1.25, 0.0))  # row 5 = 5/4 of the way; right arm rigid
    assert seen[9] == pytest.approx((2.0, 0.0))  # a sampled line
    assert seen[12] == pytest.approx((2.75, 0.0))
    assert seen[13] == (0.0, 0.0)  # left arm back in position mode
    both = TrajectoryPlayer(_ramp(20), PlayerOptions(compliant_arms={"left", "right"}),
                            feedforward=ff)
    both.step(0.0)
    assert both.step(19 / 25).feedforward_nm[rsp] == pytest.approx(-19 / 4)  # line 20


def test_feedforward_is_off_during_go_to_init_and_velocity_is_the_filtered_references():
    ff = _feedforward(200, 4)
    opts = PlayerOptions(go_to_init=True, compliant_arms={"left"})
    p = TrajectoryPlayer(_ramp(200), opts, feedforward=ff)
    t = p.step(0.0, np.zeros(N))
    assert t.going_to_init and not t.feedforward_nm.any() and not t.velocity_rad_s.any()
    ticks = [p.step(3.0 + n * TICK_S) for n in range(120 * 8)]
    assert ticks[2 * 8].line_number == 3
    assert ticks[2 * 8].feedforward_nm[JOINT_INDEX["LSP"]] == pytest.approx(0.5)
    # The daemon's filter (L = 40) smooths the 0.01 rad steps of each 25 Hz line: in steady
    # state its velocity averages the file's 0.25 rad/s over a line, and it never jumps.
    v = np.array([t.velocity_rad_s[0] for t in ticks])
    assert v[100 * 8:101 * 8].mean() == pytest.approx(0.25, rel=1e-3)
    assert np.abs(np.diff(v)).max() < 0.01 / 40 / TICK_S + 1e-9
    p.pause(3.0 + 120 * 8 * TICK_S)
    assert not p.step(3.0 + 121 * 8 * TICK_S).velocity_rad_s.any()


def test_a_pwm_arm_with_feedforward_keeps_tracking_its_reference():
    """hubo-ach's law for a compliant arm, hand on the rail or not: stiffness towards the
    reference plus the feed-forward. Mode COMPLIANT (f = pos) would leave it the
    feed-forward alone and no stiffness to hold the pose the closed chain leaves free."""
    p = TrajectoryPlayer(_ramp(20), schedule=SCHEDULE, feedforward=_feedforward(20, 4))
    ticks = [p.step(n * TICK_S) for n in range(20 * 8)]
    lsp = JOINT_INDEX["LSP"]
    pwm = [t for t in ticks if t.comply[lsp]]
    assert {t.line_number for t in pwm} == set(range(6, 13))
    assert any(t.feedforward_nm[lsp] > 0 for t in pwm)
    assert all((t.mode == RefMode.FILTER).all() for t in ticks)


def test_feedforward_must_cover_the_file():
    with pytest.raises(ModeScheduleError,
                       match="feed-forward has 6 rows; 40 lines every 4 need 11"):
        TrajectoryPlayer(_ramp(40), feedforward=_feedforward(20, 4))
