"""Why the planner found no plan, in a user's terms.

The search records, for every failed sample of a step, a `SampleFailure`: the figures of
the verdict that refused it (which limb missed which hold and by how much, which joint
ran over its torque limit, what collided), not the solver's text. `explain_no_plan`
turns a step's records into the ``no plan:`` message of ``plan-ladder``: the step the
search got furthest to, what that step does, its reasons grouped and counted, each with
its best (smallest) figure in cm, degrees or a share of a limit, and the ladder
parameters that place the holds it could not reach. The solver's own text
(``IKResult(...)``) stays in `SampleFailure.detail`, for ``-v`` logs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from ladders.spec import LadderSpec
from planner.configuration.ik import HoldMiss
from planner.configuration.validity import Verdict
from primitives.primitive import Step
from robot.vocabulary import RejectCause
from robot.words import joint_words, limb_words, part_words, target_words

#: At most this many reasons are listed for the failing step; the rest are counted.
MAX_REASONS = 3



@dataclass(frozen=True)
class SampleFailure:
    """Why one sample of a step failed, as figures a message can put in user terms.

    Attributes:
        cause: the step's failure key (a `StepFailure` or `InterpolationFailure` value,
            as counted in ``StepStats.failures``).
        stage: where in the step: ``lift-off``, ``way-point 1/3``, ``placing``, ``path``
            (between two poses found) or ``straighten``.
        verdict: the feasibility verdict of the last candidate refused, or None (no
            candidate, or a path failure without one).
        joint_move_rad: for a placed pose that meets its holds only far away, the largest
            joint correction [rad]; NaN otherwise.
        detail: the solver's own message (``IKResult(...)`` and the like), for ``-v``.
    """

    cause: str
    stage: str
    verdict: Verdict | None = None
    joint_move_rad: float = math.nan
    detail: str = ""


def step_words(step: Step) -> str:
    """What a step does: ``left foot onto rung 0``; ``the body straightens``."""
    moves = [f"{limb_words(seed.limb)} onto {target_words(seed.target)}"
             for seed in step.new_holds]
    return ", ".join(moves) if moves else "the body straightens"


def stage_words(stage: str) -> str:
    """``way-point 1/3`` → ``at way-point 1 of 3``; ``lift-off`` → ``lifting off``."""
    if stage.startswith("way-point "):
        return "at " + stage.replace("/", " of ")
    return {"lift-off": "lifting off", "placing": "placing the holds",
            "path": "moving between two poses", "straighten": "straightening"}.get(stage,
                                                                                   stage)


#: Path failures without a verdict, in words (keys: `InterpolationFailure` values).
PATH_FAILURE_WORDS = {
    "projection failed": "a pose on the way could not keep the holds",
    "projection jumped to another IK branch": "the limbs would flip to another posture "
                                              "on the way",
    "resolution not reached": "the path could not be refined to the joint resolution",
}


def _worst_miss(misses: Sequence[HoldMiss]) -> HoldMiss:
    return max(misses, key=lambda m: (m.position_error_m, m.angle_error_rad))


def _reason_key(f: SampleFailure) -> tuple[tuple, float]:
    """What groups ``f`` with other samples' failures, and the size to report the best
    (smallest) of: a distance [m], a torque ratio or a joint turn [rad]."""
    v = f.verdict
    if v is None or v.cause is None:
        return ("other", f.stage, f.cause), (0.0 if math.isnan(f.joint_move_rad)
                                             else f.joint_move_rad)
    if v.cause is RejectCause.IK and v.ik_misses:
        m = _worst_miss(v.ik_misses)
        return ("reach", f.stage, m.limb, m.target), m.position_error_m
    if v.cause is RejectCause.TORQUE:
        return ("torque", f.stage, v.torque_joint), v.torque_ratio
    if v.cause is RejectCause.COM_OUTSIDE:
        return ("com", f.stage), -v.com_margin_m
    if v.cause is RejectCause.COLLISION and v.colliding:
        return ("collision", f.stage, *v.colliding[0]), 0.0
    return (str(v.cause), f.stage), 0.0


def _reason_text(key: tuple, best: SampleFailure, moving: set[str]) -> str:
    """One reason in words, with the best sample's figure."""
    kind, stage = key[0], stage_words(key[1])
    v = best.verdict
    if kind == "reach":
        m = _worst_miss(v.ik_misses)
        reaching = m.limb in moving and best.stage not in ("lift-off", "path")
        verb = "could not reach" if reaching else "could not keep its hold on"
        where = (f"its way-point towards {target_words(m.target)}"
                 if best.stage.startswith("way-point") and reaching
                 else target_words(m.target))
        return (f"{stage}: the {limb_words(m.limb)} {verb} {where}, at best "
                f"{m.position_error_m * 100:.1f} cm and {math.degrees(m.angle_error_rad):.1f}° "
                f"off")
    if kind == "torque":
        return (f"{stage}: {joint_words(v.torque_joint)} needs at best "
                f"{v.torque_ratio:.2f}× its torque limit")
    if kind == "com":
        return (f"{stage}: the centre of mass stays at best {-v.com_margin_m * 100:.1f} cm "
                f"outside what the holds can support")
    if kind == "collision":
        return f"{stage}: {part_words(key[2])} hits {part_words(key[3])}"
    if kind == str(RejectCause.UNBALANCEABLE_STANCE):
        return f"{stage}: the holds cannot carry the robot's weight"
    if kind == str(RejectCause.JOINT_LIMITS):
        return f"{stage}: a joint would pass its limit"
    if kind == str(RejectCause.WRIST_SINGULARITY):
        return (f"{stage}: a hand on its hold would need its wrist straight (pitch near "
                f"zero), where the arm cannot turn it and the grip takes the load")
    if not math.isnan(best.joint_move_rad):
        return (f"{stage}: meeting the holds exactly would turn a joint by at best "
                f"{math.degrees(best.joint_move_rad):.0f}°")
    return f"{stage}: {PATH_FAILURE_WORDS.get(key[2], key[2])}"


