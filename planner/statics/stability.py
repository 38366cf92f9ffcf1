"""Static stability of one configuration: the CoM test, then the joint-torque LP.

Two tests, both on linearised Coulomb friction cones (thesis §6.3.1, μ = 0.4):

1. `planner.statics.com_region.support_region`: the horizontal CoM positions at which the
   stance's contacts can balance gravity (Bretl & Lall 2008), computed once per stance.
2. `planner.statics.torque_lp.torque_feasibility`: whether the joints can hold a
   configuration on those contacts, minimising the worst joint-torque ratio.

The region is exactly the set of CoM positions for which the free-flyer rows of the
torque LP are feasible, so `check_stability` skips the LP for a configuration whose CoM
lies outside it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from planner.contacts import Stance
from planner.statics.com_region import SupportRegion
from planner.statics.config import StabilityConfig
from planner.statics.torque_lp import TorqueCheck, torque_feasibility

__all__ = ["StabilityReport", "check_stability"]


@dataclass(frozen=True, eq=False)
class StabilityReport:
    """CoM margin and (if the CoM passed) the torque check of one configuration.

    Attributes:
        com_m: (3,) whole-body CoM [m].
        margin_m: signed distance of the CoM to the support region's boundary [m].
        torque: the torque check, or None when skipped because the CoM test failed.
        min_margin_m: the margin the CoM had to reach [m].
    """

    com_m: np.ndarray = field(repr=False)
    margin_m: float
    torque: TorqueCheck | None
    min_margin_m: float = 0.0

    @property
    def stable(self) -> bool:
        return (self.margin_m >= self.min_margin_m and self.torque is not None
                and self.torque.feasible)

    def __repr__(self) -> str:
        tq = repr(self.torque) if self.torque is not None else "torque check skipped"
        return (f"StabilityReport({'stable' if self.stable else 'UNSTABLE'}, CoM margin "
                f"{self.margin_m * 100:.1f} cm (need {self.min_margin_m * 100:.1f}), {tq})")


def check_stability(model, data, q: np.ndarray, stance: Stance, region: SupportRegion,
                    torque_max_nm_by_joint: Mapping[str, float], *, min_margin_m: float = 0.0,
                    frame_ids: Mapping[str, int] | None = None,
                    config: StabilityConfig | None = None) -> StabilityReport:
    """CoM-in-region test, then (only if it passes) the torque LP.

    Args:
        model, data: pinocchio model and data (data is overwritten).
        q: (model.nq,) configuration.
        stance: the holds in contact (the one ``region`` was computed for).
        region: ``support_region(stance, ...)``.
        torque_max_nm_by_joint: torque limits by joint name [N·m].
        min_margin_m: required CoM margin [m].
        frame_ids: frame id per limb, looked up if None.
        config: tunables for the torque LP.
    """
    import pinocchio as pin

    com = np.array(pin.centerOfMass(model, data, q))
    margin = region.margin(com)
    torque = None
    if margin >= min_margin_m:
        torque = torque_feasibility(model, data, q, stance, torque_max_nm_by_joint, frame_ids,
                                    config=config)
    return StabilityReport(com, float(margin), torque, min_margin_m)
