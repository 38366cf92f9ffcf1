"""The way back after a ``ladder_misplaced`` stop: the references that take the robot from
where the motion layer stopped to the plan's first line, its weight on the floor.

Both hands hold rails, closed by the plan at the layer's corrected references; the feet
still stand where they started. The hands open where they hold (`RETRACT_OPEN_S`), the
layer's corrections fade out over as long again, and the arms retrace the played lines to
the first one, in position mode. Retracing the plan keeps the arms on the collision-free
path that brought them to the rails; a straight joint-space move from the rails to the
start could sweep a forearm through a rail. `validate-plan` plays these lines before it
plans again; `play-trajectory` plays them on the robot before the operator does.
"""

from __future__ import annotations

import numpy as np

from robot.joints import FINGER_JOINTS, joint_indices

__all__ = ["RETRACT_OPEN_S", "retract_lines"]

#: How long the hands take to open before they retrace the plan [s].
RETRACT_OPEN_S = 1.0


def retract_lines(trajectory_rad: np.ndarray, line_index: int, held_ref_rad: np.ndarray,
                  rate_hz: float) -> np.ndarray:
    """The references of the way back (module docstring), one row a line.

    Args:
        trajectory_rad: the plan played, (N, 40).
        line_index: the 0-based line it stopped on.
        held_ref_rad: the motion layer's last reference (its corrections included), (40,).
        rate_hz: the plan's line rate [Hz].

    Returns:
        (2·n + line_index + 1, 40): n = `RETRACT_OPEN_S`·rate lines holding the stop's pose
        with the fingers open, n lines fading to the plan's line ``line_index``, then the
        plan's lines back to its first, every finger open.
    """
    back = np.array(trajectory_rad[line_index::-1], dtype=float)
    held = np.array(held_ref_rad, dtype=float)
    for side in ("left", "right"):
        fingers = joint_indices(FINGER_JOINTS[side])
        back[:, fingers] = 0.0
        held[fingers] = 0.0
    n = int(RETRACT_OPEN_S * rate_hz)
    fade = held + np.linspace(0.0, 1.0, n)[:, None] * (back[0] - held)
    return np.vstack([np.repeat(held[None], n, axis=0), fade, back])
