"""Shared by the command-line tests: the installed ``uvms-pin``, tiny inputs, directory digests."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
from pathlib import Path

from conftest import ROOT, run_cli_in_process, uvms_pin_command

__all__ = ["ROOT", "run_cli_in_process", "uvms_pin_command"]
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


def interrupt(
    proc: subprocess.Popen, timeout_s: float = 120.0, sig: int = signal.SIGINT
) -> tuple[str, str]:
    """Ctrl-C as a terminal sends it (to the whole process group; ``sig``: another signal,
    SIGTERM as a batch system sends it); the remaining output.

    A process group still running ``timeout_s`` later fails the test with the stack of
    every thread of its processes (SIGABRT: `paused_cli` starts them with faulthandler on),
    so that a hang seen once, on a slow machine, says where it was."""
    os.killpg(proc.pid, sig)
    try:
        return proc.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired as timeout:
        os.killpg(proc.pid, signal.SIGABRT)
        _, err = proc.communicate(timeout=60)
        stacks = [line for line in err.splitlines() if not line.startswith("Extension modules:")]
        raise AssertionError(
            f"still running {timeout_s} s after {signal.Signals(sig).name}; its stacks:\n"
            + "\n".join(stacks)
        ) from timeout
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def stopped_at(
    hook: list[str], cli_args: list[str], cwd: Path, sig: int = signal.SIGINT
) -> tuple[int, str, str]:
    """``uvms-pin CLI_ARGS`` `paused_cli.paused` at ``hook``, then sent ``sig`` (Ctrl-C by default) as
    `interrupt` sends it: (its exit status, stdout, stderr)."""
    import paused_cli

    with paused_cli.paused(hook, cli_args, cwd) as proc:
        out, err = interrupt(proc, sig=sig)
    return proc.returncode, out, err
