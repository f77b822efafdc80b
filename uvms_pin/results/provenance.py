"""What a result depends on besides its inputs: the versions of the packages that made it."""

from __future__ import annotations

import functools
import platform
from importlib import metadata as importlib_metadata


def package_versions() -> dict[str, str]:
    """Versions of the packages a result depends on (recorded in every rollout)."""
    return dict(_package_versions())


@functools.cache
def _package_versions() -> dict[str, str]:
    # read once per process: the installed metadata does not change under a running study,
    # and parsing it costs ~10 ms, a tenth of a short study run
    out = {"python": platform.python_version()}
    for name in ("uvms-pin", "pin", "numpy", "scipy"):
        try:
            out[name] = importlib_metadata.version(name)
        except importlib_metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out
