"""hubo-view and validate-plan --record: recordings of a short plan and of its simulated
runs, read back from the .rrd file (entities, time range, events, how it opens), and the
bad inputs refused with exit 2."""

from __future__ import annotations

import json
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from make_fixture import cached_reach_fixture  # noqa: E402

pytest.importorskip("rerun")

import pyarrow as pa  # noqa: E402
from rerun.chunk import RrdReader  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

from execute.validate.cli import main as validate_main  # noqa: E402
from execute.view.cli import default_output  # noqa: E402
from execute.view.cli import main as view_main  # noqa: E402
from execute.view.plan_poses import PlanKinematics  # noqa: E402
from execute.view.run_recording import peak_samples  # noqa: E402
from execute.view.scene_meshes import body_meshes  # noqa: E402
from execute.view.viewer import failure_time  # noqa: E402
from ladders.loader import sidecar_ladder  # noqa: E402
from robot.plan_sidecar import read_sidecar, sidecar_path  # noqa: E402
from robot.trajectory_file import read_trajectory  # noqa: E402


class Entity:
    """What a recording holds under one entity path."""

    def __init__(self) -> None:
        self.columns: set[str] = set()
        self.times_s: list[float] = []
        self.texts: list[str] = []
        self.static = False


def read_recording(path: Path) -> dict[str, Entity]:
    """Entity path → its columns, times [s] and text events, from the file."""
    out: dict[str, Entity] = defaultdict(Entity)
    for chunk in RrdReader(path).stream():
        e = out[chunk.entity_path]
        batch = chunk.to_record_batch()
        e.columns.update(batch.schema.names)
        e.static |= chunk.is_static
        if "time" in batch.schema.names:
            e.times_s += [ns * 1e-9 for ns in batch.column("time").cast(pa.int64()).to_pylist()]
        if "TextLog:text" in batch.schema.names:
            e.texts += [t[0] for t in batch.column("TextLog:text").to_pylist()]
    return out


def time_panel(path: Path) -> dict[str, list]:
    """The blueprint's time panel fields (timeline, play state, selection...)."""
    reader = RrdReader(path)
    fields = {}
    for chunk in reader.stream(store=reader.blueprints()[0]):
        if chunk.entity_path == "/time_panel":
            batch = chunk.to_record_batch()
            for name in batch.schema.names:
                if name.startswith("TimePanelBlueprint:"):
                    col = batch.column(name)
                    if pa.types.is_list(col.type) and pa.types.is_struct(col.type.value_type):
                        fields[name.split(":")[1]] = col.to_pylist()[0][0]
                    else:
                        fields[name.split(":")[1]] = col.to_pylist()[0]
    return fields


@pytest.fixture(scope="module")
def plan(tmp_path_factory):
    path = cached_reach_fixture(tmp_path_factory.getbasetemp())
    sidecar = read_sidecar(sidecar_path(path))
    return path, sidecar, read_trajectory(path, sidecar.rate_hz, sidecar.robot)


@pytest.fixture(scope="module")
def plan_recording(plan, tmp_path_factory):
    path = plan[0]
    out = tmp_path_factory.mktemp("view") / "plan.rrd"
    assert view_main([str(path), "-o", str(out)]) == 0
    return out, read_recording(out)


def test_a_plan_recording_has_the_robot_the_ladder_and_the_holds(plan, plan_recording):
    path, sidecar, traj = plan
    out, rec = plan_recording
    kin = PlanKinematics(traj, sidecar, sidecar_ladder(sidecar, str(path)))
    robot = {m.name for m in body_meshes(kin.model) if kin.model.body_weldid[m.body] != 0}
    assert {"pelvis", "L_foot", "R_hand", "head"} <= robot
    for body in robot:
        e = rec[f"/world/plan/robot/{body}"]
        assert {"Mesh3D:vertex_positions", "Transform3D:translation"} <= e.columns
    assert "Mesh3D:vertex_positions" in rec["/world/ladder"].columns
    assert "Mesh3D:vertex_positions" in rec["/world/floor"].columns
    assert "Points3D:labels" in rec["/world/plan/holds"].columns
    assert "LineStrips3D:strips" in rec["/world/plan/support_region"].columns
    assert "Arrows3D:vectors" in rec["/world/plan/hold_forces"].columns
    assert "Points3D:positions" in rec["/world/plan/com"].columns


