"""plan-ladder: exit codes and messages, the written files, plots, determinism."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from synthetic_plan import use_synthetic_search  # noqa: E402

from ladders.loader import ladder_to_yaml, load_ladder  # noqa: E402
from planner.cli import main  # noqa: E402
from planner.search import ClimbPlanner  # noqa: E402
from planner.verify import cli as check_plan_cli  # noqa: E402
from robot.plan_sidecar import read_sidecar, sidecar_path  # noqa: E402


def _spec_file(tmp_path: Path, name: str, **changes: str) -> Path:
    text = ladder_to_yaml(load_ladder("drc")).replace("name: drc", f"name: {name}")
    for old, new in changes.items():
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    return path


def test_bad_spec_exits_2_naming_the_field(tmp_path, capsys):
    bad = _spec_file(tmp_path, "bad", **{"slope_deg: 60.0": "slope_deg: 10.0"})
    assert main([str(bad), "-o", str(tmp_path / "x.traj")]) == 2
    err = capsys.readouterr().err
    assert f"{bad}:" in err and "slope_deg" in err and "[30, 90]" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.traj").exists()


@pytest.mark.parametrize("argv, words", [
    (["nosuch"], "unknown ladder 'nosuch'"),
    (["drc", "--top-rung", "9"], "--top-rung is 9"),
    (["drc", "--rate", "0"], "--rate is 0"),
    (["drc", "--samples", "0"], "--samples is 0"),
    (["drc", "--max-torque-ratio", "1.2"], "--max-torque-ratio is 1.2; it must be in (0, 1]"),
    (["drc", "--position-torque-share", "0"],
     "--position-torque-share is 0; it must be in (0, 1]"),
    (["drc", "--reserve-torque-share", "0.95"],
     "--reserve-torque-share is 0.95; it must be in (0, --position-torque-share]"),
    (["drc", "--reserve-samples", "-1"], "--reserve-samples is -1; it must be ≥ 0"),
    (["drc", "--foot-cop-margin", "0.05"], "--foot-cop-margin is 0.05; it must be in [0, 0.04]"),
    (["drc", "--foot-friction-share", "1.2"],
     "--foot-friction-share is 1.2; it must be in (0, 1]"),
    (["drc", "--held-wrist-margin", "0.6"],
     "--held-wrist-margin is 0.6; it must be in [0, 0.5] rad"),
    (["drc", "--robot", "asimo"], "invalid choice"),
])
def test_bad_options_exit_2(argv, words, capsys):
    assert main(argv) == 2
    assert words in capsys.readouterr().err


def test_time_limit_gives_exit_1_with_primitive_and_rung(tmp_path, capsys):
    t0 = time.monotonic()
    assert main(["drc", "--time-limit", "0.001", "-o", str(tmp_path / "t.traj")]) == 1
    assert time.monotonic() - t0 < 30  # the CLI stops a sample that runs past the limit
    err = capsys.readouterr().err
    assert "no plan: placeHands at rung 0 (left hand onto the left rail, right hand onto " \
           "the right rail): time limit of 0.001 s reached" in err
    assert not (tmp_path / "t.traj").exists()


def test_unreachable_ladder_gives_exit_1(tmp_path, capsys):
    far = _spec_file(tmp_path, "far", **{"x_m: 0.16": "x_m: 4.0"})
    assert main([str(far), "--samples", "2", "--time-limit", "60",
                 "-o", str(tmp_path / "far.traj")]) == 1
    err = capsys.readouterr().err
    assert "no plan: placeHands at rung 0 (left hand onto the left rail, right hand onto " \
           "the right rail): every sample failed. Its 2 failed samples, by reason:" in err
    assert "IKResult(" not in err


@pytest.fixture
def fake_search(monkeypatch):
    """The search replaced by the synthetic plan (the real one is slow for now)."""
    return use_synthetic_search(monkeypatch)


def test_happy_path_writes_checkable_files_and_plots(fake_search, tmp_path, capsys):
    out = tmp_path / "climb.traj"
    plots = tmp_path / "plots"
    assert main(["drc", "--top-rung", "0", "--seed", "7", "-o", str(out),
                 "--plots", str(plots)]) == 0
    cap = capsys.readouterr()
    assert "straighten@rung0" in cap.out and "backtracks" in cap.out
    assert f"wrote {out}" in cap.err
    sc = read_sidecar(sidecar_path(out))
    assert sc.seed == 7 and sc.rate_hz == 200.0
    pngs = sorted(plots.glob("stance_*.png"))
    assert len(pngs) == 1 and pngs[0].stat().st_size > 10_000  # one stance: both feet
    strip = plots / "snapshots.png"
    if strip.exists():
        import imageio.v3 as iio

        from ladders.render import SNAPSHOT_SIZE

        image = iio.imread(strip)
        assert image.shape[1] == 6 * SNAPSHOT_SIZE[0]  # six frames, captioned below:
        assert SNAPSHOT_SIZE[1] < image.shape[0] < SNAPSHOT_SIZE[1] + 80
        assert image.std() > 10  # a scene, not a blank frame
    else:
        assert "no snapshot strip" in cap.err
    assert check_plan_cli.main([str(out), "--ladder", "drc", "--every", "25"]) == 0


def test_same_seed_same_file(fake_search, tmp_path):
    a, b, c = (tmp_path / f"{n}.traj" for n in "abc")
    assert main(["drc", "--top-rung", "0", "-o", str(a)]) == 0
    assert main(["drc", "--top-rung", "0", "-o", str(b)]) == 0
    assert a.read_bytes() == b.read_bytes()
    assert main(["drc", "--top-rung", "0", "--rate", "100", "-o", str(c)]) == 0
    assert c.read_bytes() != a.read_bytes()


def test_real_mount_plan_is_deterministic_and_checks(tmp_path):
    """The real search (compliant arms) over the DRC mount, twice: ≈ 10 s each."""
    a, b = tmp_path / "a.traj", tmp_path / "b.traj"
    for path in (a, b):
        assert main(["drc", "--top-rung", "0", "--seed", "1", "--time-limit", "60",
                     "-o", str(path)]) == 0
    assert a.read_bytes() == b.read_bytes()
    assert check_plan_cli.main([str(a), "--ladder", "drc", "--every", "5"]) == 0


def test_plan_qpos_puts_the_scene_robot_where_the_planner_has_it():
    # The strip draws planned configurations in MuJoCo: the feet and palms of the
    # converted qpos must land where the planner's (pinocchio) model puts them.
    import mujoco

    from ladders.scene import build_scene
    from planner.plots import plan_qpos

    planner = ClimbPlanner(load_ladder("drc"), seed=1)
    q, _ = planner.start_configuration()
    q = q.copy()
    q[planner.kin.q_index["LSP"]] = -0.7  # an asymmetric pose, so a swapped column shows
    q[planner.kin.q_index["REB"]] = -1.1
    model = build_scene(load_ladder("drc")).compile()
    data = mujoco.MjData(model)
    data.qpos[:] = plan_qpos(model, planner.kin, q[None])[0]
    mujoco.mj_kinematics(model, data)
    for site, frame in (("L_sole", "L_sole"), ("R_sole", "R_sole"), ("L_palm", "L_palm"),
                        ("R_palm", "R_palm")):
        np.testing.assert_allclose(data.site(site).xpos,
                                   planner.kin.frame_pose(q, frame)[:3, 3], atol=1e-6)


def test_ladder_placed_on_the_robot_exits_2_naming_the_placement(tmp_path, capsys):
    inside = _spec_file(tmp_path, "inside", **{"x_m: 0.16": "x_m: -0.2"})
    assert main([str(inside), "-o", str(tmp_path / "i.traj")]) == 2
    err = capsys.readouterr().err
    assert "placement_x_m = -0.2 m" in err and "farther away" in err
    assert not (tmp_path / "i.traj").exists()
