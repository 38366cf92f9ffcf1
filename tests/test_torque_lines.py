"""check-plan's torque LP on many lines (one basis carried from line to line, HiGHS only
where it stops being optimal) answers what `torque_feasibility` answers line by line."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from synthetic_plan import write_synthetic_plan  # noqa: E402

from ladders.loader import load_ladder  # noqa: E402
from planner.contacts import Stance  # noqa: E402
from planner.statics.torque_lp import torque_feasibility  # noqa: E402
from planner.verify.check import PlanVerifier  # noqa: E402
from planner.verify.line_pass import _grip_use, _utilisation  # noqa: E402
from planner.verify.torque_lines import StanceLines  # noqa: E402
from robot.plan_sidecar import HoldRecord, read_sidecar, sidecar_path  # noqa: E402


@pytest.fixture(scope="module")
def plan(tmp_path_factory):
    path = write_synthetic_plan(tmp_path_factory.mktemp("plan") / "good.traj")
    return np.loadtxt(path), read_sidecar(sidecar_path(path))


def test_the_batch_lp_is_torque_feasibility_line_by_line(plan):
    """The left foot and the right hand gripping (a rail's grip at the palm, wherever it
    is), so that the grip carries load and the optimal basis changes as the body rises:
    the worst joint ratio and the grip's wrench on every line. (Which joint reaches the
    worst ratio is not the LP's to say: several do at its optimum.)"""
    traj, side = plan
    v = PlanVerifier(load_ladder("drc"), side.robot, "mixed")
    seg = side.segments[3]
    rows = np.arange(seg.first_line - 1, seg.last_line)
    poses, q = v.line_poses(traj[rows], seg)
    palm = v.frame_positions(poses, "right_hand")[0]
    left_foot = next(h for h in v.stance(3, seg).stance.holds if h.limb == "left_foot")
    hand = v.contact_hold("right_hand", HoldRecord("rail_right", tuple(palm)))
    stance = Stance((left_foot, hand))
    limits = v.stance(3, seg).torque_limits
    lines = StanceLines(v.kin, stance.holds, limits, v.frame_id)
    out = lines.solve(poses)
    assert 1 < lines.highs_solves < len(rows) / 10  # the basis carries from line to line
    assert np.abs(out.grip_wrench["right_hand"]).max() > 10.0  # [N]: the grip holds
    for i in range(len(rows)):
        tq = torque_feasibility(v.model, v.data, q[i], stance, limits, v.frame_id)
        assert out.equilibrium[i] == tq.equilibrium
        assert out.max_ratio[i] == pytest.approx(tq.max_ratio, abs=1e-7)
        force, torque = tq.wrenches["right_hand"]
        np.testing.assert_allclose(out.grip_wrench["right_hand"][i],
                                   np.concatenate([force, torque]), atol=1e-3)


def test_grip_use_of_many_wrenches_is_the_latch_capacitys():
    from ladders.contact_model import GRIP_LOADS, hand_limits

    limits = hand_limits(0.4, 0.025, np.array([0.3, 0.0, 0.95]))
    rng = np.random.default_rng(2)
    force, torque = rng.normal(scale=80.0, size=(50, 3)), rng.normal(scale=4.0, size=(50, 3))
    use = _utilisation(limits, force, torque)
    for i in range(50):
        one = limits.utilisation(force[i], torque[i])
        np.testing.assert_allclose(use[i], [one[load] for load in GRIP_LOADS], rtol=1e-12)


def test_grip_use_names_the_grip_as_the_per_line_account_does():
    """The batch's most used grip limit and its clause are `contact_wrench_utilisation`'s
    on the same wrench; no load on a grip is "no grip"."""
    from types import SimpleNamespace

    from ladders.contact_model import hand_limits
    from planner.statics.torque_lp import TorqueCheck
    from planner.verify.check import contact_wrench_utilisation
    from planner.verify.torque_lines import LineTorques

    limits = hand_limits(0.4, 0.025, np.array([0.3, 0.0, 0.95]))
    hand = SimpleNamespace(limb="right_hand", limits=limits)
    wrenches = np.array([[0.0, 30.0, 140.0, 1.0, -2.0, 0.5], np.zeros(6)])
    lp = LineTorques(np.ones(2, dtype=bool), np.full(2, 0.5), np.zeros(2, dtype=int),
                     {"right_hand": wrenches})
    use, clause = _grip_use([hand], lp)
    for i, w in enumerate(wrenches):
        one = TorqueCheck(True, True, 0.5, "", wrenches={"right_hand": (w[:3], w[3:])},
                          contact_use={"right_hand": limits.utilisation(w[:3], w[3:])})
        expected = contact_wrench_utilisation(one)
        assert use[i] == pytest.approx(expected.value, rel=1e-12)
        assert clause(i) == expected.detail
    assert clause(1) == "no grip"
