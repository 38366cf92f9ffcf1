"""Thesis §4.3.4: the arms' tracking error in PWM and in position mode, with and without
gravity compensation.

``errorDuringTrajectory`` (eqs. 4.13–4.16): per joint, the sum over the trajectory's
setpoints of |encoder − reference|; then the norm over the joints. Measured on the same
motion, the DRC mount's first reach (both arms in the air, `placeHands`' limb segment,
seed 1), played four ways:

- position mode (the arms rigid);
- PWM mode without feed-forward (hubo-ach's PWM law alone, as the thesis's plain
  PWM-mode tracking);
- PWM mode with the planner's feed-forward (gravity at the *planned* configuration);
- PWM mode with the motion layer's gravity compensation (gravity at the *sensed*
  configuration and IMU tilt).

The thesis measured a ratio PWM/position of 65.5 over a climb (0.2372 / 0.0036).
"""

from __future__ import annotations

import dataclasses
import tempfile
from pathlib import Path

import numpy as np

THESIS_RATIO = 65.5


def _reach_error(run, first_line: int, last_line: int) -> float:
    from execute.validate.metrics import tracking_error_by_arm

    lg = run.log
    keep = (lg.line_index >= first_line - 1) & (lg.line_index <= last_line - 1)
    by_arm, _ = tracking_error_by_arm(lg.pos_rad[keep], lg.ref_rad[keep], lg.line_index[keep])
    return float(np.linalg.norm([by_arm["left"], by_arm["right"]]))


def run() -> list[dict]:
    from execute.validate.cli import ladder_from_sidecar
    from execute.validate.simulate import SimulationOptions, simulate
    from planner.cli import main as plan_main
    from robot.plan_sidecar import read_sidecar, sidecar_path
    from robot.trajectory_file import read_trajectory

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "mount.traj"
        if plan_main(["drc", "--seed", "1", "--top-rung", "0", "-o", str(path)]) != 0:
            return [{"name": "tracking: no DRC mount plan for seed 1", "value": "-",
                     "target": None}]
        sidecar = read_sidecar(sidecar_path(path))
        traj = read_trajectory(path, sidecar.rate_hz)
    ladder = ladder_from_sidecar(sidecar.ladder, "bench")
    reach = next(s for s in sidecar.segments if s.phase == "limb")
    bare = dataclasses.replace(sidecar, arm_feedforward=None)
    ways = {
        "position": (sidecar, "position", False),
        "PWM, no feed-forward": (bare, "pwm", False),
        "PWM, planned feed-forward": (sidecar, "pwm", False),
        "PWM, gravity compensation": (sidecar, "pwm", True),
    }
    errors = {}
    for name, (sc, strategy, closed) in ways.items():
        result = simulate(traj, sc, ladder, SimulationOptions(
            strategy=strategy, record_qpos=False, closed_loop=closed, stop_on_failure=True))
        errors[name] = _reach_error(result, reach.first_line, reach.last_line)
    figures = [{"name": f"errorDuringTrajectory, {name}", "value": round(err, 4),
                "unit": "rad", "target": None} for name, err in errors.items()]
    base = errors["position"]
    for name in list(errors)[1:]:
        figures.append({"name": f"ratio {name} / position", "value": round(errors[name] / base, 1),
                        "unit": "×", "target": f"thesis {THESIS_RATIO} (PWM, no compensation)",
                        "ok": None})
    return figures
