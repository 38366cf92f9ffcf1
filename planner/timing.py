"""Time-parameterising the planner's dense paths into trajectory-file lines (toppra).

Each segment of a plan is a dense path of configurations (consecutive ones within the
planner's resolution). Its 40 file columns are fitted with a cubic spline over the
cumulative joint-space distance ``s`` [rad], time-optimally parameterised by toppra
under the robot's nominal joint velocity and acceleration limits (scaled by
`TimingConfig.limit_scale`, because sampling the result at 200 Hz slightly exceeds the
limits it was given), and sampled at the file rate. toppra starts and stops each segment
at zero path speed, so segments join at rest without a velocity jump. The samples are
checked against the unscaled limits; if they break one, the segment is timed again on
a grid twice as fine with limits `RETRY_SCALE` times lower (up to
`TimingConfig.retries` times), then `TimingError` is raised.

toppra enforces the limits only at its grid points. The planner's dense paths are
projected by IK point by point and can kink; with one grid point per path point the
sampled acceleration of a real placeHands swing reached 2.8× the limit, with two 1.14×,
with four 0.95×.

After each step (a stance change) the last line is repeated for a quasi-static dwell.

Every output line keeps the index of the segment it came from, whether it is a dwell
line, and a full configuration (floating base included, interpolated along ``s`` like
the joints), which the sidecar's mode schedule needs for palm-to-rail distances.

Size: one pipeline (spline fit, toppra, its fall-backs when the LP fails, sampling
at the file rate, the limit check of the sampled lines) whose stages pass each other
toppra's intermediate objects.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from robot.constants import DAEMON_RATE_HZ
from robot.errors import HuboLadderError
from robot.joints import JOINT_NAMES, NUM_JOINTS
from robot.limits import JointLimits

log = logging.getLogger(__name__)

#: Spline end conditions. "clamped" (zero dq/ds at the ends) bends an arc-length path
#: into a hook at each end whose curvature toppra only sees at grid points: sampled
#: accelerations then exceeded the limit by 14 %. The ends are at rest anyway, because
#: toppra starts and stops with zero path speed.
BC_TYPE = "not-a-knot"
#: A path turning by more than this at a point stops there: timed rest to rest [deg].
CORNER_DEG = 30.0
#: Width of the moving average that rounds off a dense IK path's kinks [points].
PATH_SMOOTH_POINTS = 9
#: Spacing of the spline's knots along a dense path [rad of joint-space path].
KNOT_SPACING_RAD = 0.05
#: Width of the moving average that smooths a joint where it was clipped [samples].
SMOOTH_SAMPLES = 15
#: Limit scale factor applied on each retry.
RETRY_SCALE = 0.95

__all__ = ["SegmentPath", "TimedPlan", "TimingConfig", "TimingError", "default_config",
           "time_parameterize"]


class TimingError(HuboLadderError):
    """toppra found no parameterisation, or the sampled file breaks a joint limit."""


@dataclass(frozen=True)
class TimingConfig:
    """Tunables of the time parameterisation.

    Attributes:
        rate_hz: file rate: one line every 1 / rate_hz s [Hz].
        dwell_s: quasi-static hold after each step [s].
        limit_scale: fraction of the nominal velocity and acceleration limits given to
            toppra (the samples are checked against the unscaled limits).
        min_motion_rad: a segment whose path is shorter than this is skipped [rad].
        tolerance: relative slack of the sample check (float rounding only).
        grid_subdivision: toppra grid points per interval between path points; toppra
            meets the limits at grid points only, and a kink in a dense IK path bends
            the spline sharply between two of them.
        retries: re-timings (grid twice as fine, limits `RETRY_SCALE` lower) when the
            samples break a limit.
    """

    rate_hz: float = DAEMON_RATE_HZ
    dwell_s: float = 0.5
    limit_scale: float = 0.9
    min_motion_rad: float = 1e-9
    tolerance: float = 1e-6
    grid_subdivision: int = 2
    retries: int = 3


def default_config() -> TimingConfig:
    """The default timing tunables (200 Hz, 0.5 s dwell, limits ×0.9)."""
    return TimingConfig()


@dataclass
class SegmentPath:
    """One segment's dense path, ready for timing.

    Attributes:
        label: how messages name the segment, e.g. ``moveLHand@rung2/limb``.
        columns_rad: (M, 40) file columns of the path, its start point included [rad].
        configs: (M, nq) full configurations matching ``columns_rad`` (pinocchio layout:
            base xyz [m], base quaternion x y z w, joints [rad]), or None.
        dwell_after: hold the last line for ``dwell_s`` after this segment (end of a step).
        velocity_max_rad_s: (40,) velocity limits of this segment [rad/s], below the
            nominal ones (e.g. a compliant arm on its rail); the nominal ones when None.
    """

    label: str
    columns_rad: np.ndarray = field(repr=False)
    configs: np.ndarray | None = field(default=None, repr=False)
    dwell_after: bool = False
    velocity_max_rad_s: np.ndarray | None = field(default=None, repr=False)

    def velocity_limits(self, limits: JointLimits) -> np.ndarray:
        """The velocity limits this segment is timed with [rad/s]."""
        nominal = limits.velocity_nominal_rad_s
        return nominal if self.velocity_max_rad_s is None else np.minimum(
            nominal, self.velocity_max_rad_s)


@dataclass
class TimedPlan:
    """The sampled trajectory and where each line came from.

    Attributes:
        rate_hz: file rate [Hz].
        columns_rad: (N, 40) lines of the trajectory file [rad].
        configs: (N, nq) full configuration of each line, or None when the input paths
            carried none.
        segment_of_line: (N,) index into the input segment list of each line.
        dwell: (N,) True for the quasi-static dwell lines after a step.
        durations_s: segment index → time its motion takes [s] (skipped segments absent).
        skipped: indices of segments with no motion (no lines).
    """

    rate_hz: float
    columns_rad: np.ndarray = field(repr=False)
    configs: np.ndarray | None = field(repr=False)
    segment_of_line: np.ndarray = field(repr=False)
    dwell: np.ndarray = field(repr=False)
    durations_s: dict[int, float] = field(default_factory=dict)
    skipped: list[int] = field(default_factory=list)

    @property
    def line_count(self) -> int:
        return len(self.columns_rad)

    @property
    def duration_s(self) -> float:
        """Playing time of the file, first line at t = 0 [s]."""
        return (self.line_count - 1) / self.rate_hz

    def __repr__(self) -> str:
        return (f"TimedPlan({self.line_count} lines at {self.rate_hz:g} Hz = "
                f"{self.duration_s:.2f} s, {len(self.durations_s)} segments timed, "
                f"{len(self.skipped)} skipped, {int(self.dwell.sum())} dwell lines)")


def _toppra_trajectory(s: np.ndarray, columns: np.ndarray, v_max: np.ndarray,
                       a_max: np.ndarray, subdivision: int = 1):
    """toppra's time-optimal parameterisation of the spline through ``columns`` over ``s``,
    on a grid of ``subdivision`` points per interval between path points.

    Returns:
        The ``ParametrizeConstAccel`` trajectory, or None when toppra found none (toppra
        reports failure by returning None).
    """
    import toppra as ta
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    path = ta.SplineInterpolator(s, columns, bc_type=BC_TYPE)
    # At least as fine as the path's own points: constraints hold on the grid only.
    base = np.union1d(s, np.linspace(s[0], s[-1], 101))
    base = base[np.concatenate([[True], np.diff(base) > 1e-9])]  # toppra: strictly increasing
    base[-1] = s[-1]
    steps = np.arange(subdivision) / subdivision
    grid = np.append((base[:-1, None] + np.diff(base)[:, None] * steps).ravel(), base[-1])
    try:
        inst = algo.TOPPRA([constraint.JointVelocityConstraint(v_max),
                            constraint.JointAccelerationConstraint(a_max)], path,
                           gridpoints=grid, parametrizer="ParametrizeConstAccel")
    except ValueError as exc:  # toppra refuses a grid it finds degenerate: try another
        log.info("toppra refused the grid of a %d-knot path: %s", len(s), exc)
        return None
    return inst.compute_trajectory(0, 0)


class _TrapezoidTrajectory:
    """Rest-to-rest trapezoidal timing along a spline q(s): the fallback when toppra's LP
    solver finds a path numerically uncontrollable.

    Path speed ṡ ≤ V and |s̈| ≤ A are uniform bounds chosen so that every joint meets
    |q'·ṡ| ≤ v and |q'·s̈ + q''·ṡ²| ≤ a everywhere on a fine grid: half of each joint's
    acceleration budget goes to the path's curvature at speed V, half to speeding up.
    Slower than time-optimal, which a quasi-static climb does not need; always feasible.
    """

    def __init__(self, s: np.ndarray, way: np.ndarray, v_max: np.ndarray, a_max: np.ndarray):
        from scipy.interpolate import CubicSpline

        self.spline = CubicSpline(s, way, bc_type=BC_TYPE, axis=0)
        grid = np.linspace(s[0], s[-1], max(200, 20 * len(s)))
        d1 = np.abs(self.spline(grid, 1)).max(axis=0)
        d2 = np.abs(self.spline(grid, 2)).max(axis=0)
        with np.errstate(divide="ignore"):
            v_path = np.min(np.where(d1 > 1e-12, v_max / d1, np.inf))
            v_curv = np.min(np.where(d2 > 1e-12, np.sqrt(0.5 * a_max / d2), np.inf))
            a_path = np.min(np.where(d1 > 1e-12, 0.5 * a_max / d1, np.inf))
        self.V, self.A = float(min(v_path, v_curv)), float(a_path)
        self.length = float(s[-1] - s[0])
        self.s0 = float(s[0])
        t_ramp = self.V / self.A
        if self.A * t_ramp**2 >= self.length:  # triangular profile: never reaches V
            t_ramp = math.sqrt(self.length / self.A)
            self.V = self.A * t_ramp
        self.t_ramp = t_ramp
        self.duration = 2 * t_ramp + (self.length - self.A * t_ramp**2) / self.V

    def _eval_params(self, ts: np.ndarray):
        ts = np.asarray(ts, dtype=float)
        tr, A, V, T = self.t_ramp, self.A, self.V, self.duration
        s = np.where(ts < tr, 0.5 * A * ts**2,
                     np.where(ts > T - tr, self.length - 0.5 * A * (T - ts) ** 2,
                              0.5 * A * tr**2 + V * (ts - tr)))
        return self.s0 + np.clip(s, 0.0, self.length), None, None

    def __call__(self, ts: np.ndarray) -> np.ndarray:
        return self.spline(self._eval_params(ts)[0])


def _path_parameter(columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cumulative joint-space distance ``s`` [rad] and the indices of the points kept
    (points that do not move from their predecessor are dropped: ``s`` must increase)."""
    step = np.linalg.norm(np.diff(columns, axis=0), axis=1)
    keep = np.concatenate([[True], step > 1e-12])
    s = np.concatenate([[0.0], np.cumsum(step)])[keep]
    return s, np.flatnonzero(keep)


