"""Loading the compiled core (``uvms_pin._core``) and checking that it is current.

The extension is built at ``pip install`` (scikit-build-core, CMakeLists.txt). It is refused,
with the command that rebuilds it, when it is missing, was built from other sources than the
tree this package runs from (a fingerprint of ``src/uvms_core``), or against another Pinocchio.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from types import ModuleType

import pinocchio as pin  # loads libpinocchio_default before the extension needs it

from uvms_pin.errors import CoreUnavailableError

REBUILD = "rebuild it with `pip install -e .` (or `make clean test`) in the uvms-pin checkout"
SOURCE_DIR = Path(__file__).resolve().parents[3] / "src" / "uvms_core"


def source_hash(source_dir: Path = SOURCE_DIR) -> str | None:
    """The fingerprint CMakeLists.txt bakes into the extension (None without sources)."""
    files = sorted(p for p in source_dir.glob("*") if p.suffix in (".cpp", ".hpp"))
    if not files:
        return None
    lines = "".join(f"{p.name}:{hashlib.sha256(p.read_bytes()).hexdigest()}\n" for p in files)
    return hashlib.sha256(lines.encode()).hexdigest()


def _load() -> ModuleType:
    try:
        from uvms_pin import _core
    except ImportError as exc:
        raise CoreUnavailableError(f"the compiled core is not built ({exc}): {REBUILD}") from exc
    if _core.PINOCCHIO_VERSION != pin.__version__:
        raise CoreUnavailableError(
            f"the compiled core was built against Pinocchio {_core.PINOCCHIO_VERSION} but "
            f"pinocchio {pin.__version__} is installed: {REBUILD}"
        )
    expected = source_hash()
    if expected is not None and expected != _core.SOURCE_HASH:
        raise CoreUnavailableError(
            f"the compiled core is stale (built from other sources than {SOURCE_DIR}): {REBUILD}"
        )
    return _core


_MODULE: list[ModuleType] = []  # loaded once per process


def core_module() -> ModuleType:
    """The extension module, checked once per process (CoreUnavailableError otherwise)."""
    if not _MODULE:
        _MODULE.append(_load())
    return _MODULE[0]


def core_available() -> bool:
    """Whether the compiled core loads and is current."""
    try:
        core_module()
    except CoreUnavailableError:
        return False
    return True