def ladder_parameters(target: str, spec: LadderSpec) -> str:
    """The ladder parameters that place ``target`` (a hold or ladder piece) relative to
    the robot, with their values; ``""`` for the floor and robot parts."""
    slope = f"slope {spec.slope_deg:g}°"
    kind = target.split("_")[0]
    if kind == "rail":
        return (f"{slope}, rails {spec.rail_spacing_m:g} m apart and "
                f"{spec.rail_height_m:g} m above the rungs")
    if kind == "stringer":
        return f"{slope}, rails {spec.rail_spacing_m:g} m apart"
    if kind == "rung":
        rung = int(target.split("_")[1])
        first = f"first rung {spec.first_rung_height_m:g} m high"
        return (f"{slope}, {first}" if rung == 0 else
                f"{slope}, {first}, rungs {spec.rung_spacing_m:g} m apart")
    return ""


def _reason_parameters(key: tuple, best: SampleFailure, spec: LadderSpec) -> str:
    """``; set by …`` for a hold a limb could not reach or a ladder piece it hits."""
    if key[0] == "reach":
        params = ladder_parameters(key[3], spec)
    elif key[0] == "collision":
        params = ladder_parameters(key[3], spec) or ladder_parameters(key[2], spec)
    else:
        params = ""
    return f" (set by the ladder's {params})" if params else ""


def reasons(failures: Sequence[SampleFailure], step: Step, spec: LadderSpec
            ) -> list[tuple[int, str]]:
    """The failures grouped by reason, most frequent first: (samples, words)."""
    groups: dict[tuple, tuple[int, float, SampleFailure]] = {}
    for f in failures:
        key, size = _reason_key(f)
        n, best_size, best = groups.get(key, (0, math.inf, f))
        groups[key] = (n + 1, size, f) if size < best_size else (n + 1, best_size, best)
    moving = set(step.primitive.moving_limbs)
    ordered = sorted(groups.items(), key=lambda kv: -kv[1][0])
    return [(n, _reason_text(key, best, moving) + _reason_parameters(key, best, spec))
            for key, (n, _, best) in ordered]


def explain_no_plan(deepest: Step, failures: Sequence[SampleFailure], spec: LadderSpec,
                    stop: str, stopped_at: Step | None = None) -> str:
    """The ``no plan:`` message: the furthest step the search reached, what it does, why
    its samples failed (grouped, counted, each with its best figure and the ladder
    parameters that place the hold), and where and why the search stopped.

    Args:
        deepest: the furthest step reached (the one that failed, or the deepest one the
            search backtracked from).
        failures: every failed sample of ``deepest``, over all its visits.
        spec: the ladder, for its parameters.
        stop: why the search stopped, in words (``every sample failed``, ``the time
            limit of 150 s ran out``).
        stopped_at: the step where the search stopped when it is not ``deepest`` (it
            backtracked from there), else None.
    """
    where = f"{deepest.primitive.name} at rung {deepest.rung} ({step_words(deepest)})"
    if stopped_at is None or stopped_at.label == deepest.label:
        head = f"no plan: {where}: {stop}"
    else:
        head = (f"no plan: {where}, the furthest step reached, failed; the search "
                f"backtracked to {stopped_at.primitive.name} at rung {stopped_at.rung} and "
                f"stopped there: {stop}")
    if not failures:
        return head + "; no sample of the furthest step had finished"
    lines = [f"{head}. Its {len(failures)} failed samples, by reason:"]
    found = reasons(failures, deepest, spec)
    lines += [f"  {n} × {words}" for n, words in found[:MAX_REASONS]]
    if len(found) > MAX_REASONS:
        rest = sum(n for n, _ in found[MAX_REASONS:])
        lines.append(f"  {rest} × other reasons ({len(found) - MAX_REASONS} more)")
    return "\n".join(lines)
