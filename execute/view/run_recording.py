"""A simulated run's recording (``validate-plan --record``), from the run in memory.

The timeline is the simulated time. It holds:

- the simulated robot (``world/sim/robot``), from the run log's qpos through MuJoCo's
  forward kinematics on the board model's own scene (the ladder where it was placed);
- the plan's ghost (``world/plan``, translucent), at the line the player was playing,
  with the plan's segments, holds, CoM, support regions and hold forces
  (`execute.view.plan_layers`);
- the grips' loads as arrows at the palms (the latch's load history, every 0.1 s while
  latched), and the simulated CoM;
- events: grasps, board trips, the motion layer's corrections, the failure;
- per joint, the tracking error (pos − ref) and the torque, as time series (the
  fingers' under ``sim/fingers``).

Display thins the 200 Hz log to `DISPLAY_EVERY_S` for the 3D poses; the series keep, in
each display interval, the sample of largest magnitude, so no spike is lost.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import rerun as rr

from daemon.sim.board_model import TICK_S
from execute.view.layout import blueprint
from execute.view.output import open_file
from execute.view.plan_layers import PlanLayers, log_plan
from execute.view.plan_poses import PlanKinematics, body_poses
from execute.view.recording import (
    TIMELINE,
    log_event,
    log_robot,
    log_scalars,
    log_static_bodies,
    log_track,
    robot_bodies,
    time_column,
)
from execute.view.scene_meshes import body_meshes
from robot.joints import FINGER_JOINTS, JOINT_NAMES

__all__ = ["GHOST_RGBA", "RUN_SERIES", "peak_samples", "record_run", "write_run_recording"]

#: The plan's ghost beside the simulated robot.
GHOST_RGBA = (90, 150, 255, 90)
SIM_COM_RGB = (20, 20, 20)
#: Grip loads are drawn this long per newton [m/N], this thick [m], in this colour.
GRIP_M_PER_N = 0.002
GRIP_RADIUS_M = 0.006
GRIP_RGB = (255, 120, 0)
#: The plots of a run's recording: (entity, title).
RUN_SERIES = (("/sim/tracking_error_rad", "tracking error pos − ref [rad] (fingers apart)"),
              ("/sim/torque_nm", "joint torque [N·m] (fingers apart)"),
              ("/plan/stability_margin_cm", "plan: CoM margin in its support region [cm]"))


def peak_samples(values: np.ndarray, step: int) -> np.ndarray:
    """(T, J) → (ceil(T / step), J): in each window of ``step`` rows, the value of
    largest magnitude, per column."""
    T = len(values)
    k = -(-T // step)
    padded = np.concatenate([values, np.repeat(values[-1:], k * step - T, axis=0)])
    windows = padded.reshape(k, step, *values.shape[1:])
    pick = np.abs(windows).argmax(axis=1)
    return np.take_along_axis(windows, pick[:, None], axis=1)[:, 0]


def _first_time_of_row(line_index: np.ndarray, time_s: np.ndarray):
    """When the player first reached each line (None: never)."""
    reached = np.maximum.accumulate(line_index)

    def time_of_row(row: int) -> float | None:
        k = int(np.searchsorted(reached, row))
        return None if k >= len(reached) else float(time_s[k])

    return time_of_row


def _log_grips(rec: rr.RecordingStream, run, model: mujoco.MjModel) -> None:
    """Each latched grip's load (the rail's force on the hand) as an arrow at its palm,
    one column batch per hand (a whole climb has tens of thousands of samples)."""
    lg = run.log
    data = mujoco.MjData(model)
    for side, latch in run.board.latches.items():
        path = f"world/sim/grip_forces/{side}"
        site = model.site(f"{side[0].upper()}_palm").id
        if latch.load_history:
            times = np.array([t for t, _, _ in latch.load_history])
            forces = np.array([f for _, f, _ in latch.load_history])
            ticks = np.minimum(np.searchsorted(lg.time_s, times), len(lg.time_s) - 1)
            palms = np.empty((len(ticks), 3))
            for i, k in enumerate(ticks):
                data.qpos[:] = lg.qpos[k]
                mujoco.mj_kinematics(model, data)
                palms[i] = data.site_xpos[site]
            rec.send_columns(path, indexes=[time_column(times)], columns=rr.Arrows3D.columns(
                origins=palms, vectors=GRIP_M_PER_N * forces,
                labels=[f"{n:.0f} N" for n in np.linalg.norm(forces, axis=1)],
                colors=np.tile(GRIP_RGB, (len(times), 1)),
                radii=np.full(len(times), GRIP_RADIUS_M)))
        for g in lg.grasps:  # a hand that lets go carries no load
            if g.hand == side and g.kind != "latched":
                rec.set_time(TIMELINE, duration=g.time_s)
                rec.log(path, rr.Clear(recursive=False))


def _log_events(rec: rr.RecordingStream, run) -> None:
    """Grasps, trips, the motion layer's events and the failure, as text events."""
    warn, error = rr.TextLogLevel.WARN, rr.TextLogLevel.ERROR
    for g in run.log.grasps:
        log_event(rec, "events/grasp", g.time_s, str(g),
                  rr.TextLogLevel.INFO if g.kind == "latched" else warn)
    for trip in run.log.trips:
        log_event(rec, "events/trip", trip.time_s, str(trip), error)
    for e in (run.motion or {}).get("events", []):
        log_event(rec, "events/motion", e["time_s"], f"{e['kind']}: {e.get('cause', '')}")
    f = run.verdict.failure
    if f is not None:
        log_event(rec, "events/failure", f.time_s,
                  f"failed ({f.cause.value}) at line {f.line:,}: {f.why}", error)
    else:
        log_event(rec, "events/verdict", run.simulated_s, "climbed: every final hold in "
                  "contact")


