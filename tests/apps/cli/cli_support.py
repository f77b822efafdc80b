"""Shared by the command-line tests: the installed ``uvms-pin``, tiny inputs, directory digests."""

from __future__ import annotations

import contextlib
import hashlib
import io
import os
import signal
import subprocess
import sys
import traceback
import warnings
from pathlib import Path

from conftest import ROOT, uvms_pin_command

__all__ = ["ROOT", "uvms_pin_command"]
URDF = ROOT / "models" / "uvms_lbv150.urdf"


def run_cli(args: list[str], cwd: Path, timeout_s: float = 300.0) -> subprocess.CompletedProcess:
    """``uvms-pin ARGS`` as a user types it, in ``cwd``; output captured as text."""
    return subprocess.run(
        [*uvms_pin_command(), *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout_s,
        check=False,
    )


def run_cli_in_process(args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    """``uvms-pin ARGS`` in ``cwd`` run in this process as the console script runs it:
    ``sys.exit(main(ARGS))``, an uncaught exception printed as the interpreter prints it (exit
    status 1), Python's default warning filters; stdout and stderr captured as text. The
    modules the run imported from ``cwd`` (a user's controller) are forgotten after it, as a
    new process would not have them. A second of import time spared per call; what only a
    process shows (Ctrl-C, a closed stdout, the interpreter's own exit) needs `run_cli`."""
    from uvms_pin.apps.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    modules_before = set(sys.modules)
    previous_cwd = Path.cwd()
    os.chdir(cwd)
    try:
        with (
            contextlib.redirect_stdout(out),
            contextlib.redirect_stderr(err),
            warnings.catch_warnings(),
        ):
            _python_default_warning_filters()
            try:
                status = main(list(args))
            except SystemExit as exc:  # argparse's errors, --version
                status = _exit_status(exc.code)
            except Exception:
                traceback.print_exc()
                status = 1
    finally:
        os.chdir(previous_cwd)
        _forget_modules_under(Path(cwd).resolve(), set(sys.modules) - modules_before)
    return subprocess.CompletedProcess(["uvms-pin", *args], status, out.getvalue(), err.getvalue())


def _python_default_warning_filters() -> None:
    """The filters of a fresh ``python`` (no -W, no PYTHONWARNINGS): what pytest added removed;
    changing them also voids the once-per-location records of earlier runs."""
    warnings.resetwarnings()
    for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning):
        warnings.simplefilter("ignore", category)
    warnings.filterwarnings("default", category=DeprecationWarning, module="__main__")


def _exit_status(code: object) -> int:
    """The process's exit status for ``sys.exit(code)``: None 0, an int itself, else the
    code printed on stderr and 1."""
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    print(code, file=sys.stderr)
    return 1


def _forget_modules_under(directory: Path, names: set[str]) -> None:
    for name in names:
        file = getattr(sys.modules.get(name), "__file__", None)
        if file and Path(file).resolve().is_relative_to(directory):
            del sys.modules[name]


def start_cli(args: list[str], cwd: Path) -> subprocess.Popen:
    """``uvms-pin ARGS`` in the background, in its own session (a terminal's process group),
    with the default Ctrl-C behaviour whatever the test runner passed on."""
    return subprocess.Popen(
        [*uvms_pin_command(), *args],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )


def tree_digest(path: Path) -> dict[str, str]:
    """Relative path -> SHA-256 of every file under ``path`` ({} if it does not exist)."""
    if not path.exists():
        return {}
    if path.is_file():
        return {".": hashlib.sha256(path.read_bytes()).hexdigest()}
    return {
        str(p.relative_to(path)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(path.rglob("*"))
        if p.is_file()
    }


def passive_scenario(duration_s: float = 0.1, **replace: str) -> str:
    """The passive-current scenario, ``duration_s`` long, its model by absolute path."""
    text = (
        (ROOT / "scenarios" / "passive_current.toml")
        .read_text()
        .replace('"uvms_lbv150"', f'"{URDF}"')
        .replace("duration_s = 20.0", f"duration_s = {duration_s}")
    )
    for old, new in replace.items():
        assert old in text, old
        text = text.replace(old, new)
    return text


STUDY = """
[study]
name = "tiny_passive"
base = "base.toml"
seed = 3

[[parameter]]
path = "water.current_world_m_s[0]"
values = [0.0, 0.1]
"""


def interrupt(proc: subprocess.Popen, timeout_s: float = 120.0) -> tuple[str, str]:
    """Ctrl-C as a terminal sends it (to the whole process group); the remaining output.

    A process group still running ``timeout_s`` later fails the test with the stack of
    every thread of its processes (SIGABRT: `paused_cli` starts them with faulthandler on),
    so that a hang seen once, on a slow machine, says where it was."""
    os.killpg(proc.pid, signal.SIGINT)
    try:
        return proc.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired as timeout:
        os.killpg(proc.pid, signal.SIGABRT)
        _, err = proc.communicate(timeout=60)
        stacks = [line for line in err.splitlines() if not line.startswith("Extension modules:")]
        raise AssertionError(
            f"still running {timeout_s} s after Ctrl-C; its stacks:\n" + "\n".join(stacks)
        ) from timeout
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
