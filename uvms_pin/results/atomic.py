"""Result files written whole or not at all, with the permissions the user's umask gives.

A file is written under a temporary name in its own directory and renamed over its target
(atomic on POSIX): a crash or Ctrl-C leaves the previous file or none, never half of one.
The temporary file is created with mode 0666 filtered by the umask, as ``open()`` does
(``tempfile.mkstemp`` would make every result 0600, unlike the figures beside it).
"""

from __future__ import annotations

import json
import os
import secrets
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

import numpy as np

TEMP_SUFFIX = ".tmp"


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path to write; renamed to ``path`` when the block ends without error.

    The temporary name keeps ``path``'s suffix before ``.tmp`` is appended
    (``.fig.png.1a2b3c4d.png.tmp``) so that writers choosing a format by suffix still
    can be told it explicitly; it starts with a dot so that listings skip it.
    """
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(4)}{TEMP_SUFFIX}")
    os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def atomic_write(path: str | Path, writer: Callable[[IO], object], *, binary: bool) -> Path:
    """Call ``writer(file)`` on a temporary file, then rename it to ``path``."""
    with (
        atomic_path(path) as tmp,
        open(tmp, "wb" if binary else "w", encoding=None if binary else "utf-8") as f,
    ):
        writer(f)
    return Path(path)


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return atomic_write(path, lambda f: f.write(text), binary=False)


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def json_text(payload: dict[str, Any]) -> str:
    """``payload`` as indented JSON with sorted keys (numpy arrays and scalars, paths: as
    lists, numbers, text); TypeError for anything else, before any file is touched."""
    return json.dumps(payload, indent=2, sort_keys=True, default=_json_default)


def write_json_atomic(path: str | Path, payload: dict[str, Any]) -> Path:
    """Write ``payload`` as JSON (`json_text`) to ``path`` atomically."""
    return write_text_atomic(path, json_text(payload))