def test_a_plan_recording_covers_the_plan_and_names_every_segment(plan, plan_recording):
    _, sidecar, traj = plan
    _, rec = plan_recording
    times = rec["/world/plan/robot/pelvis"].times_s
    assert min(times) == 0.0
    assert max(times) == pytest.approx((len(traj) - 1) / sidecar.rate_hz)
    texts = rec["/events/segment"].texts
    assert len(texts) == len(sidecar.segments)
    assert all(seg.primitive in text for seg, text in zip(sidecar.segments, texts,
                                                          strict=True))
    starts = sorted(rec["/events/segment"].times_s)
    assert starts == pytest.approx([(s.first_line - 1) / sidecar.rate_hz
                                    for s in sidecar.segments])
    margin = rec["/plan/stability_margin_cm"].times_s
    assert len(margin) == len(times)


def test_the_plan_is_placed_where_its_holds_are(plan):
    """The palms of the last segment's held hands (MuJoCo's palm sites on the placed
    bodies) are at the sidecar's holds."""
    path, sidecar, traj = plan
    kin = PlanKinematics(traj, sidecar, sidecar_ladder(sidecar, str(path)))
    seg = sidecar.segments[-1]
    poses = kin.poses(np.array([seg.last_line - 1]))
    m = kin.model
    assert poses.placed.all()
    for limb, site in (("left_hand", "L_palm"), ("right_hand", "R_palm"),
                       ("left_foot", "L_sole")):
        s = m.site(site)
        body = int(m.site_bodyid[s.id])
        R = Rotation.from_quat(poses.body_quat_xyzw[0, body]).as_matrix()
        p = poses.body_pos_m[0, body] + R @ m.site_pos[s.id]
        assert np.linalg.norm(p - seg.holds[limb].position_m) < 0.01, limb


def test_peak_samples_keep_the_largest_magnitude_of_each_window():
    v = np.zeros((10, 2))
    v[3, 0], v[7, 1], v[9, 0] = -5.0, 2.0, 1.0
    assert peak_samples(v, 4).tolist() == [[-5, 0], [0, 2], [1, 0]]  # last: padded


def test_validate_plan_records_a_run_with_its_grasps(plan, tmp_path):
    path, sidecar, traj = plan
    out, result = tmp_path / "run.rrd", tmp_path / "run.json"
    assert validate_main([str(path), "--record", str(out), "--json", str(result)]) == 0
    rec = read_recording(out)
    for body in ("pelvis", "L_hand", "R_foot"):
        assert "Transform3D:translation" in rec[f"/world/sim/robot/{body}"].columns
        assert "Transform3D:translation" in rec[f"/world/plan/robot/{body}"].columns
        # the plan is a translucent ghost: one colour with alpha (Rerun blends a mesh's
        # albedo factor, not its vertex colours); the simulated robot has the geoms' colours
        assert "Mesh3D:albedo_factor" in rec[f"/world/plan/robot/{body}"].columns
        assert "Mesh3D:vertex_colors" in rec[f"/world/sim/robot/{body}"].columns
    grasps = rec["/events/grasp"]
    assert len(grasps.texts) == 2 and all("latched" in t for t in grasps.texts)
    # the grasp events sit at the simulated times the result reports
    reported = [float(g.split(" at t = ")[1].split(" s")[0])
                for g in json.loads(result.read_text())["grasp_events"]]
    assert sorted(grasps.times_s) == pytest.approx(sorted(reported), abs=0.006)
    assert rec["/events/verdict"].texts[0].startswith("climbed")
    assert len(rec["/events/segment"].texts) == len(sidecar.segments)
    assert "Scalars:scalars" in rec["/sim/tracking_error_rad/LSP"].columns
    assert "Scalars:scalars" in rec["/sim/torque_nm/LKN"].columns
    assert "Scalars:scalars" in rec["/sim/fingers/tracking_error_rad/LF1"].columns
    assert "/sim/tracking_error_rad/LF1" not in rec
    assert "Arrows3D:vectors" in rec["/world/sim/grip_forces/left"].columns
    grip = rec["/world/sim/grip_forces/left"]  # the latch's load every 0.1 s while latched
    assert {"Arrows3D:origins", "Arrows3D:labels", "Arrows3D:colors"} <= grip.columns
    assert len(grip.times_s) > 10
    assert max(rec["/world/sim/robot/pelvis"].times_s) >= (len(traj) - 1) / sidecar.rate_hz


