"""``python -m ladders show|check``."""

from ladders.cli import main


def test_show_prints_parameters_and_writes_mesh_and_picture(tmp_path, capsys):
    assert main(["show", "drc", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "slope_deg" in out and "60" in out and "rail_spacing_m" in out
    assert (tmp_path / "drc.glb").stat().st_size > 1000
    assert (tmp_path / "drc.png").read_bytes()[:4] == b"\x89PNG"


def test_check_refuses_a_bad_file_with_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\ngeometry:\n  slope_deg: 120\n")
    assert main(["check", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.yaml:3:" in err and "geometry.slope_deg" in err
    assert main(["check", "drc"]) == 0
