"""OMPL fallback for a moving limb whose way-point arc collides (issue: "where the arc
fails, plan the moving limb with OMPL (RRTConnect) in the constrained space").

The constrained space is the moving limbs' joints with the rest of the body held: the
supporting limbs then stay exactly on their holds, so every state is on the contact
constraints without projection. RRTConnect (OMPL) searches that space for a path clear of
collisions within the joint limits (coal, ≈ 0.1 ms a state); the path is then shortened
by OMPL's rope shortcut (deterministic) and sampled so that neighbours are within the
planner's resolution, and every configuration of it passes the planner's whole
feasibility test (limits, collisions, CoM and torque stability: the LP costs ≈ 1.5 ms a
state, too much for the search itself, and a limb moving in the air seldom changes what
the stance can carry).

Determinism: OMPL's random numbers come from one process-wide generator, which OMPL lets
us seed only before its first draw; it is seeded then with a fixed seed, and the budget is
a count of validity checks, not wall time. A fresh process (``plan-ladder``) therefore
gives the same paths on every run; a process that plans several times draws on from where
its previous searches left the generator.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from planner.configuration.kinematics import HuboKinematics
from planner.configuration.validity import FeasibilityChecker
from planner.contacts import Stance

__all__ = ["OMPL_SEED", "plan_limb_path"]

#: The seed of OMPL's random numbers (set before its first draw in the process).
OMPL_SEED = 20140501
#: Edge check step inside OMPL [rad, max over joints]; the final path is re-checked at the
#: planner's resolution, so a coarser step here only costs the search retries.
EDGE_CHECK_RAD = 0.05
_seeded = False


def _seed_ompl() -> None:
    global _seeded
    if _seeded:
        return
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_NONE)  # OMPL logs through its own handler, not Python's
    ou.RNG.setSeed(OMPL_SEED)
    _seeded = True


def plan_limb_path(kin: HuboKinematics, checker: FeasibilityChecker, q_from: np.ndarray,
                   q_to: np.ndarray, joints: Sequence[str], stance: Stance,
                   contacts: dict[str, str], *, resolution_rad: float = 0.01,
                   max_checks: int = 30000) -> list[np.ndarray] | None:
    """A feasible path of ``joints`` from ``q_from`` to ``q_to``, the other coordinates
    held, or None when RRTConnect finds none within ``max_checks`` validity checks.

    Args:
        q_from, q_to: configurations equal outside ``joints`` (the held body).
        joints: the moving limbs' joint names.
        stance: the holds that carry the robot meanwhile (stability is tested on them).
        contacts: limb → object it may touch.
        resolution_rad: largest joint step between returned neighbours [rad].

    Returns:
        Configurations from ``q_from`` (excluded) to ``q_to`` (included).
    """
    from ompl import base as ob
    from ompl import geometric as og

    idx = np.array([kin.q_index[n] for n in joints if n in kin.q_index])
    rest = np.setdiff1d(np.arange(len(q_from)), idx)
    if not np.allclose(q_from[rest], q_to[rest], atol=1e-9):
        raise ValueError("plan_limb_path holds the body: q_from and q_to must differ only "
                         "in the moving joints")
    _seed_ompl()
    # The ends may sit a rounding error outside the limits (the planner's check allows
    # that): OMPL would wait forever for a goal inside them.
    lower = np.minimum(kin.model.lowerPositionLimit[idx], np.minimum(q_from[idx], q_to[idx]))
    upper = np.maximum(kin.model.upperPositionLimit[idx], np.maximum(q_from[idx], q_to[idx]))
    checks = [0]

    def configuration(x) -> np.ndarray:
        q = q_from.copy()
        q[idx] = x
        return q

    def clear(x) -> bool:
        checks[0] += 1
        return bool(checker.collision_free(configuration(x), contacts))

    space = ob.RealVectorStateSpace(len(idx))
    bounds = ob.RealVectorBounds(len(idx))
    for i, (lo, hi) in enumerate(zip(lower, upper, strict=True)):
        bounds.setLow(i, float(lo))
        bounds.setHigh(i, float(hi))
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(lambda s: clear([s[i] for i in range(len(idx))]))
    info = setup.getSpaceInformation()
    info.setStateValidityCheckingResolution(EDGE_CHECK_RAD / space.getMaximumExtent())
    start, goal = space.allocState(), space.allocState()
    for i, k in enumerate(idx):
        start[i], goal[i] = float(q_from[k]), float(q_to[k])
    setup.setStartAndGoalStates(start, goal)
    setup.setPlanner(og.RRTConnect(info))
    setup.setup()
    polls = [0]

    def done() -> bool:
        # Budget in checks; the poll count bounds loops that check nothing.
        polls[0] += 1
        return checks[0] >= max_checks or polls[0] >= 10 * max_checks

    solved = setup.solve(ob.PlannerTerminationCondition(done))
    if not (solved and setup.haveExactSolutionPath()):
        return None
    path = setup.getSolutionPath()
    og.PathSimplifier(info).ropeShortcutPath(path)  # deterministic, checks at the edge step
    vertices = [np.array([path.getState(k)[i] for i in range(len(idx))])
                for k in range(path.getStateCount())]
    out = [configuration(x) for a, b in zip(vertices, vertices[1:], strict=False)
           for x in _segment(a, b, resolution_rad)]
    # OMPL checked edges every EDGE_CHECK_RAD: re-check every sample, with stability.
    return out if all(checker.check(q, stance, contacts).ok for q in out) else None


def _segment(a: np.ndarray, b: np.ndarray, resolution_rad: float) -> list[np.ndarray]:
    """Points from ``a`` (excluded) to ``b`` (included), steps ≤ resolution per joint."""
    n = max(1, int(np.ceil(np.max(np.abs(b - a)) / resolution_rad)))
    return [a + (b - a) * (k / n) for k in range(1, n + 1)]
