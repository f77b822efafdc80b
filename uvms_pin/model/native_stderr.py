"""Capturing what C++ libraries print on file descriptor 2 (urdfdom's parser errors).

urdfdom reports a bad URDF on stderr through console_bridge before Pinocchio raises; the
user should see one message, the project's, with that text folded in.
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager

_ANSI = re.compile(r"\x1b\[[0-9;]*m")
_SOURCE_LINE = re.compile(r" at line \d+ in \S+")  # where in urdfdom's C++ sources


class Captured:
    """The text written to fd 2 inside a `captured_native_stderr` block (set at its end)."""

    text: str = ""


@contextmanager
def captured_native_stderr() -> Iterator[Captured]:
    """Redirect fd 2 to a temporary file while the block runs; its text, colours removed."""
    captured = Captured()
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield captured
        finally:
            sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            raw = sink.read().decode("utf-8", errors="replace")
            captured.text = " ".join(_SOURCE_LINE.sub("", _ANSI.sub("", raw)).split())