def test_a_failed_run_opens_at_its_failure(plan, tmp_path):
    """Open loop with the ladder 8 cm further than planned: the hands close on nothing."""
    path = plan[0]
    out, result = tmp_path / "fail.rrd", tmp_path / "fail.json"
    code = validate_main([str(path), "--open-loop", "--placement-error", "0.08,0,0",
                          "--record", str(out), "--json", str(result)])
    assert code == 1
    failure_s = json.loads(result.read_text())["time_s"]
    rec = read_recording(out)
    assert rec["/events/failure"].times_s == [pytest.approx(failure_s)]
    assert "grasp_not_latched" in rec["/events/failure"].texts[0]
    assert all("missed" in t for t in rec["/events/grasp"].texts)
    assert failure_time(out) == pytest.approx(failure_s)
    panel = time_panel(out)
    assert panel["timeline"] == ["time"]
    selection = panel["time_selection"]
    assert selection["max"] * 1e-9 == pytest.approx(failure_s + 0.5)
    assert selection["min"] * 1e-9 == pytest.approx(max(0.0, failure_s - 7.0))


def test_hubo_view_of_a_result_puts_its_failure_on_the_plan(plan, tmp_path):
    path, sidecar, _ = plan
    result = {"plan": str(path), "verdict": "failed", "cause": "fall", "time_s": 3.2,
              "line": 60, "why": "the pelvis dropped", "strategy": "mixed", "loop": "closed",
              "motion": {"events": [{"kind": "arrival wait", "time_s": 2.0, "line": 40,
                                     "cause": "waited"}]}}
    where = tmp_path / "r.result.json"
    where.write_text(json.dumps(result))
    assert view_main([str(where)]) == 0
    out = default_output(where)
    assert out == tmp_path / "r.result.rrd"
    rec = read_recording(out)
    assert rec["/events/failure"].times_s == [pytest.approx(59 / sidecar.rate_hz)]
    assert rec["/events/motion"].times_s == [pytest.approx(39 / sidecar.rate_hz)]
    # the plan as far as the run got: it ends 0.5 s past the failure, where a viewer opens
    end, dt = max(rec["/world/plan/robot/pelvis"].times_s), 1 / sidecar.rate_hz
    assert 59 * dt + 0.5 - dt <= end <= 59 * dt + 0.5
    assert time_panel(out)["time_selection"]["max"] * 1e-9 == \
        pytest.approx(59 / sidecar.rate_hz + 0.5)


def _bad(argv, capsys, main=view_main) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err  # one line, no traceback
    return err


