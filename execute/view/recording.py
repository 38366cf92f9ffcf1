"""Our things as Rerun entities: the scene, a robot moving, tracks, series and events.

Every time-varying entity is on one timeline, ``time`` (a duration [s]): the plan's time
(line / rate) for a plan, the simulated time for a run. Large arrays go in as columns
(`rerun.send_columns`), one call per entity, so a whole climb logs in well under a second.

Entity paths (`docs/viewer.md` lists them all): ``world/...`` is 3D, in metres, z up;
``events/...`` text events; ``plan/...`` and ``sim/...`` time series.
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np
import rerun as rr

from execute.view.scene_meshes import BodyMesh

__all__ = ["TIMELINE", "log_event", "log_robot", "log_scalars", "log_static_bodies",
           "log_track", "robot_bodies", "time_column"]

#: The one timeline of a recording (a duration [s]).
TIMELINE = "time"


def time_column(times_s: np.ndarray) -> rr.TimeColumn:
    """The ``time`` index of a column batch [s]."""
    return rr.TimeColumn(TIMELINE, duration=np.asarray(times_s, dtype=float))


def robot_bodies(model: mujoco.MjModel, meshes: Sequence[BodyMesh]) -> list[BodyMesh]:
    """The meshes of the bodies that move (the robot's: every body not welded to the
    world)."""
    return [m for m in meshes if model.body_weldid[m.body] != 0]


def log_static_bodies(rec: rr.RecordingStream, root: str, model: mujoco.MjModel,
                      meshes: Sequence[BodyMesh]) -> None:
    """The bodies that never move (floor, ladder), static, at their place in ``model``."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    for m in meshes:
        if model.body_weldid[m.body] != 0:
            continue
        path = f"{root}/{m.name}"
        q = data.xquat[m.body]
        rec.log(path, rr.Transform3D(translation=data.xpos[m.body],
                                     quaternion=[q[1], q[2], q[3], q[0]]), static=True)
        rec.log(path, rr.Mesh3D(vertex_positions=m.vertices_m, triangle_indices=m.faces,
                                vertex_normals=m.normals, vertex_colors=m.colors), static=True)


def log_robot(rec: rr.RecordingStream, root: str, meshes: Sequence[BodyMesh],
              times_s: np.ndarray, body_pos_m: np.ndarray, body_quat_xyzw: np.ndarray,
              tint_rgba: Sequence[int] | None = None) -> None:
    """A robot moving: each body's mesh (static, at ``root/<body>``) and its pose over
    time (one column batch per body).

    Args:
        meshes: the robot's bodies (`robot_bodies`).
        times_s: (K,) the poses' times [s].
        body_pos_m, body_quat_xyzw: (K, nbody, 3) and (K, nbody, 4), indexed by body id.
        tint_rgba: one colour for the whole robot (a ghost: its alpha makes it
            translucent, which Rerun draws for a mesh's albedo factor, not for its
            vertex colours), else the geoms' colours.
    """
    index = [time_column(times_s)]
    for m in meshes:
        path = f"{root}/{m.name}"
        colour = ({"vertex_colors": m.colors} if tint_rgba is None
                  else {"albedo_factor": list(tint_rgba)})
        rec.log(path, rr.Mesh3D(vertex_positions=m.vertices_m, triangle_indices=m.faces,
                                vertex_normals=m.normals, **colour), static=True)
        rec.send_columns(path, indexes=index, columns=rr.Transform3D.columns(
            translation=body_pos_m[:, m.body], quaternion=body_quat_xyzw[:, m.body]))


def log_track(rec: rr.RecordingStream, path: str, times_s: np.ndarray, points_m: np.ndarray,
              color: Sequence[int], radius_m: float = 0.02) -> None:
    """One point moving over time (a CoM), NaN rows dropped."""
    ok = ~np.isnan(points_m).any(axis=1)
    rec.log(path, rr.Points3D.from_fields(colors=[color], radii=[radius_m]), static=True)
    rec.send_columns(path, indexes=[time_column(np.asarray(times_s)[ok])],
                     columns=rr.Points3D.columns(positions=points_m[ok]))


def log_scalars(rec: rr.RecordingStream, path: str, times_s: np.ndarray, values: np.ndarray,
                name: str | None = None) -> None:
    """A time series (NaN samples dropped), named ``name`` in plots."""
    values = np.asarray(values, dtype=float)
    ok = ~np.isnan(values)
    if not ok.any():
        return
    if name is not None:
        rec.log(path, rr.SeriesLines(names=name), static=True)
    rec.send_columns(path, indexes=[time_column(np.asarray(times_s)[ok])],
                     columns=rr.Scalars.columns(scalars=values[ok]))


def log_event(rec: rr.RecordingStream, path: str, time_s: float, text: str,
              level: str = rr.TextLogLevel.INFO) -> None:
    """A text event at ``time_s`` (a mark on the time panel, a row in the text log)."""
    rec.set_time(TIMELINE, duration=float(time_s))
    rec.log(path, rr.TextLog(text, level=level))
