"""Finding files a URDF refers to: ``package://`` and relative mesh paths.

``package://NAME/rest`` resolves to ``DIR/NAME/rest`` for the first directory DIR of the
search path that has it (ROS and Pinocchio's ``package_dirs`` convention: a directory that
*contains* packages; a directory that *is* package NAME serves too). The search path is the
caller's ``package_dirs``, then the folders of ``ROS_PACKAGE_PATH`` (ROS 1) and the
``share`` folder of each prefix of ``AMENT_PREFIX_PATH`` (ROS 2), as a sourced ROS workspace
sets them, then the ``share`` directory of the installed ``example-robot-data``
distribution, so its robots load without arguments (its wheel ships URDFs and meshes under
``site-packages/cmeel.prefix/share/example-robot-data`` but no Python loader). ``file://``
URLs and absolute paths are taken as they are; other paths are relative to the URDF's
directory.
"""

from __future__ import annotations

import difflib
import functools
import os
import sys
from collections.abc import Iterable
from importlib import metadata
from pathlib import Path

from uvms_pin.errors import NotShippedError, ParameterError

__all__ = [
    "environment_folders",
    "example_robot_data_dir",
    "find_model",
    "package_folders",
    "package_search_path",
    "resolve_model",
    "resolve_resource",
    "shipped_models",
    "shipped_path",
]

_ERD_DISTRIBUTION = "example-robot-data"
_ERD_SHARE = ("cmeel.prefix", "share")


@functools.lru_cache(maxsize=1)
def _example_robot_data_share() -> Path | None:
    try:
        dist = metadata.distribution(_ERD_DISTRIBUTION)
    except metadata.PackageNotFoundError:
        return None
    share = Path(str(dist.locate_file(Path(*_ERD_SHARE))))
    return share if (share / _ERD_DISTRIBUTION).is_dir() else None


def example_robot_data_dir() -> Path | None:
    """``.../share/example-robot-data`` of the installed distribution, or None."""
    share = _example_robot_data_share()
    return None if share is None else share / _ERD_DISTRIBUTION


def environment_folders(variable: str) -> list[Path]:
    """The folders a search-path environment variable lists (``os.pathsep`` between them),
    in order; none when it is unset or empty."""
    return [Path(d) for d in os.environ.get(variable, "").split(os.pathsep) if d]


def package_folders(package_dirs: str | Path | Iterable[str | Path]) -> Iterable[str | Path]:
    """``package_dirs`` as a list of folders: one folder given alone is the list of it (a
    string is not read as its characters); a list as it is."""
    return (package_dirs,) if isinstance(package_dirs, str | Path) else package_dirs


def package_search_path(package_dirs: Iterable[str | Path] = ()) -> list[Path]:
    """The directories searched for ``package://`` names, in order (the module docstring)."""
    dirs = [Path(d) for d in package_dirs]
    dirs += environment_folders("ROS_PACKAGE_PATH")
    dirs += [prefix / "share" for prefix in environment_folders("AMENT_PREFIX_PATH")]
    share = _example_robot_data_share()
    if share is not None:
        dirs.append(share)
    return dirs


def resolve_resource(
    filename: str, base_dir: str | Path, package_dirs: Iterable[str | Path] = ()
) -> Path | None:
    """The file a URDF ``filename`` attribute points to, or None if it does not exist.

    Args:
        filename: ``package://NAME/rest``, ``file:///abs``, an absolute or a relative path.
        base_dir: the URDF's directory (for relative paths).
        package_dirs: extra directories containing packages, searched first.
    """
    if filename.startswith("package://"):
        rest = filename[len("package://") :]
        for directory in package_search_path(package_dirs):
            candidate = directory / rest
            if candidate.is_file():
                return candidate
            # a directory that IS the package: drop the package name
            _, _, inner = rest.partition("/")
            if inner and (directory / inner).is_file() and directory.name == rest.split("/")[0]:
                return directory / inner
        return None
    if filename.startswith("file://"):
        filename = filename[len("file://") :]
    path = Path(filename)
    if not path.is_absolute():
        path = Path(base_dir) / path
    return path if path.is_file() else None


def shipped_path(relative: str | Path) -> Path:
    """A file shipped with uvms-pin: ``models/uvms_lbv150.urdf``, ``scenarios/...``, ...

    From a source checkout (editable install) it is the repository's file; from a wheel it
    is the copy installed in ``<prefix>/share/uvms-pin/``.

    Raises:
        NotShippedError: neither exists (a FileNotFoundError).
    """
    relative = Path(relative)
    candidates = [
        Path(__file__).resolve().parents[2] / relative,
        Path(sys.prefix) / "share" / "uvms-pin" / relative,
    ]
    for candidate in candidates:
        if candidate.exists():
            return candidate
    raise NotShippedError(
        f"{relative} is not shipped with this install (looked in {', '.join(map(str, candidates))})"
    )


def shipped_models() -> list[str]:
    """Names of the shipped models (``models/NAME.urdf``), e.g. ``lbv150``, ``uvms_lbv150``."""
    try:
        return sorted(p.stem for p in shipped_path("models").glob("*.urdf"))
    except FileNotFoundError:
        return []


def find_model(entry: str | Path, base_dir: str | Path = ".") -> Path | None:
    """A model file: ``entry`` as a path (relative to ``base_dir``) if that file exists,
    else a shipped model name (``"uvms_lbv150"`` or ``"uvms_lbv150.urdf"``), else None."""
    path = Path(entry)
    candidate = path if path.is_absolute() else Path(base_dir) / path
    if candidate.is_file():
        return candidate.resolve()
    if len(path.parts) == 1 and path.stem in shipped_models() and path.suffix in ("", ".urdf"):
        return shipped_path(Path("models") / f"{path.stem}.urdf")
    return None


def resolve_model(entry: str | Path, base_dir: str | Path = ".") -> Path:
    """The model file ``entry`` names (`find_model`), or a ParameterError saying why there
    is none: an empty entry, a directory, or neither a file nor a shipped model (the shipped
    names listed, the closest first)."""
    text = str(entry)
    if not text.strip():
        raise ParameterError(
            f"the model is empty; give a URDF file or a shipped model ({', '.join(shipped_models())})"
        )
    found = find_model(entry, base_dir)
    if found is not None:
        return found
    path = Path(entry)
    candidate = path if path.is_absolute() else Path(base_dir) / path
    if candidate.is_dir():
        raise ParameterError(f"'{text}' is a directory ({candidate.resolve()}), not a URDF file")
    names = shipped_models()
    close = difflib.get_close_matches(path.stem, names, n=1, cutoff=0.6)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    raise ParameterError(
        f"'{text}' is neither a file ({candidate.resolve()}) nor a shipped model "
        f"({', '.join(names)}){hint}"
    )
