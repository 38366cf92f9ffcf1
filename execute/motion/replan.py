"""How to plan again after a ``ladder_misplaced`` stop: the first plan's own settings.

The new plan is the first one's, made for the ladder where the hands found it: the same
seed and top rung, and the planner settings the sidecar recorded (arm strategy, torque
share, the feet's centre-of-pressure margin and friction share). `validate-plan` plans it
in-process (`execute.validate.simulate`); on the robot `play-trajectory` writes the
measured ladder and prints the ``plan-ladder`` command that makes it.
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass, field

from robot.plan_sidecar import PlanSidecar
from robot.vocabulary import HoldTargetKind, Limb

__all__ = ["ReplanSettings"]

#: `planner.search.PlannerConfig` fields a sidecar's metrics record → plan-ladder's flag.
_PLANNER_FLAGS = {"arm_strategy": "--arm-strategy",
                  "position_torque_share": "--position-torque-share",
                  "foot_cop_margin_m": "--foot-cop-margin",
                  "foot_friction_share": "--foot-friction-share",
                  "held_wrist_margin_rad": "--held-wrist-margin"}


@dataclass(frozen=True)
class ReplanSettings:
    """Attributes:
        seed: the first plan's planner seed.
        top_rung: the rung both feet end on (None: they end on the floor, as a reach
            without a climb does; plan-ladder then climbs the whole ladder).
        rate_hz: the line rate [Hz].
        planner: `PlannerConfig` fields the first plan was made with.
    """

    seed: int
    top_rung: int | None
    rate_hz: float
    planner: dict = field(default_factory=dict)

    @classmethod
    def of(cls, sidecar: PlanSidecar) -> ReplanSettings:
        """The settings of the plan that ``sidecar`` describes."""
        metrics = sidecar.metrics or {}
        top = max((h.hold_target.rung for limb, h in sidecar.final_holds.items()
                   if Limb(limb).is_foot and h.hold_target.kind is HoldTargetKind.RUNG),
                  default=None)
        return cls(sidecar.seed, top, sidecar.rate_hz,
                   {k: metrics[k] for k in _PLANNER_FLAGS if k in metrics})

    def command(self, ladder_path: str, out_path: str) -> str:
        """The ``plan-ladder`` command line that makes the new plan."""
        words = ["plan-ladder", ladder_path, "--seed", str(self.seed), "--rate",
                 f"{self.rate_hz:g}"]
        if self.top_rung is not None:
            words += ["--top-rung", str(self.top_rung)]
        for key, value in self.planner.items():
            words += [_PLANNER_FLAGS[key], f"{value:g}" if isinstance(value, float)
                      else str(value)]
        return shlex.join(words + ["-o", out_path])