def test_bad_inputs_exit_2_naming_the_file(plan, tmp_path, capsys):
    path = plan[0]
    missing = tmp_path / "nope.traj"
    assert f"{missing}: no such file" in _bad([str(missing)], capsys)
    other = tmp_path / "notes.txt"
    other.write_text("x")
    assert "hubo-view reads a plan" in _bad([str(other)], capsys)
    lone = tmp_path / "lone.traj"
    lone.write_text(path.read_text())
    assert "lone.plan.json: no plan sidecar" in _bad([str(lone)], capsys)
    garbled = tmp_path / "g.json"
    garbled.write_text("{not json")
    assert f"{garbled}: not a JSON document" in _bad([str(garbled)], capsys)
    wrong = tmp_path / "w.json"
    wrong.write_text(json.dumps({"verdict": "climbed"}))
    assert "not a validate-plan result" in _bad([str(wrong)], capsys)
    lost = tmp_path / "l.json"
    lost.write_text(json.dumps({"plan": "gone/x.traj", "verdict": "climbed"}))
    assert "field 'plan': gone/x.traj not found" in _bad([str(lost)], capsys)
    assert "a recording is written as a .rrd file" in _bad(
        [str(path), "-o", str(tmp_path / "x.txt")], capsys)
    assert "--display-hz 0" in _bad([str(path), "--display-hz", "0"], capsys)
    assert "no folder" in _bad([str(path), "-o", str(tmp_path / "a" / "b.rrd")], capsys)
    recording = tmp_path / "run.rrd"
    recording.write_bytes(b"")
    assert "opened with --open or --screenshot" in _bad([str(recording)], capsys)
    assert "--serve is its own viewer" in _bad([str(path), "--serve", "--open"], capsys)
    assert "--at -1" in _bad([str(recording), "--open", "--at", "-1"], capsys)
    assert "a screenshot is a .png" in _bad([str(recording), "--screenshot", "x.jpg"], capsys)


def test_without_rerun_hubo_view_says_how_to_install_it(plan, tmp_path):
    """No rerun-sdk: one line that names the extra, for a plan and for a recording, not a
    traceback from the first module that imports Rerun."""
    code = ("import sys\nsys.modules['rerun'] = None  # as if rerun-sdk were not installed\n"
            "from execute.view.cli import main\nsys.exit(main(sys.argv[1:]))")
    recording = tmp_path / "run.rrd"
    recording.write_bytes(b"")
    for argv in ([str(plan[0]), "-o", str(tmp_path / "plan.rrd")], [str(recording), "--open"]):
        done = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True,
                              text=True)
        assert done.returncode == 1, done.stderr
        assert done.stderr.count("\n") == 1, done.stderr
        assert "need the rerun-sdk package: pip install -e '.[view]'" in done.stderr


def test_validate_plan_refuses_a_bad_record_path_before_simulating(plan, tmp_path, capsys):
    err = _bad([str(plan[0]), "--record", str(tmp_path / "run.mp4")], capsys, validate_main)
    assert "run.mp4: a recording is written as a .rrd file" in err


@pytest.mark.parametrize("hz", ["0", "500"])
def test_validate_plan_refuses_a_record_rate_out_of_range_before_simulating(plan, tmp_path,
                                                                             capsys, hz):
    err = _bad([str(plan[0]), "--record", str(tmp_path / "run.rrd"), "--record-hz", hz],
               capsys, validate_main)
    assert f"--record-hz {hz}: choose a rate within [0.1, 200] Hz" in err
    assert not (tmp_path / "run.rrd").exists()


@pytest.mark.skipif(not list(Path("/usr/share/vulkan/icd.d").glob("*.json")),
                    reason="no Vulkan driver for a headless viewer (Debian: "
                           "mesa-vulkan-drivers)")
def test_a_headless_viewer_shows_the_plan_recording(plan_recording, tmp_path, capsys):
    """Rerun's own viewer, headless, opens the file at 3 s and takes a screenshot: the
    picture is the viewer's layout with the 3D view drawn (many colours, not a blank)."""
    from PIL import Image

    out, _ = plan_recording
    shot = tmp_path / "plan.png"
    assert view_main([str(out), "--screenshot", str(shot), "--at", "3"]) == 0
    assert "at t = 3 s" in capsys.readouterr().out
    image = Image.open(shot).convert("RGB")
    assert image.width >= 800 and image.height >= 600
    assert len(image.getcolors(maxcolors=1 << 20) or ()) > 500


def test_importing_the_viewer_loads_neither_rerun_nor_mujoco():
    code = ("import sys\nimport execute.view\n"
            "print(','.join(m for m in ('rerun', 'mujoco', 'pinocchio') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == ""
