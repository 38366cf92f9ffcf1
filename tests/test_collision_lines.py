"""check-plan's collision pass on many lines asks coal only about pairs a bound cannot
clear, and finds what `CollisionModel` finds on every line: the same flags, the same
clearances."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from synthetic_plan import write_synthetic_plan  # noqa: E402

from ladders.loader import load_ladder  # noqa: E402
from planner.verify.check import PlanVerifier, allowed_contacts  # noqa: E402
from planner.verify.collision_lines import CollisionLines, segment_distance  # noqa: E402
from robot.joints import JOINT_INDEX  # noqa: E402
from robot.plan_sidecar import read_sidecar, sidecar_path  # noqa: E402


def test_segment_distance_against_sampled_points():
    rng = np.random.default_rng(5)
    n = 120
    p1, q1, p2, q2 = (rng.normal(size=(n, 3)) for _ in range(4))
    q1[:20] = p1[:20]  # points
    q2[10:30] = p2[10:30]
    q2[30:50] = p2[30:50] + 2.0 * (q1[30:50] - p1[30:50])  # parallel
    q1[50:55] = p1[50:55] + [0.0, 0.0, 1e-13]  # nearly points
    d = segment_distance(p1, q1, p2, q2)
    s = np.linspace(0.0, 1.0, 401)[:, None]
    for i in range(n):
        a, b = p1[i] + s * (q1[i] - p1[i]), p2[i] + s * (q2[i] - p2[i])
        sampled = np.sqrt(((a[:, None] - b[None]) ** 2).sum(axis=2)).min()
        assert d[i] <= sampled + 1e-12, i  # a lower bound of every sampled pair ...
        assert d[i] == pytest.approx(sampled, abs=1e-2), i  # ... and the distance itself


@pytest.fixture(scope="module")
def plan(tmp_path_factory):
    path = write_synthetic_plan(tmp_path_factory.mktemp("plan") / "good.traj")
    return np.loadtxt(path), read_sidecar(sidecar_path(path))


def test_flags_and_clearances_are_the_collision_models(plan):
    traj, side = plan
    v = PlanVerifier(load_ladder("drc"), side.robot, "mixed")
    lines = CollisionLines(v.collision)
    seg = side.segments[3]  # the rise, both feet on the floor
    rows = np.arange(seg.first_line - 1, seg.last_line)
    cols = traj[rows].copy()
    # Fold the standing leg on every 7th line: the body drops, a shin goes into the floor.
    cols[::7, JOINT_INDEX["LHP"]], cols[::7, JOINT_INDEX["LKN"]] = -1.4, 2.5
    poses, q = v.line_poses(cols, seg)
    contacts = allowed_contacts(side.segments, 3, 0.8)
    wanted = np.arange(0, len(rows), 5)
    out = lines.check(poses, q, lines.active(contacts), wanted)
    v.collision.allow(contacts)
    assert out.hit[::7].all() and not out.hit[1::7].any()
    col = v.collision
    for i in range(len(rows)):
        assert out.hit[i] == col.in_collision(q[i]), i
        if not (out.hit[i] or i % 5 == 0):
            assert np.isnan(out.clearance_m[i])
            continue
        # coal's distances move by ~1e-7 with its cached guesses: equal to 1e-6.
        pin.computeDistances(v.model, v.data, col.geom, col.gdata, q[i])
        dist = {" – ".join(lines.names[k]): col.gdata.distanceResults[int(k)].min_distance
                for k in np.flatnonzero(lines.active(contacts))}
        smallest = min(dist.values())
        assert out.clearance_m[i] == pytest.approx(smallest, abs=1e-6), i
        assert dist[out.pair[i]] == pytest.approx(smallest, abs=1e-6), i
