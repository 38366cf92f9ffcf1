"""A small real `SearchResult` built from the planner's own IK, for the output tests.

Until the search plans whole climbs quickly, the timing, sidecar, CLI and check-plan
tests run on this: the robot stands on the floor in front of the DRC ladder, crouches
``CROUCH_M`` and rises back (two body-move steps, both feet on the floor), each made
dense by contact-space interpolation, plus a finger-closing segment.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from ladders.loader import load_ladder
from planner.configuration.ik import solve_ik
from planner.contacts import Stance
from planner.paths.interpolation import contact_space_interpolate
from planner.search import ClimbPlanner, PathSegment, SearchResult, StepStats
from primitives.library import STRAIGHTEN
from primitives.primitive import Step

#: How far the pelvis goes down and back up [m].
CROUCH_M = 0.05


def _body_move(planner: ClimbPlanner, q: np.ndarray, stance: Stance, dz_m: float
               ) -> list[np.ndarray]:
    kin = planner.kin
    pelvis = kin.frame_pose(q, "pelvis")[:3, 3] + [0.0, 0.0, dz_m]
    res = solve_ik(kin, q, stance.holds, torso_R=planner.torso_R, pelvis_target_m=pelvis,
                   pelvis_weight=10.0)
    assert res.converged, res
    contacts = {h.limb: h.target for h in stance.holds}
    return contact_space_interpolate(kin, planner.checker, q, res.q, stance.holds, stance,
                                     contacts, resolution_rad=planner.config.resolution_rad)


@cache
def synthetic_plan() -> tuple[ClimbPlanner, SearchResult, np.ndarray]:
    """(planner, result, start configuration): crouch, close the right hand, rise."""
    planner = ClimbPlanner(load_ladder("drc"), seed=1)
    q0, stance = planner.start_configuration()
    down = _body_move(planner, q0, stance, -CROUCH_M)
    fingers = planner._finger_path(down[-1], "right", 0.5)
    up = _body_move(planner, fingers[-1], stance, CROUCH_M)
    s1, s2 = Step(STRAIGHTEN, (), 0), Step(STRAIGHTEN, (), 1)
    segments = [PathSegment(s1, "body", stance.holds, (), down),
                PathSegment(s2, "grasp", stance.holds, (), fingers),
                PathSegment(s2, "body", stance.holds, (), [fingers[-1]]),  # no motion
                PathSegment(s2, "body", stance.holds, (), up)]
    stats = [StepStats(s1.label, 0.1, 3, 0, 0.05, 0.4), StepStats(s2.label, 0.2, 5, 1, 0.04, 0.5)]
    return planner, SearchResult(segments, stance, stats, 0.3), q0


def write_synthetic_plan(path):
    """The synthetic plan written to ``path`` (and its sidecar) as plan-ladder writes it,
    at 200 Hz, without the clearance metric; returns ``path``."""
    from planner.output import write_plan

    planner, result, q0 = synthetic_plan()
    write_plan(result, planner, path, 200.0, q_start=q0, clearance_every=0)
    return path


def use_synthetic_search(monkeypatch) -> SearchResult:
    """Replace `ClimbPlanner.plan` by the synthetic plan (the real search is slow), with its
    progress calls; returns the result it gives."""
    _, result, _ = synthetic_plan()

    def plan(self, top_rung=None, progress=None):
        for i, st in enumerate(result.step_stats):
            progress(i, 4, result.segments[0].step, st)
        return result

    monkeypatch.setattr(ClimbPlanner, "plan", plan)
    return result
