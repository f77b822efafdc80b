"""Output directories: checked before any work, owned by one run at a time, never mixed.

A command that writes results into a directory first checks that it can (`check_writable`,
before simulating), then `claim`s it: the directory is created, locked against a second
uvms-pin process writing into it (``flock`` on the directory, released when the process
ends however it ends, so no stale lock survives a crash), and refused if it already holds
results another run wrote, unless ``overwrite`` is given; then only the files uvms-pin
writes are removed, the user's own files are left alone. A directory holding another
*kind* of result (a study, an arm comparison) is refused even with ``overwrite``: one
mistyped ``--out`` must not delete a study.
"""

from __future__ import annotations

import errno
import json
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from uvms_pin.errors import OutputError, ParameterError
from uvms_pin.results.atomic import TEMP_SUFFIX

try:  # POSIX; elsewhere directories are not locked
    import fcntl
except ImportError:  # pragma: no cover
    fcntl = None


@dataclass(frozen=True)
class OutputKind:
    """The files one command writes into its directory (glob patterns, relative).

    Attributes:
        name: what the directory then holds ("a run's outputs", ...), for messages.
        patterns: every file the command may write; ``overwrite`` removes these only.
        markers: the files whose presence means the directory holds this kind's results.
        listed: the files (names relative to the directory) the kind's own record there
            says it wrote, where no pattern can name them (a pool validation's figure per
            trial, named after the trial); None: the patterns say all.
    """

    name: str
    patterns: tuple[str, ...]
    markers: tuple[str, ...]
    listed: Callable[[Path], list[str]] | None = None

    def present(self, directory: Path) -> list[Path]:
        """This kind's files in ``directory`` (sorted)."""
        found = {p for pattern in self.patterns for p in directory.glob(pattern) if p.is_file()}
        if self.listed is not None:
            found |= {p for p in map(directory.joinpath, self.listed(directory)) if p.is_file()}
        return sorted(found)

    def holds(self, directory: Path) -> bool:
        return any(any(directory.glob(m)) for m in self.markers)


RUN = OutputKind(
    "a run's outputs",
    (
        "rollout.npz",
        "rollout.json",
        "metrics.json",
        "replay.html",
        "pose.png",
        "velocities.png",
        "energy.png",
        "force.png",
        "first_level_errors.png",
        "second_level_errors.png",
        "flow.png",  # runs with waves or a varying current
        "surface.png",  # runs in which a body left the water in part
        "tracking.png",  # runs with a tracking task ([task])
        "estimate.png",  # runs with a navigation estimator ([estimator])
        "objects.png",  # runs with free objects ([world.objects] with a mass or density)
        "contacts.png",  # runs with a world ([world.objects], a seabed)
        "perception.npz",  # runs with cameras or sonars ([[sensors.camera]], [[sensors.sonar]])
        "perception.png",  # the same
    ),
    ("rollout.npz", "rollout.json", "metrics.json", "replay.html"),
)
STUDY = OutputKind(
    "a study's results",
    (
        "study.toml",
        "study_inputs.json",
        "results.parquet",
        "parts/*.parquet",
        "rollouts/*/rollout.npz",
        "rollouts/*/rollout.json",
        "report.md",
        "figures/*.png",
    ),
    ("results.parquet", "parts", "study.toml"),
)
COMPARISON = OutputKind(
    "an arm comparison",
    ("comparison.csv", "comparison.md", "comparison.png", "models/*.urdf"),
    ("comparison.csv", "comparison.md", "comparison.png", "models/*.urdf"),
)
CONTROLLER_COMPARISON = OutputKind(
    "a controller comparison",
    (
        "controllers.csv",
        "controllers.md",
        "controllers_force.png",
        "controllers_metrics.png",
        "robustness.csv",
        "robustness.md",
        "robustness/robustness.toml",
        "robustness/study.toml",
        "robustness/study_inputs.json",
        "robustness/results.parquet",
        "robustness/parts/*.parquet",
    ),
    ("controllers.csv", "controllers.md"),
)


def _pool_figures(directory: Path) -> list[str]:
    """The figure per trial (``<trial>.png``) of the trials the directory's
    ``pool_validation.json`` lists (none when it is missing or unreadable)."""
    try:
        trials = json.loads((directory / "pool_validation.json").read_text())["trials"]
    except (OSError, ValueError, KeyError, TypeError):
        return []
    return [f"{name}.png" for name in trials if isinstance(name, str) and "/" not in name]


#: `uvms-pin identify --fit --out` (uvms_pin.apps.validation.identification)
IDENTIFICATION = OutputKind(
    "an identification",
    ("identification.json", "bluerov2_heavy_identified.urdf", "identified*.png"),
    ("identification.json", "bluerov2_heavy_identified.urdf"),
)
#: `uvms-pin validate pool --out` (uvms_pin.apps.validation.run)
POOL_VALIDATION = OutputKind(
    "a pool validation",
    ("pool_validation.json", "pool_validation.csv"),
    ("pool_validation.json", "pool_validation.csv"),
    listed=_pool_figures,
)
KINDS = (RUN, STUDY, COMPARISON, CONTROLLER_COMPARISON, IDENTIFICATION, POOL_VALIDATION)
OVERWRITE_HELP = (
    "replace the results an earlier run left in --out (only files uvms-pin writes are removed)"
)


def given_path(name: str, value: str | Path) -> Path:
    """``value`` as a Path, or ParameterError naming ``name`` (None, a number, an empty
    string: Path("") would be the current directory)."""
    if not isinstance(value, str | Path) or not str(value).strip():
        raise ParameterError(f"{name} must be a path, got {value!r}")
    return Path(value)


