"""The head camera of the simulated robot, rendered by MuJoCo at the joint angles the sim
daemon reports, a few frames a second.

The thesis's operator watched every grasp through the head camera. A sim daemon
(``hubo-daemon --backend sim``) runs in another process and publishes no image, so the
page's process builds the same scene (`ladders.scene.build_scene` of the same ladder and
robot, as the sim backend does), adds a camera to the head and renders it at the newest
``state`` sample's joint angles: the neck keys turn the view.

The state channel carries no pose of the robot's base. The base is put where the sim
backend starts it: upright, at the world origin, lowered until the lowest sole touches
the floor. So the view is the simulator's at the foot of the ladder; once the robot
climbs (its base rises and tilts) the view is what the head would see from the ground.

On the robot no image channel exists (hubo-ach had none either; the camera streamed
separately): the page says so.
"""

from __future__ import annotations

import io
import logging
import math
import os
import sys
import threading
import time
from collections.abc import Callable

import numpy as np

__all__ = ["HEAD_CAMERA", "FRAME_SIZE_PX", "SimHeadCamera", "add_head_camera"]

log = logging.getLogger(__name__)

HEAD_CAMERA = "head_camera"
#: Camera on the head link, in the head's frame [m]: in front of the 0.09 m head sphere.
HEAD_CAMERA_POS_M = (0.10, 0.0, 0.08)
#: Looking along the head's +x (forward), image up along its +z: MuJoCo cameras look
#: along their −z, so camera x = −y_head, camera y = +z_head.
HEAD_CAMERA_XYAXES = (0.0, -1.0, 0.0, 0.0, 0.0, 1.0)
HEAD_CAMERA_FOVY_DEG = 70.0
FRAME_SIZE_PX = (320, 240)  # width, height
JPEG_QUALITY = 80
#: Render only while a page has asked for a frame this recently [s]: on a machine without
#: a GPU (llvmpipe) a frame costs about 50 ms of CPU, time the sim daemon needs.
WATCHED_FOR_S = 2.0


def add_head_camera(spec) -> None:
    """Add `HEAD_CAMERA` to the ``head`` body of an uncompiled scene spec."""
    spec.body("head").add_camera(name=HEAD_CAMERA, pos=list(HEAD_CAMERA_POS_M),
                                 xyaxes=list(HEAD_CAMERA_XYAXES), fovy=HEAD_CAMERA_FOVY_DEG)


class _Scene:
    """The compiled scene with its head camera, posed from joint angles."""

    def __init__(self, ladder: str, robot: str):
        import mujoco

        from ladders.loader import load_ladder
        from ladders.scene import build_scene
        from robot.joints import JOINT_NAMES

        spec = build_scene(load_ladder(ladder), robot)
        add_head_camera(spec)
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        m = self.model
        present = [(j, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n))
                   for j, n in enumerate(JOINT_NAMES)]
        present = [(j, jid) for j, jid in present if jid >= 0]
        self.cols = np.array([j for j, _ in present])
        self.qpos_adr = np.array([m.jnt_qposadr[jid] for _, jid in present])
        self.soles = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"{s}_sole")
                      for s in ("L", "R")]

    def pose(self, q_rad: np.ndarray) -> None:
        """Joint angles ``q_rad`` (40,) [rad]; the base upright at the origin, lowest sole
        on the floor (module docstring)."""
        import mujoco

        m, d = self.model, self.data
        mujoco.mj_resetDataKeyframe(m, d, 0)
        d.qpos[self.qpos_adr] = q_rad[self.cols]
        d.qpos[3:7] = (1.0, 0.0, 0.0, 0.0)
        mujoco.mj_kinematics(m, d)
        d.qpos[2] -= min(d.site_xpos[s][2] for s in self.soles)
        mujoco.mj_kinematics(m, d)
        mujoco.mj_camlight(m, d)  # cameras follow their bodies only here


class SimHeadCamera:
    """A thread that renders the head camera at ``fps`` from the newest state sample
    (`start` names where it comes from).

    Args:
        ladder: the sim daemon's ``--ladder`` (name or spec file).
        robot: the sim daemon's ``--robot``.
        fps: frames a second [Hz].

    Attributes:
        error: why no frame can be rendered (no OpenGL context), else None.
        frames: frames rendered so far.

    Raises:
        InputError: an unknown ladder (the scene is built here, at the edge).
    """

    def __init__(self, ladder: str = "drc", robot: str = "drc-hubo", fps: float = 4.0):
        if "mujoco" not in sys.modules:
            os.environ.setdefault("MUJOCO_GL", "egl")
        self.fps = fps
        self._latest_state: Callable[[], np.ndarray | None] = lambda: None
        self._scene = _Scene(ladder, robot)
        self.error: str | None = None
        self.frames = 0
        self._jpeg: bytes | None = None
        self._asked_s = -math.inf  # time.monotonic() of the last latest_jpeg() [s]
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="head-camera", daemon=True)

    def start(self, latest_state: Callable[[], np.ndarray | None]) -> SimHeadCamera:
        """Render from ``latest_state`` (the page's state source: the sim daemon's channel,
        or a sim robot's samples through the bridge), which returns the newest ``state``
        sample or None."""
        self._latest_state = latest_state
        self._thread.start()
        return self

    def close(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=5.0)

    def latest_jpeg(self) -> bytes | None:
        """The newest frame as JPEG bytes, None before the first. Calls keep the renderer
        running (`WATCHED_FOR_S`)."""
        with self._lock:
            self._asked_s = time.monotonic()
            return self._jpeg

    def _run(self) -> None:
        """Make the renderer here (an OpenGL context belongs to the thread that made it),
        then render a frame per 1/fps at the newest state sample's joint angles."""
        import mujoco
        from PIL import Image

        scene = self._scene
        try:
            renderer = mujoco.Renderer(scene.model, height=FRAME_SIZE_PX[1],
                                       width=FRAME_SIZE_PX[0])
        except Exception as exc:  # mujoco raises plain RuntimeError/FatalError types
            gl = os.environ.get("MUJOCO_GL")
            self.error = f"no head camera: {exc} (MUJOCO_GL={gl!r}; EGL needs Mesa or a GPU)"
            log.error("%s", self.error)
            return
        option = mujoco.MjvOption()
        option.geomgroup[:] = 1  # the robot's geoms are in group 3
        flags = renderer.scene.flags  # shadows and reflections cost 4/5 of a frame's CPU
        flags[mujoco.mjtRndFlag.mjRND_SHADOW] = flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
        period_s = 1.0 / self.fps
        try:
            while not self._stop.is_set():
                t0 = time.monotonic()
                s = self._latest_state()
                if s is not None and time.monotonic() - self._asked_s < WATCHED_FOR_S:
                    scene.pose(np.asarray(s["pos"]))
                    renderer.update_scene(scene.data, camera=HEAD_CAMERA, scene_option=option)
                    rgb = renderer.render()
                    buf = io.BytesIO()
                    Image.fromarray(rgb).save(buf, format="JPEG", quality=JPEG_QUALITY)
                    with self._lock:
                        self._jpeg = buf.getvalue()
                    self.frames += 1
                self._stop.wait(max(0.0, period_s - (time.monotonic() - t0)))
        finally:
            renderer.close()
