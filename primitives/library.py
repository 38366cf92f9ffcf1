"""The primitive library and the climbing sequence built from it.

Mount: placeHands, placeLFoot, placeRFoot (feet onto rung 0). Then per rung the executed
cycle of the thesis: left hand up, right hand up, left foot up, right foot up, straighten.
Hands hold the rail above the rung the feet stand on; before the feet step to rung k+1
both hands move to the rail above rung k+1.
"""

from __future__ import annotations

from primitives.hold_seeds import FOOT_ALONG_M, MOUNT_ALONG_RAIL_M, foot_on_rung, hand_on_rail
from primitives.primitive import LimbWaypoints, Primitive, Step

# Seed postures [rad]: arms reaching forward and out to the rails with bent elbows and
# straight wrists (a flexed wrist folds the open fingers onto the forearm); legs
# a little bent (a straight knee is a kinematic singularity). Fingers are set by the
# planner. Foot moves leave the legs to the pelvis target (over the stance foot).
_ARMS = {"LSP": -0.6, "RSP": -0.6, "LSR": 0.5, "RSR": -0.5, "LEB": -1.0, "REB": -1.0,
         "LWP": 0.0, "RWP": 0.0}
_STAND = {"LHP": -0.35, "RHP": -0.35, "LKN": 0.6, "RKN": 0.6, "LAP": -0.25, "RAP": -0.25}

#: Hands stand off 10 cm from the rail before closing in: palm plate (2 cm) and open
#: fingers (2.2 cm) must pass a 2.5 cm-radius rail with margin.
_HAND_PATH = LimbWaypoints(lift_m=0.0, clearance_m=0.10)

PLACE_HANDS = Primitive("placeHands", ("left_hand", "right_hand"), {**_ARMS, **_STAND},
                        pelvis_offset_m=(-0.05, 0.0, 0.90), waypoints=_HAND_PATH)
PLACE_L_FOOT = Primitive("placeLFoot", ("left_foot",), _ARMS)
#: Stepping off the floor onto rung 0, the foot still on the floor keeps the pelvis low:
#: seed it about as high as that leg reaches (3 cm below standing), over the rung foot.
PLACE_R_FOOT = Primitive("placeRFoot", ("right_foot",), _ARMS,
                         pelvis_offset_m=(-0.05, 0.0, 0.0), pelvis_below_standing_m=0.03)
MOVE_L_HAND = Primitive("moveLHand", ("left_hand",), {**_ARMS, **_STAND},
                        waypoints=_HAND_PATH)
MOVE_R_HAND = Primitive("moveRHand", ("right_hand",), {**_ARMS, **_STAND},
                        waypoints=_HAND_PATH)
MOVE_L_FOOT = Primitive("moveLFoot", ("left_foot",), _ARMS)
MOVE_R_FOOT = Primitive("moveRFoot", ("right_foot",), _ARMS)
#: Straighten the legs with every hold kept: the body rises over the new rung.
STRAIGHTEN = Primitive("straighten", (), {**_ARMS, **_STAND}, pelvis_offset_m=(-0.2, 0.0, 0.85))

#: Where the torso stands over rung 0 at the end of the mount (placeRFoot's pelvis seed,
#: over the rung foot), up-ladder of the rung's tread centre [m]: the hands' mount holds
#: must leave the arms room from there.
MOUNT_TORSO_ALONG_M = FOOT_ALONG_M + PLACE_R_FOOT.pelvis_offset_m[0]

#: Where the torso stands over rung k+1 once the left foot carries it there (moveRFoot's
#: pelvis seed over that foot), up-ladder of the tread centre [m]: the hands' holds above
#: rung k+1 must leave the arms room from there, as the mount holds do from rung 0.
CLIMB_TORSO_ALONG_M = FOOT_ALONG_M + MOVE_R_FOOT.pelvis_offset_m[0]

PRIMITIVES = {p.name: p for p in (PLACE_HANDS, PLACE_L_FOOT, PLACE_R_FOOT, MOVE_L_HAND,
                                  MOVE_R_HAND, MOVE_L_FOOT, MOVE_R_FOOT, STRAIGHTEN)}


def climb_sequence(top_rung: int) -> list[Step]:
    """Every step from standing on the floor to both feet on rung ``top_rung``."""
    if top_rung < 0:
        raise ValueError(f"top rung must be ≥ 0, got {top_rung}")
    steps = [
        Step(PLACE_HANDS, tuple(hand_on_rail(limb, 0, MOUNT_ALONG_RAIL_M, MOUNT_TORSO_ALONG_M)
                                for limb in ("left_hand", "right_hand")), 0),
        Step(PLACE_L_FOOT, (foot_on_rung("left_foot", 0),), 0),
        Step(PLACE_R_FOOT, (foot_on_rung("right_foot", 0),), 0),
        Step(STRAIGHTEN, (), 0),
    ]
    for k in range(top_rung):
        steps += [
            Step(MOVE_L_HAND, (hand_on_rail("left_hand", k + 1, 0.0, CLIMB_TORSO_ALONG_M),), k),
            Step(MOVE_R_HAND, (hand_on_rail("right_hand", k + 1, 0.0, CLIMB_TORSO_ALONG_M),), k),
            Step(MOVE_L_FOOT, (foot_on_rung("left_foot", k + 1),), k + 1),
            Step(MOVE_R_FOOT, (foot_on_rung("right_foot", k + 1),), k + 1),
            Step(STRAIGHTEN, (), k + 1),
        ]
    return steps