def check_writable(path: str | Path, option: str = "--out", shown: str | None = None) -> Path:
    """``path`` as a directory uvms-pin can create or write into; OutputError otherwise.

    Nothing is created: the first existing ancestor must be a directory we may write in.
    ``shown``: the file the user named, when ``path`` is its directory (messages name it).
    """
    if not str(path).strip():  # Path("") is ".": an empty --out is a missing value
        raise OutputError(f"{option} {str(path)!r}: an empty path; give a directory")
    path = Path(path)
    option = f"{option} {path if shown is None else shown}"
    target = path.absolute()
    existing = target
    while not existing.exists():
        if existing.is_symlink():  # a dangling link: mkdir would fail on it
            raise OutputError(f"{option}: {existing} is a broken symbolic link")
        existing = existing.parent
    if not existing.is_dir():
        # with ``shown``, ``path`` is the directory of the file the user named
        itself = existing == target and shown is None
        where = "is a file" if itself else f"is under a file ({existing})"
        raise OutputError(f"{option}: {where}; give a directory")
    if not _may_write(existing):
        raise OutputError(f"{option}: cannot write in {existing} (permission denied or read-only)")
    return path


def _may_write(directory: Path) -> bool:
    """Whether a file can be created in ``directory`` (tried: access() lies to root)."""
    probe = directory / f".uvms-pin-probe.{os.getpid()}{TEMP_SUFFIX}"
    try:
        os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
    except OSError:
        return False
    probe.unlink()
    return True


@contextmanager
def claim(
    directory: str | Path, kind: OutputKind, *, overwrite: bool = False, option: str = "--out"
) -> Iterator[Path]:
    """Create and lock ``directory`` for ``kind``'s outputs while the block runs.

    Raises OutputError if another uvms-pin process writes into it, if it holds another
    kind's results, or this kind's and ``overwrite`` is false (with ``overwrite`` they
    are removed first). ``kind = STUDY`` accepts its own results (a sweep resumes).
    """
    directory = check_writable(directory, option)
    created = not directory.exists()
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{option} {directory}: cannot create it ({exc.strerror})") from exc
    try:
        with _locked(directory, option):
            _refuse_other_kinds(directory, kind, option)
            if kind is not STUDY and kind.holds(directory) and not overwrite:
                raise OutputError(
                    f"{option} {directory} already holds {kind.name} "
                    f"({', '.join(p.name for p in kind.present(directory)[:4])}...); "
                    "pass --overwrite to replace them, or choose another directory"
                )
            if overwrite:
                remove_outputs(directory, kind)
            yield directory
    finally:  # a run that wrote nothing leaves no directory behind
        if created and directory.is_dir() and not any(directory.iterdir()):
            directory.rmdir()


def _refuse_other_kinds(directory: Path, kind: OutputKind, option: str) -> None:
    for other in KINDS:
        if other is not kind and other.holds(directory):
            raise OutputError(
                f"{option} {directory} holds {other.name}, not {kind.name}; choose another "
                "directory (--overwrite does not delete another command's results)"
            )


def remove_outputs(directory: Path, kind: OutputKind) -> list[Path]:
    """Delete ``kind``'s files (and left-over temporary files) from ``directory``.

    Sub-directories the kind created are removed only once empty.
    """
    removed = kind.present(directory)
    for pattern in kind.patterns:  # temporary files of an interrupted write (atomic.py)
        head, _, name = pattern.rpartition("/")
        temporary = f".{name}.*{TEMP_SUFFIX}"
        removed += sorted(directory.glob(f"{head}/{temporary}" if head else temporary))
    for path in removed:
        path.unlink(missing_ok=True)
    subdirs = {p.parent for pattern in kind.patterns for p in directory.glob(pattern)}
    subdirs |= {directory / pattern.split("/")[0] for pattern in kind.patterns if "/" in pattern}
    for sub in sorted(subdirs, key=lambda p: len(p.parts), reverse=True):
        if sub != directory and sub.is_dir() and not any(sub.iterdir()):
            sub.rmdir()
    return removed


@contextmanager
def claim_file(
    path: str | Path, *, overwrite: bool = False, option: str = "--out"
) -> Iterator[Path]:
    """Lock the directory of a single output file (a replay page) while the block runs.

    Raises OutputError if the file exists and ``overwrite`` is false, if it is a
    directory, or if its directory cannot be written or is locked by another process.
    """
    path = Path(path)
    if path.is_dir():
        raise OutputError(f"{option} {path}: is a directory; give a file name (replay.html)")
    directory = check_writable(path.parent, option, shown=str(path))
    made = [d for d in (directory.absolute(), *directory.absolute().parents) if not d.exists()]
    directory.mkdir(parents=True, exist_ok=True)
    try:
        with _locked(directory, option):
            if path.exists() and not overwrite:
                raise OutputError(
                    f"{option} {path} already exists; pass --overwrite to replace it, "
                    "or --out to write elsewhere"
                )
            yield path
    except BaseException:
        # a failed command leaves no empty directory of its own making behind
        for created in made:  # (the deepest first)
            try:
                created.rmdir()
            except OSError:  # not empty: something was written there
                break
        raise


@contextmanager
def _locked(directory: Path, option: str) -> Iterator[None]:
    if fcntl is None:  # pragma: no cover
        yield
        return
    fd = os.open(directory, os.O_RDONLY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                yield  # a file system without flock (some network mounts): unlocked
                return
            raise OutputError(
                f"{option} {directory} is being written by another uvms-pin process; "
                "wait for it to finish, or choose another directory"
            ) from exc
        yield
    finally:
        os.close(fd)
