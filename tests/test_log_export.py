"""`daemon.log_export`: a state log exported to MCAP decodes back to the logged values."""

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("mcap_ros2")

from mcap.reader import make_reader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402

from daemon.log_export import decimate, export_mcap, main, msgdef  # noqa: E402
from daemon.state_log import LOG_DTYPE, StateLogWriter  # noqa: E402
from daemon.structs import FT_NAMES, IMU_NAMES, STATE_DTYPE  # noqa: E402
from robot.joints import JOINT_NAMES, NUM_JOINTS  # noqa: E402

TICK_S = 0.005


def synthetic_records(n: int, dtype: np.dtype = LOG_DTYPE, seed: int = 7) -> np.ndarray:
    """``n`` records at 200 Hz with seeded random joints, FT and IMU values, the player
    playing and then held by the watchdog for the last fifth."""
    rng = np.random.default_rng(seed)
    r = np.zeros(n, dtype=dtype)
    r["time_s"] = 1.25 + np.arange(n) * TICK_S
    r["pos"] = rng.uniform(-2.0, 2.0, (n, NUM_JOINTS))
    r["vel"] = rng.normal(0.0, 0.5, (n, NUM_JOINTS))
    r["ref"] = r["pos"] + rng.normal(0.0, 0.01, (n, NUM_JOINTS))
    r["cur"] = rng.uniform(0.0, 3.0, (n, NUM_JOINTS))
    for f in ("mx", "my", "fz"):
        r["ft"][f] = rng.normal(0.0, 100.0, (n, len(FT_NAMES)))
    for f in ("ax", "ay", "az", "wx", "wy", "wz"):
        r["imu"][f] = rng.normal(0.0, 3.0, (n, len(IMU_NAMES)))
    if "playing" in dtype.names:
        r["playing"] = 1
        r["watchdog"][4 * n // 5:] = 1
        r["ref_age_ms"] = rng.uniform(0.0, 20.0, n).astype(np.float32)
    return r


def write_log(path: Path, records: np.ndarray, meta: dict | None = None) -> Path:
    with StateLogWriter(path, records.dtype, meta=meta or {"backend": "sim",
                                                           "instance": "test"}) as w:
        for rec in records:
            w.append(rec)
    return path


def by_topic(path: Path) -> dict[str, list]:
    """Topic → decoded messages, as (ROS message, MCAP log time [ns]) pairs."""
    out: dict[str, list] = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, message, ros_msg in reader.iter_decoded_messages():
            out.setdefault(channel.topic, []).append((ros_msg, message.log_time))
    return out


@pytest.fixture
def exported(tmp_path):
    records = synthetic_records(50)
    log = write_log(tmp_path / "run.hlog", records)
    result = export_mcap(log, tmp_path / "run.mcap")
    return records, result, by_topic(tmp_path / "run.mcap")


def test_joint_positions_and_stamps_round_trip_exactly(exported):
    records, result, topics = exported
    msgs = topics["/joint_states"]
    assert len(msgs) == len(records) == result.records
    expected_ns = [round(t * 1e9) for t in records["time_s"].tolist()]
    for k, m in enumerate(msgs):
        js, log_time_ns = m
        assert list(js.name) == list(JOINT_NAMES)
        assert np.array_equal(np.asarray(js.position), records["pos"][k])  # bit for bit
        assert np.array_equal(np.asarray(js.velocity), records["vel"][k])
        assert len(js.effort) == 0  # the log has no torque: left empty, not made up
        stamp_ns = js.header.stamp.sec * 1_000_000_000 + js.header.stamp.nanosec
        assert stamp_ns == expected_ns[k] == log_time_ns
        assert abs(stamp_ns * 1e-9 - records["time_s"][k]) < 1e-9
    refs = topics["/joint_references"]
    assert np.array_equal(np.array([m[0].position for m in refs]), records["ref"])
    assert result.duration_s == pytest.approx(49 * TICK_S)


def test_imu_values_round_trip_and_missing_orientation_is_marked(exported):
    records, _, topics = exported
    assert [t for t in topics if t.startswith("/imu")] == ["/imu", "/imu/RFT_TILT",
                                                          "/imu/LFT_TILT"]
    for k, topic in enumerate(["/imu", "/imu/RFT_TILT", "/imu/LFT_TILT"]):
        imu = records["imu"][:, k]
        got = [m[0] for m in topics[topic]]
        acc = np.array([[g.linear_acceleration.x, g.linear_acceleration.y,
                         g.linear_acceleration.z] for g in got])
        rate = np.array([[g.angular_velocity.x, g.angular_velocity.y, g.angular_velocity.z]
                         for g in got])
        assert np.array_equal(acc, np.stack([imu["ax"], imu["ay"], imu["az"]], axis=1))
        assert np.array_equal(rate, np.stack([imu["wx"], imu["wy"], imu["wz"]], axis=1))
        assert all(g.orientation_covariance[0] == -1.0 for g in got)
        assert all(g.angular_velocity_covariance[0] == 0.0 for g in got)  # sim: measured
        assert got[0].header.frame_id == IMU_NAMES[k]


def test_ft_values_round_trip_and_unmeasured_axes_are_nan(exported):
    records, _, topics = exported
    for k, name in enumerate(FT_NAMES):
        got = [m[0].wrench for m in topics[f"/ft/{name}"]]
        ft = records["ft"][:, k]
        assert np.array_equal([w.torque.x for w in got], ft["mx"])
        assert np.array_equal([w.torque.y for w in got], ft["my"])
        assert np.array_equal([w.force.z for w in got], ft["fz"])
        assert all(math.isnan(w.force.x) and math.isnan(w.force.y) and math.isnan(w.torque.z)
                   for w in got)


def test_player_flags_round_trip(exported):
    records, _, topics = exported
    statuses = [m[0].status[0] for m in topics["/player"]]
    assert [s.level for s in statuses] == [1 if w else 0 for w in records["watchdog"]]
    ages = [float(dict((v.key, v.value) for v in s.values)["ref_age_ms"]) for s in statuses]
    assert np.allclose(ages, records["ref_age_ms"], atol=5e-4)
    assert statuses[0].hardware_id == "test"


def test_schemas_are_ros2_msgdefs_that_name_every_dependency(tmp_path, exported):
    reader = make_reader(open(tmp_path / "run.mcap", "rb"))  # noqa: SIM115
    summary = reader.get_summary()
    assert reader.get_header().profile == "ros2"
    names = {s.name: s for s in summary.schemas.values()}
    assert set(names) == {"sensor_msgs/msg/JointState", "sensor_msgs/msg/Imu",
                          "geometry_msgs/msg/WrenchStamped",
                          "diagnostic_msgs/msg/DiagnosticArray"}
    assert all(s.encoding == "ros2msg" for s in names.values())
    assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
    text = names["geometry_msgs/msg/WrenchStamped"].data.decode()
    for dep in ("std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/Wrench",
                "geometry_msgs/Vector3"):
        assert f"{'=' * 80}\nMSG: {dep}\n" in text
    assert msgdef("sensor_msgs/msg/Imu").count("MSG: geometry_msgs/Vector3") == 1


def test_a_hubo_read_log_on_can_has_no_player_topic_and_no_tilt_rates(tmp_path):
    records = synthetic_records(20, STATE_DTYPE)
    log = write_log(tmp_path / "read.hlog", records, {"backend": "can"})
    topics = by_topic(export_mcap(log, tmp_path / "read.mcap").path)
    assert "/player" not in topics and "/joint_states" in topics
    tilt = [m[0] for m in topics["/imu/RFT_TILT"]]
    assert all(g.angular_velocity_covariance[0] == -1.0 for g in tilt)
    assert all(g.angular_velocity.x == 0.0 for g in tilt)
    body = [m[0] for m in topics["/imu"]]
    assert [g.angular_velocity.z for g in body] == records["imu"][:, 0]["wz"].tolist()


def test_rate_keeps_the_first_record_of_each_period(tmp_path):
    records = synthetic_records(200)  # 1 s at 200 Hz
    log = write_log(tmp_path / "run.hlog", records)
    result = export_mcap(log, tmp_path / "run.mcap", rate_hz=50.0)
    msgs = by_topic(result.path)["/joint_states"]
    assert len(msgs) == result.records == 50
    assert np.array_equal([m[0].position for m in msgs], records["pos"][::4])
    t = np.array([0.0, 0.005, 0.012, 0.021, 0.035, 0.041])  # dropped ticks shift nothing
    assert decimate(t, 50.0).tolist() == [0, 3, 5]


def test_success_prints_messages_per_topic(tmp_path, capsys):
    log = write_log(tmp_path / "run.hlog", synthetic_records(30))
    assert main([str(log), "-o", str(tmp_path / "out.mcap")]) == 0
    out = capsys.readouterr().out
    assert "30 records, 0.145 s" in out
    assert "/joint_states" in out and "sensor_msgs/msg/JointState" in out
    assert "/ft/LHFT" in out and "30 messages" in out


def _corrupt(tmp_path: Path) -> Path:
    path = tmp_path / "bad.hlog"
    path.write_bytes(b"NOTALOG!" + b"\0" * 64)
    return path


def _backwards(tmp_path: Path) -> Path:
    records = synthetic_records(10)
    records["time_s"][6] = 0.5
    return write_log(tmp_path / "back.hlog", records)


def _empty(tmp_path: Path) -> Path:
    return write_log(tmp_path / "empty.hlog", synthetic_records(0))


def _no_pos(tmp_path: Path) -> Path:
    records = np.zeros(3, dtype=[("time_s", "<f8"), ("cur", "<f8", (NUM_JOINTS,))])
    return write_log(tmp_path / "nopos.hlog", records)


@pytest.mark.parametrize("make_log, out_name, rate, needle", [
    (lambda p: p / "missing.hlog", "out.mcap", None, "missing.hlog: cannot read"),
    (_corrupt, "out.mcap", None, "bad.hlog: not a hubo-ladder state log"),
    (_backwards, "out.mcap", None, "back.hlog: record 6 goes back in time"),
    (_empty, "out.mcap", None, "empty.hlog: has no complete record"),
    (_no_pos, "out.mcap", None, "nopos.hlog: no 'pos' field"),
    (lambda p: write_log(p / "ok.hlog", synthetic_records(5)), "out.bag", None,
     "out.bag: the MCAP export is written as a .mcap file; name it out.mcap"),
    (lambda p: write_log(p / "ok.hlog", synthetic_records(5)), "out.mcap", 500.0,
     "--rate 500: must be in (0, 200] Hz"),
    (lambda p: write_log(p / "ok.hlog", synthetic_records(5)), "out.mcap", 0.0,
     "--rate 0: must be in (0, 200] Hz"),
])
def test_bad_input_exits_2_with_one_line_and_writes_nothing(tmp_path, capsys, make_log,
                                                            out_name, rate, needle):
    log = make_log(tmp_path)
    before = set(tmp_path.iterdir())
    argv = [str(log), "-o", str(tmp_path / out_name)]
    if rate is not None:
        argv += ["--rate", str(rate)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("hubo-log-mcap: ") and needle in err and "\n" not in err
    assert set(tmp_path.iterdir()) == before


def test_a_missing_output_folder_is_refused(tmp_path, capsys):
    log = write_log(tmp_path / "ok.hlog", synthetic_records(5))
    assert main([str(log), "-o", str(tmp_path / "no" / "out.mcap")]) == 2
    assert "no folder" in capsys.readouterr().err
    assert not (tmp_path / "no").exists()


def test_a_failure_while_writing_leaves_no_file(tmp_path, monkeypatch):
    import daemon.log_export as log_export

    log = write_log(tmp_path / "ok.hlog", synthetic_records(5))
    old = tmp_path / "out.mcap"
    old.write_bytes(b"previous export")

    def broken(*args):
        raise RuntimeError("encoder bug")

    monkeypatch.setattr(log_export, "_write_all", broken)
    with pytest.raises(RuntimeError, match="encoder bug"):
        export_mcap(log, old)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ok.hlog", "out.mcap"]
    assert old.read_bytes() == b"previous export"  # the previous file is not clobbered


def test_the_exporter_pulls_in_no_planning_library():
    import subprocess
    import sys

    code = ("import sys\nimport daemon.log_export as m\nm.require_mcap()\n"
            "import mcap_ros2.writer\n"
            "print(','.join(n for n in ('placo', 'pinocchio', 'ompl', 'toppra', 'mujoco') "
            "if n in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == ""
