"""A 40-column file as the public hubo-read-trajectory users wrote them: ``%f`` values (6
decimals, a trailing space), a slow squat whose knees end a little below their 0 lower
limit, as 9 of 11 real files do (0.0004 to 0.07 rad below)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robot.joints import JOINT_INDEX

#: The knees' overshoot below 0 on the lines that go past it [rad].
SMALL_OVERSHOOTS_RAD = (-0.0004, -0.07)


def real_style_rows(n: int = 60, knee_min_rad: tuple[float, float] = SMALL_OVERSHOOTS_RAD[::-1]
                    ) -> np.ndarray:
    """(n, 40): hips, knees and ankles of a squat that straightens the right and left knee
    to ``knee_min_rad``; the arms hang at a 10° shoulder roll, elbows bent 30°."""
    q = np.zeros((n, 40))
    s = 0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, n))  # 0 → 1, smooth
    for side, k_min in zip("RL", knee_min_rad, strict=True):
        knee = 0.6 + (k_min - 0.6) * s  # from a 0.6 rad squat to straight (and past)
        q[:, JOINT_INDEX[f"{side}KN"]] = knee
        q[:, JOINT_INDEX[f"{side}HP"]] = -knee / 2
        q[:, JOINT_INDEX[f"{side}AP"]] = -knee / 2
        q[:, JOINT_INDEX[f"{side}EB"]] = -0.523599
    q[:, JOINT_INDEX["RSR"]] = -0.174533
    q[:, JOINT_INDEX["LSR"]] = 0.174533
    return q


def write_real_style(path: Path, rows: np.ndarray) -> Path:
    """Write ``rows`` as ``%f `` columns with a trailing space and '\\n' endings."""
    path.write_text("".join("".join(f"{v:f} " for v in row) + "\n" for row in rows))
    return path
