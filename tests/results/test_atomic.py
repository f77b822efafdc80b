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
