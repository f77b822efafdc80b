"""The uvms-pin command line with a pause a test can wait for: no sleeping, no polling.

    python tests/paused_cli.py --pause-at-sample N -- run scenario.toml --out o
    python tests/paused_cli.py --pause-after-rows K -- sweep study.toml --out o

runs ``uvms-pin ARGS`` (`uvms_pin.apps.cli.main.main`, what the console script calls) and,
at the chosen point, prints `PAUSED` on stdout and waits there for a signal: SIGINT raises
KeyboardInterrupt at that point, as a Ctrl-C would; SIGKILL ends the process. The points:

- ``--pause-at-sample N``: once the N-th sample of the process's runs is logged (the
  observer every run has, `uvms_pin.sim.log.RolloutLog`): the run is in the middle of its
  simulation, with N samples in its log.
- ``--pause-after-rows K``: once a sweep has durably recorded its K-th row
  (`uvms_pin.apps.study.runner.ResultStore.record`), before it goes on.
- ``--pause-at-call MODULE:NAME``: when the function ``NAME`` of ``MODULE`` is first
  called, before it runs (a command's step that is no run's sample: an identification's fit).

A test starts it with `start` and waits with `wait_until_paused`: the process is then
exactly at that point, however fast or slow the machine.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import select
import signal
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

PAUSED = "uvms-pin test hook: paused"


def start(hook: list[str], cli_args: list[str], cwd: Path, **popen) -> subprocess.Popen:
    """The command in the background (text pipes; its own session, default Ctrl-C;
    faulthandler on: a SIGABRT prints every thread's stack, which a test stuck waiting
    for it can show)."""
    popen["env"] = {**popen.get("env", os.environ), "PYTHONFAULTHANDLER": "1"}
    return subprocess.Popen(
        [sys.executable, __file__, *hook, "--", *cli_args],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        # a runner started in the background passes SIGINT on as ignored (and Python keeps
        # an inherited SIG_IGN): give the child the default Ctrl-C behaviour
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        **popen,
    )


class _CtrlCOnSetName:
    """A descriptor whose ``__set_name__`` sends this process SIGINT (a Ctrl-C)."""

    def __set_name__(self, owner: type, name: str) -> None:
        os.kill(os.getpid(), signal.SIGINT)


def ctrl_c_in_a_class_body() -> type:
    """Press Ctrl-C (SIGINT to this process) while a class body is being defined, as when it
    lands in a library's import: Python turns an exception raised in ``__set_name__`` into
    a RuntimeError (3.11), so a handler raising KeyboardInterrupt there is not seen as one."""

    class Defined:
        attribute = _CtrlCOnSetName()

    return Defined


@contextlib.contextmanager
def paused(hook: list[str], cli_args: list[str], cwd: Path) -> Iterator[subprocess.Popen]:
    """The command started (`start`) and waited for until paused at ``hook``; killed on
    leaving the block if still running."""
    proc = start(hook, cli_args, cwd)
    try:
        wait_until_paused(proc)
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def wait_until_paused(proc: subprocess.Popen) -> list[str]:
    """Block until the process reports its pause; the stdout lines printed before it.

    Raises AssertionError (with its stderr) if it ends without pausing."""
    lines = []
    for line in proc.stdout:
        if line.startswith(PAUSED):
            return lines
        lines.append(line)
    proc.wait()
    raise AssertionError(f"exited with {proc.returncode} before the pause:\n{proc.stderr.read()}")


def _pause(where: str) -> None:
    """Report the pause, then wait for a signal; its handler's exception (SIGINT:
    KeyboardInterrupt) propagates from here.

    Not `signal.pause()`: a test sends its signal as soon as it reads the line, which can be
    before this thread reaches pause(); Python's C handler notes the signal, and pause()
    then waits for another that never comes. The wake-up file descriptor is written by that
    handler whenever the signal arrives, so the select below returns in every order."""
    assert threading.current_thread() is threading.main_thread(), "signals reach the main thread"
    read_end, write_end = os.pipe()
    os.set_blocking(write_end, False)
    signal.set_wakeup_fd(write_end)  # before the line: no signal can be missed
    print(f"{PAUSED} {where}", flush=True)
    while True:  # the pending handler runs (and raises) between two of these calls
        select.select([read_end], [], [])
        os.read(read_end, 64)


def _pause_at_sample(n: int) -> None:
    from uvms_pin.sim.compiled_loop import CompiledLoop
    from uvms_pin.sim.log import RolloutLog

    # the compiled loop logs its samples a chunk at a time, past any one of them: the runs
    # this hook pauses take the Python loop, sample by sample
    CompiledLoop.build = classmethod(lambda cls, *args: (None, "the test hook pauses at a sample"))
    original = RolloutLog.on_sample
    logged = 0

    def on_sample(self, sample) -> None:
        nonlocal logged
        original(self, sample)
        logged += 1
        if logged == n:
            _pause(f"at sample {n}")

    RolloutLog.on_sample = on_sample


def _pause_after_rows(k: int) -> None:
    from uvms_pin.apps.study.runner import ResultStore

    original = ResultStore.record
    recorded = 0

    def record(self, row) -> None:
        nonlocal recorded
        original(self, row)
        recorded += 1
        if recorded == k:
            _pause(f"after row {k}")

    ResultStore.record = record


def _pause_at_call(target: str) -> None:
    """Pause when the function ``module:name`` is first called (the name as that module
    holds it: a function it imported is patched there)."""
    import importlib

    module_name, _, name = target.partition(":")
    module = importlib.import_module(module_name)
    original = getattr(module, name)

    def called(*args, **kwargs):
        _pause(f"at {target}")
        return original(*args, **kwargs)

    setattr(module, name, called)


def main(argv: list[str]) -> int:
    split = argv.index("--")
    parser = argparse.ArgumentParser()
    parser.add_argument("--pause-at-sample", type=int)
    parser.add_argument("--pause-after-rows", type=int)
    parser.add_argument("--pause-at-call", metavar="MODULE:NAME")
    hooks = parser.parse_args(argv[:split])
    if hooks.pause_at_sample is not None:
        _pause_at_sample(hooks.pause_at_sample)
    if hooks.pause_after_rows is not None:
        _pause_after_rows(hooks.pause_after_rows)
    if hooks.pause_at_call is not None:
        _pause_at_call(hooks.pause_at_call)
    from uvms_pin.apps.cli.main import main as cli

    return cli(argv[split + 1 :])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