def _log_series(rec: rr.RecordingStream, run, step: int) -> None:
    """Per joint, the tracking error and the torque, peak-preserving per display step;
    the fingers apart (``sim/fingers/...``: a finger closed on a rail stays a radian
    short of its reference, which would flatten the other joints' plots)."""
    lg = run.log
    times = lg.time_s[::step]
    err = peak_samples(lg.pos_rad - lg.ref_rad, step)
    tau = peak_samples(lg.torque_nm, step)
    fingers = {n for hand in FINGER_JOINTS.values() for n in hand}
    for j, name in enumerate(JOINT_NAMES):
        group = "sim/fingers" if name in fingers else "sim"
        log_scalars(rec, f"{group}/tracking_error_rad/{name}", times, err[:, j], name)
        log_scalars(rec, f"{group}/torque_nm/{name}", times, tau[:, j], name)


def record_run(rec: rr.RecordingStream, run, trajectory_rad: np.ndarray, ladder,
               layers: PlanLayers | None = None, verifier=None) -> None:
    """Log a simulated run (an `execute.validate.simulate.SimulationRun` that kept its
    qpos) beside its plan's ghost.

    Args:
        trajectory_rad: the plan's (N, 40) lines [rad].
        ladder: the ladder the plan was made for (the ghost's frame).
        layers: what to draw of the plan, and how densely.
        verifier: the plan's `planner.verify.check.PlanVerifier`, if the caller has one
            (its stances' support regions are reused); built here if None.
    """
    layers = layers or PlanLayers()
    lg = run.log
    if lg.qpos is None or not len(lg.qpos):
        raise ValueError("the run kept no qpos (SimulationOptions.record_qpos=False)")
    step = max(1, round(layers.display_every_s / TICK_S))
    ticks = np.arange(0, len(lg.time_s), step)
    times = lg.time_s[ticks]
    model = run.board.model
    meshes = body_meshes(model)
    log_static_bodies(rec, "world", model, meshes)
    pos, quat = body_poses(model, lg.qpos[ticks])
    log_robot(rec, "world/sim/robot", robot_bodies(model, meshes), times, pos, quat)
    log_track(rec, "world/sim/com", times, lg.com_m[ticks], SIM_COM_RGB)
    kin = PlanKinematics(trajectory_rad, run.sidecar, ladder, verifier=verifier)
    log_plan(rec, kin, lg.line_index[ticks].astype(int), times,
             _first_time_of_row(lg.line_index, lg.time_s), layers, tint_rgba=GHOST_RGBA)
    _log_grips(rec, run, model)
    _log_series(rec, run, step)
    _log_events(rec, run)
    f = run.verdict.failure
    rec.send_blueprint(blueprint(RUN_SERIES, None if f is None else f.time_s))


def write_run_recording(run, trajectory_rad: np.ndarray, ladder, path: str | Path,
                        layers: PlanLayers | None = None, verifier=None) -> Path:
    """`record_run` into the file ``path`` (``.rrd``); returns the path."""
    rec = open_file(path)
    record_run(rec, run, trajectory_rad, ladder, layers, verifier)
    rec.flush()
    return Path(path)
