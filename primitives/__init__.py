"""Motion primitives: seed holds relative to rungs and rails, seed poses, way-point recipes."""

from primitives.hold_seeds import (
           FloorSeed,
           HoldSeed,
           RailSeed,
           RungSeed,
           foot_on_rung,
           hand_on_rail,
)
from primitives.library import PRIMITIVES, STRAIGHTEN, climb_sequence
from primitives.primitive import LimbWaypoints, Primitive, Step

__all__ = ["PRIMITIVES", "STRAIGHTEN", "FloorSeed", "HoldSeed", "LimbWaypoints", "Primitive",
           "RailSeed", "RungSeed", "Step", "climb_sequence", "foot_on_rung", "hand_on_rail"]