def _interpolate_configs(s_way: np.ndarray, configs: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Configurations at path parameters ``s``: piecewise linear between the dense
    configurations, the base quaternion normalised (neighbours differ by a few mrad)."""
    out = np.empty((len(s), configs.shape[1]))
    for j in range(configs.shape[1]):
        out[:, j] = np.interp(s, s_way, configs[:, j])
    quat = out[:, 3:7]
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    return out


def _check_samples(label: str, lines: np.ndarray, rate_hz: float, limits: JointLimits,
                   tol: float, velocity_max_rad_s: np.ndarray | None = None) -> None:
    """Finite-difference velocity and acceleration of sampled lines against the limits
    (``velocity_max_rad_s``: the segment's velocity limits; the nominal ones if None)."""
    v_max = limits.velocity_nominal_rad_s if velocity_max_rad_s is None else velocity_max_rad_s
    for order, limit, verb, unit in ((1, v_max, "moves", "rad/s"),
                                     (2, limits.accel_nominal_rad_s2, "accelerates", "rad/s²")):
        if len(lines) <= order:
            return
        rate = np.abs(np.diff(lines, n=order, axis=0)) * rate_hz**order
        ratio = rate / limit
        if ratio.max() > 1.0 + tol:
            k, j = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
            raise TimingError(f"segment {label}: sample {k + 1} {verb} {JOINT_NAMES[j]} at "
                              f"{rate[k, j]:.4g} {unit}, above its limit "
                              f"{limit[j]:.4g} {unit}")


def _box(x: np.ndarray, width: int) -> np.ndarray:
    """Moving average of ``width`` samples, the ends padded with the end values."""
    pad = width // 2
    xp = np.concatenate([np.full(pad, x[0]), x, np.full(pad, x[-1])])
    c = np.cumsum(np.concatenate([[0.0], xp]))
    return (c[width:] - c[:-width]) / width


def _fade_weight(n: int, ramp: int) -> np.ndarray:
    """0 at both ends of n samples, 1 inside, a smoothstep over ``ramp`` samples."""
    u = np.clip(np.minimum(np.arange(n), np.arange(n)[::-1]) / max(ramp, 1), 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def _smooth_path(way: np.ndarray, width: int) -> np.ndarray:
    """The dense IK path with its kinks rounded off before time parameterisation.

    Points projected one by one by IK can change direction abruptly; a spline through them
    turns that into curvature spikes between toppra's grid points, and the sampled file
    then broke the acceleration limit by half. A triangular moving average (``width``
    points, 0.01 rad apart, twice) rounds them off. The ends stay exact (stance changes
    join bit for bit). Joints move by a few mrad: far inside the 1 cm hold tolerance that
    ``check-plan`` verifies on the written file.
    """
    if width < 2 or len(way) < 3:
        return way
    weight = _fade_weight(len(way), width)[:, None]
    smooth = np.column_stack([_box(_box(way[:, j], width), width) for j in range(way.shape[1])])
    return way + weight * (smooth - way)


def _limit_positions(lines: np.ndarray, limits: JointLimits) -> np.ndarray:
    """Samples within the joint position limits.

    Where the IK path rides a joint limit, the spline through it rings past the limit
    (by up to 0.8 mrad on a real foot swing). Clipping alone leaves corners whose
    finite-difference acceleration reached 5× the limit, so a clipped joint is then
    smoothed over the whole segment by a triangular moving average (`SMOOTH_SAMPLES`
    wide, twice). An average of samples within the limits stays within them, and its
    speed and acceleration are averages of the clipped ones. On the mount's foot swings
    it moved the joint by at most 0.45 mrad; 9 samples left 1.09× the acceleration
    limit. Smoothing only near the clipped samples left a step where the smoothed part
    met the rest. The smoothing fades out towards the segment's ends
    (3 × `SMOOTH_SAMPLES`), which stay exact; the result is a convex combination of
    clipped samples, so within the limits.
    """
    clipped = np.clip(lines, limits.lower_rad, limits.upper_rad)
    hit = np.any(clipped != lines, axis=0)
    if not hit.any() or len(lines) < 3:
        return clipped
    # Blend weight: 0 at both ends (exact, at rest), 1 inside, a smoothstep in between.
    weight = _fade_weight(len(lines), 3 * SMOOTH_SAMPLES)
    out = clipped.copy()
    for j in np.flatnonzero(hit):
        smooth = _box(_box(clipped[:, j], SMOOTH_SAMPLES), SMOOTH_SAMPLES)
        out[:, j] = clipped[:, j] + weight * (smooth - clipped[:, j])
    return out


def _knot_indices(length_rad: float, n_points: int, spacing_rad: float) -> np.ndarray:
    """Indices of evenly spread knots about ``spacing_rad`` of path apart (at least 4,
    at most every point) among ``n_points`` dense path points."""
    n_knots = int(min(n_points, max(4, math.ceil(length_rad / spacing_rad) + 1)))
    return np.unique(np.round(np.linspace(0, n_points - 1, n_knots)).astype(int))


def _time_segment(seg: SegmentPath, limits: JointLimits, cfg: TimingConfig
                  ) -> tuple[np.ndarray, np.ndarray | None, float] | None:
    """Sampled lines of one segment (its start point first), their configurations and
    its duration [s]; None when the segment does not move."""
    cols = np.asarray(seg.columns_rad, dtype=float)
    if cols.ndim != 2 or cols.shape[1] != NUM_JOINTS:
        raise ValueError(f"segment {seg.label}: expected (M, {NUM_JOINTS}) columns, "
                         f"got shape {cols.shape}")
    s_all, kept = _path_parameter(cols)
    if len(s_all) < 2 or s_all[-1] < cfg.min_motion_rad:
        return None
    way = _smooth_path(cols[kept], PATH_SMOOTH_POINTS)
    scale, sub = cfg.limit_scale, cfg.grid_subdivision
    v_max = seg.velocity_limits(limits)
    for attempt in range(cfg.retries + 1):
        traj = None
        # The spline runs through knots about KNOT_SPACING_RAD of path apart, not through
        # every dense IK point (0.01 rad apart): through all of them toppra's LP solver
        # found the path numerically uncontrollable at times. Between corners the dense
        # path is smooth, so the spline strays from the dropped points by little; a
        # coarser or finer grid is tried when toppra still fails.
        for spacing in KNOT_SPACING_RAD * np.array([1.0, 0.8, 2.0, 0.6, 1.4, 4.0, 0.4]):
            idx = _knot_indices(s_all[-1], len(way), spacing)
            for grid_sub in (sub, 1, 3):
                traj = _toppra_trajectory(s_all[idx], way[idx], scale * v_max,
                                          scale * limits.accel_nominal_rad_s2, grid_sub)
                if traj is not None:
                    break
            if traj is not None:
                break
        if traj is None:
            log.info("%s: toppra found no parameterisation; timing it with a conservative "
                     "trapezoid", seg.label)
            idx = _knot_indices(s_all[-1], len(way), KNOT_SPACING_RAD)
            traj = _TrapezoidTrajectory(s_all[idx], way[idx], scale * v_max,
                                        scale * limits.accel_nominal_rad_s2)
        duration = float(traj.duration)
        n = max(1, math.ceil(duration * cfg.rate_hz - 1e-9))
        # n equal steps of duration / n ≤ 1 / rate: played at the file rate, the motion
        # is never faster than toppra's.
        ts = np.linspace(0.0, duration, n + 1)
        s_t, _, _ = traj._eval_params(ts)  # path parameter of each sample (toppra internal)
        s_t = np.clip(s_t, 0.0, s_all[-1])
        lines = np.asarray(traj(ts), dtype=float)
        lines[0], lines[-1] = way[0], way[-1]  # exact ends: segments join bit for bit
        lines = _limit_positions(lines, limits)
        try:
            _check_samples(seg.label, lines, cfg.rate_hz, limits, cfg.tolerance, v_max)
            break
        except TimingError as exc:
            if attempt == cfg.retries:
                raise
            scale, sub = scale * RETRY_SCALE, 2 * sub
            log.debug("%s; timing again on a %d× grid with limits ×%.3g", exc, sub, scale)
    configs = None
    if seg.configs is not None:
        configs = _interpolate_configs(s_all, np.asarray(seg.configs, dtype=float)[kept], s_t)
    return lines, configs, duration


def _corner_indices(cols: np.ndarray) -> list[int]:
    """Points where the path turns by more than `CORNER_DEG` (way-point junctions, where
    the moving limb changes direction, and the snap onto a hold)."""
    d = np.diff(cols, axis=0)
    norm = np.linalg.norm(d, axis=1)
    moving = np.flatnonzero(norm > 1e-12)
    corners = []
    for a, b in zip(moving[:-1], moving[1:], strict=True):
        cos = float(d[a] @ d[b] / (norm[a] * norm[b]))
        if cos < math.cos(math.radians(CORNER_DEG)):
            corners.append(int(b))  # the point between step a and step b
    return corners


def _time_segment_at_corners(seg: SegmentPath, limits: JointLimits, cfg: TimingConfig
                             ) -> tuple[np.ndarray, np.ndarray | None, float] | None:
    """Time a segment piece by piece between its corners, each piece rest to rest.

    A quasi-static climber stops where its path turns sharply; a spline through such a
    corner must overshoot it, and the sampled file then broke the acceleration limit.
    """
    cols = np.asarray(seg.columns_rad, dtype=float)
    cuts = [0] + _corner_indices(cols) + [len(cols) - 1]
    if len(cuts) == 2:
        return _time_segment(seg, limits, cfg)
    lines, confs, total = [], [], 0.0
    for k, (a, b) in enumerate(zip(cuts[:-1], cuts[1:], strict=True)):
        piece = SegmentPath(f"{seg.label}#{k}", cols[a:b + 1],
                            None if seg.configs is None else
                            np.asarray(seg.configs, dtype=float)[a:b + 1], False,
                            seg.velocity_max_rad_s)
        timed = _time_segment(piece, limits, cfg)
        if timed is None:
            continue
        p_lines, p_confs, duration = timed
        if lines:  # the shared corner is already the last line
            p_lines = p_lines[1:]
            p_confs = None if p_confs is None else p_confs[1:]
        lines.append(p_lines)
        confs.append(p_confs)
        total += duration
    if not lines:
        return None
    configs = None if seg.configs is None else np.vstack(confs)
    return np.vstack(lines), configs, total


def time_parameterize(segments: Sequence[SegmentPath], limits: JointLimits,
                      config: TimingConfig | None = None,
                      q_index_of_column: np.ndarray | None = None) -> TimedPlan:
    """Time every segment and concatenate the samples into file lines.

    Consecutive segments must join: each one's first point is the previous one's last.
    The first segment's first point becomes line 1; every later segment contributes its
    samples after that shared point.

    Args:
        segments: the plan's segments, in order.
        limits: the robot's joint limits (nominal velocity [rad/s] and acceleration
            [rad/s²] are used, and positions bound the spline's overshoot).
        config: rate, dwell and limit scale; `default_config()` if None.
        q_index_of_column: (40,) index into a configuration of each column (-1 for none);
            with it, the joints of each line's configuration are the sampled columns
            themselves rather than interpolated.

    Returns:
        The timed plan.

    Raises:
        TimingError: toppra found no parameterisation of a segment, or its samples
            exceed a nominal limit; the message names the segment.
    """
    cfg = config or default_config()
    if cfg.rate_hz <= 0 or cfg.dwell_s < 0:
        raise ValueError(f"rate must be > 0 Hz and dwell ≥ 0 s, got {cfg.rate_hz}, "
                         f"{cfg.dwell_s}")
    n_dwell = math.ceil(cfg.dwell_s * cfg.rate_hz - 1e-9)
    lines: list[np.ndarray] = []
    confs: list[np.ndarray] = []
    seg_of: list[np.ndarray] = []
    dwell: list[np.ndarray] = []
    durations: dict[int, float] = {}
    skipped: list[int] = []
    have_configs = all(s.configs is not None for s in segments)
    for i, seg in enumerate(segments):
        timed = _time_segment_at_corners(seg, limits, cfg)
        if timed is None:
            skipped.append(i)
            log.debug("segment %s does not move: skipped", seg.label)
            if not lines:  # the plan starts here: keep its (only) point as line 1
                cols = np.asarray(seg.columns_rad, dtype=float)[:1]
                timed = (cols, None if seg.configs is None
                         else np.asarray(seg.configs, dtype=float)[:1], 0.0)
            else:
                timed = (np.empty((0, NUM_JOINTS)), None, 0.0)
        else:
            durations[i] = timed[2]
        seg_lines, seg_confs, _ = timed
        if lines and len(seg_lines):
            seg_lines = seg_lines[1:]  # the shared start point is already the last line
            seg_confs = None if seg_confs is None else seg_confs[1:]
        if len(seg_lines):
            lines.append(seg_lines)
            seg_of.append(np.full(len(seg_lines), i))
            dwell.append(np.zeros(len(seg_lines), dtype=bool))
            if have_configs:
                confs.append(seg_confs)
        if seg.dwell_after and n_dwell and lines:
            lines.append(np.repeat(lines[-1][-1:], n_dwell, axis=0))
            seg_of.append(np.full(n_dwell, i))
            dwell.append(np.ones(n_dwell, dtype=bool))
            if have_configs:
                confs.append(np.repeat(confs[-1][-1:], n_dwell, axis=0))
    if not lines:
        raise TimingError("the plan has no configurations to time")
    columns = np.vstack(lines)
    configs = None
    if have_configs:
        configs = np.vstack(confs)
        if q_index_of_column is not None:
            have = np.asarray(q_index_of_column) >= 0
            configs[:, np.asarray(q_index_of_column)[have]] = columns[:, have]
    # The joins (segment ends, dwells) are checked with the whole file.
    _check_samples("joins", columns, cfg.rate_hz, limits, cfg.tolerance)
    return TimedPlan(cfg.rate_hz, columns, configs, np.concatenate(seg_of),
                     np.concatenate(dwell), durations, skipped)
