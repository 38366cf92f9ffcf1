"""Tunables of the static stability tests, and the error their LPs raise.

Both tests (`planner.statics.com_region.support_region` and
`planner.statics.torque_lp.torque_feasibility`) linearise the friction cones with the
same number of edges and bound the contact forces the same way, so they share one
`StabilityConfig`.
"""

from __future__ import annotations

from dataclasses import dataclass

from robot.errors import HuboLadderError

__all__ = ["StabilityConfig", "StabilityError", "default_config"]


class StabilityError(HuboLadderError):
    """An LP of the stability test failed for a reason other than infeasibility."""


@dataclass(frozen=True)
class StabilityConfig:
    """Tunables of the stability tests.

    Attributes:
        cone_edges: edges k of each linearised friction cone (inner pyramid).
        box_half_m: the CoM LPs are capped to a square of this half-side around the
            contacts' centroid [m]; contacts that can pull (hands) make the region
            unbounded, and it is then clipped to this square.
        area_tol_m2: stop refining when outer − inner area < this [m²] ...
        area_rel_tol: ... or < this fraction of the inner area.
        edge_tol_m: an LP point less than this beyond an inner edge closes the edge [m].
        max_lps: hard cap on LPs per region (a warning is logged when reached).
        force_max_weights: upper bound of each cone coefficient, in body weights; only
            keeps the torque LP bounded when contacts can squeeze each other.
    """

    cone_edges: int = 8
    box_half_m: float = 5.0
    area_tol_m2: float = 1e-4
    area_rel_tol: float = 0.01
    edge_tol_m: float = 1e-5
    max_lps: int = 60
    force_max_weights: float = 20.0


def default_config() -> StabilityConfig:
    """The default `StabilityConfig` (k = 8 cone edges, ±5 m box, 1e-4 m² or 1 % gap)."""
    return StabilityConfig()
