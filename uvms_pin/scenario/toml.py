"""Reading the TOML files a user writes (scenarios, studies) with errors that name them."""

from __future__ import annotations

import copy
import functools
import tomllib
from pathlib import Path
from typing import Any

from uvms_pin.errors import UvmsPinError


def read_toml(path: Path, error: type[UvmsPinError], source: str | None = None) -> dict[str, Any]:
    """The parsed TOML of ``path``; ``error(message)`` naming ``source`` if it cannot be.

    Covers a missing file, a directory, an unreadable file, bytes that are not UTF-8
    (TOML is UTF-8 by definition) and invalid TOML.
    """
    source = str(path) if source is None else source
    if path.is_dir():
        raise error(f"{source}: is a directory, not a TOML file")
    if not path.is_file():
        raise error(f"{source}: file not found")
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise error(f"{source}: cannot read it ({exc.strerror})") from exc
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(
            f"{source}: not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}); "
            "TOML files must be saved as UTF-8"
        ) from exc
    try:
        return copy.deepcopy(_parsed(text))  # the caller's own: it may change it
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{source}: not valid TOML ({exc})") from exc


@functools.lru_cache(maxsize=32)
def _parsed(text: str) -> dict[str, Any]:
    """``text`` parsed, once per process (a study reads its base scenario for every run)."""
    return tomllib.loads(text)
