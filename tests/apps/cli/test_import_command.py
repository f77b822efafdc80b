"""``uvms-pin import``: a Gazebo vehicle in, a URDF and a thruster table out."""

from __future__ import annotations

from conftest import ROOT, run

REXROV = ROOT / "tests" / "model" / "importer" / "data" / "rexrov_expanded.urdf"


def test_import_writes_the_urdf_and_the_table_and_says_what_it_did_not_map(tmp_path):
    out = tmp_path / "rexrov.urdf"
    result = run("import", str(REXROV), "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert out.is_file() and out.with_suffix(".thrusters.toml").is_file()
    assert "8 thrusters" in result.stdout
    assert "not mapped: link 'rexrov/base_link': <box>" in result.stdout
    info = run("info", str(out), "--water-density", "1028")
    assert info.returncode == 0, info.stderr
    # the second time, the files exist: refused without --overwrite, nothing changed
    before = out.read_text()
    again = run("import", str(REXROV), "--out", str(out))
    assert again.returncode == 2 and "--overwrite" in again.stderr
    assert out.read_text() == before


def test_a_bad_file_is_exit_2_and_writes_nothing(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text(REXROV.read_text().replace("<type>fossen</type>", "<type>spheroid</type>"))
    out = tmp_path / "out.urdf"
    result = run("import", str(bad), "--out", str(out))
    assert result.returncode == 2
    assert "spheroid" in result.stderr and "Traceback" not in result.stderr
    assert not out.exists() and not out.with_suffix(".thrusters.toml").exists()


def test_a_failed_import_leaves_no_directory_of_its_own_making(tmp_path):
    """The --out file's missing directories are made for it, and removed again (when still
    empty) if the import fails; one that existed stays."""
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'/><joint/></robot>")
    result = run("import", str(bad), "--out", str(tmp_path / "new" / "deeper" / "out.urdf"))
    assert result.returncode == 2, result.stderr
    assert not (tmp_path / "new").exists()
    (tmp_path / "kept").mkdir()
    assert run("import", str(bad), "--out", str(tmp_path / "kept" / "out.urdf")).returncode == 2
    assert (tmp_path / "kept").is_dir()
