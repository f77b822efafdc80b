"""Result files written whole or not at all, with the permissions the user's umask gives.

A file is written under a temporary name in its own directory and renamed over its target
(atomic on POSIX): a crash or Ctrl-C leaves the previous file or none, never half of one.
When the system refuses the write (a full disk), the error is a `ResourceError` naming the
file that was being written, not its temporary name.
The temporary file is created with mode 0666 filtered by the umask, as ``open()`` does
(``tempfile.mkstemp`` would make every result 0600, unlike the figures beside it).
"""

from __future__ import annotations

import json
import math
import os
import secrets
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

import numpy as np

from uvms_pin.errors import ResourceError

TEMP_SUFFIX = ".tmp"


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path to write; renamed to ``path`` when the block ends without error.

    The temporary name keeps ``path``'s suffix before ``.tmp`` is appended
    (``.fig.png.1a2b3c4d.png.tmp``) so that writers choosing a format by suffix still
    can be told it explicitly; it starts with a dot so that listings skip it.
    """
    with atomic_paths(path) as (tmp,):
        yield tmp


@contextmanager
def atomic_paths(*paths: str | Path) -> Iterator[list[Path]]:
    """Temporary paths for files that go together (a rollout's arrays and metadata): all
    renamed into place when the block ends without error, or none of them.

    The renames come after every file is written; if one fails, the files renamed before it
    are put back as they were (their previous versions kept as hard links meanwhile).
    """
    targets = [Path(p) for p in paths]
    temps: list[Path] = []
    try:
        for path in targets:
            temps.append(_temporary(path, ""))
            os.close(os.open(temps[-1], os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
        yield temps
        _replace_together(targets, temps)
    except ResourceError:
        _remove(temps)
        raise
    except OSError as exc:
        _remove(temps)
        ours = {str(t): str(t) for t in targets} | {
            str(tmp): str(t) for tmp, t in zip(temps, targets, strict=False)
        }
        if exc.filename is not None and str(exc.filename) not in ours:
            raise  # the writer failed to read another file: its own error
        # the disk (full, the directory removed...): say which file, not its temporary
        where = (
            " and ".join(str(t) for t in targets)
            if exc.filename is None
            else ours[str(exc.filename)]
        )
        raise _not_written(where, exc) from exc
    except BaseException:
        _remove(temps)
        raise


def _temporary(path: Path, kind: str) -> Path:
    return path.with_name(f".{path.name}.{secrets.token_hex(4)}{kind}{TEMP_SUFFIX}")


def _replace_together(targets: list[Path], temps: list[Path]) -> None:
    """Rename each temporary onto its target; on a failure, undo the renames done."""
    backups: list[Path | None] = []
    for path in targets:
        backup = None
        if len(targets) > 1 and path.exists():
            backup = _temporary(path, ".old")
            try:
                os.link(path, backup)
            except OSError:  # no hard links here: this file cannot be put back
                backup = None
        backups.append(backup)
    done = 0
    try:
        for tmp, path in zip(temps, targets, strict=True):
            try:
                os.replace(tmp, path)
            except OSError as exc:
                raise ResourceError(exc.errno, exc.strerror or str(exc), str(path)) from exc
            done += 1
    except OSError:
        for path, backup in zip(targets[:done], backups[:done], strict=True):
            if backup is not None:
                os.replace(backup, path)
            else:
                path.unlink(missing_ok=True)
        raise
    finally:
        _remove([b for b in backups if b is not None])


def _remove(paths: list[Path]) -> None:
    for path in paths:
        path.unlink(missing_ok=True)


def _not_written(path: str, exc: OSError) -> ResourceError:
    """``exc`` (a full disk, a directory removed...) as the failure to write ``path``."""
    if isinstance(exc, ResourceError):
        return exc
    return ResourceError(exc.errno, exc.strerror or str(exc), path)


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


def json_text(payload: dict[str, Any], *, standard: bool = True) -> str:
    """``payload`` as indented JSON with sorted keys (numpy arrays and scalars, paths: as
    lists, numbers, text); TypeError for anything else, before any file is touched.

    ``standard``: a NaN or infinite number is written ``null`` (what every JSON reader
    accepts: jq, JavaScript...; "not defined for this run"); False: Python's ``NaN`` and
    ``Infinity`` tokens, which Python reads back exactly (rollout.json, `Rollout.load`)."""
    if standard:
        payload = _non_finite_as_null(payload)
    return json.dumps(
        payload, indent=2, sort_keys=True, default=_json_default, allow_nan=not standard
    )


def _non_finite_as_null(value: Any) -> Any:
    """``value`` with every NaN or infinite number (Python's, numpy's, in arrays) as None."""
    if isinstance(value, dict):
        return {key: _non_finite_as_null(item) for key, item in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_non_finite_as_null(item) for item in value]
    if isinstance(value, float | np.floating) and not math.isfinite(value):
        return None
    return value


def write_json_atomic(path: str | Path, payload: dict[str, Any]) -> Path:
    """Write ``payload`` as standard JSON (`json_text`: NaN as null) to ``path`` atomically."""
    return write_text_atomic(path, json_text(payload))
