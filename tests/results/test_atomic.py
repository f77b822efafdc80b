"""Atomic result files: whole or absent, with the permissions the umask gives."""

from __future__ import annotations

import os
import stat

import pytest

from uvms_pin.model.native_stderr import captured_native_stderr
from uvms_pin.results.atomic import atomic_write, write_text_atomic


@pytest.mark.parametrize("umask", [0o022, 0o027, 0o002])
def test_a_result_file_follows_the_umask(tmp_path, umask):
    previous = os.umask(umask)
    try:
        path = write_text_atomic(tmp_path / "metrics.json", "{}")
    finally:
        os.umask(previous)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask


def test_a_failed_write_leaves_the_previous_file_and_no_temporary(tmp_path):
    path = tmp_path / "rollout.json"
    path.write_text("earlier")

    def fails(f):
        f.write("half")
        raise RuntimeError("disk on fire")

    with pytest.raises(RuntimeError):
        atomic_write(path, fails, binary=False)
    assert path.read_text() == "earlier"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rollout.json"]


def test_native_stderr_is_captured_and_restored(capfd):
    with captured_native_stderr() as captured:
        os.write(2, b"\x1b[31mError: joint [j] at line 12 in /src/joint.cpp\x1b[0m\n")
    os.write(2, b"after\n")
    assert captured.text == "Error: joint [j]"
    assert capfd.readouterr().err == "after\n"


def test_files_written_together_are_replaced_together_or_not_at_all(tmp_path, monkeypatch):
    import errno

    from uvms_pin.errors import ResourceError
    from uvms_pin.results.atomic import atomic_paths

    a, b = tmp_path / "a.npz", tmp_path / "a.json"
    a.write_text("old a")
    b.write_text("old b")
    real = os.replace

    def replace(src, dst, *args, **kw):  # the second rename fails as on a full disk
        if str(dst) == str(b):
            raise OSError(errno.ENOSPC, "No space left on device", str(src))
        return real(src, dst, *args, **kw)

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(ResourceError) as info, atomic_paths(a, b) as (ta, tb):
        ta.write_text("new a")
        tb.write_text("new b")
    assert info.value.filename == str(b) and info.value.errno == errno.ENOSPC
    assert (a.read_text(), b.read_text()) == ("old a", "old b")  # the first put back
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "a.npz"]  # no temporary
    monkeypatch.setattr(os, "replace", real)
    # a write failing without a file name (ENOSPC in the middle of a write) names both
    with pytest.raises(ResourceError, match=r"a.npz and .*a.json"), atomic_paths(a, b) as (ta, _):
        raise OSError(errno.ENOSPC, "No space left on device")
    assert (a.read_text(), b.read_text()) == ("old a", "old b")
    # a writer failing to read some other file keeps its own error
    with pytest.raises(FileNotFoundError), atomic_paths(a) as (ta,):
        (tmp_path / "elsewhere.txt").read_text()
    with atomic_paths(a, b) as (ta, tb):
        ta.write_text("new a")
        tb.write_text("new b")
    assert (a.read_text(), b.read_text()) == ("new a", "new b")
