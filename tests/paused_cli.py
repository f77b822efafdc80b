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

A test starts it with `start` and waits with `wait_until_paused`: the process is then
exactly at that point, however fast or slow the machine.
"""

from __future__ import annotations

import argparse
import signal
import subprocess
import sys
from pathlib import Path

PAUSED = "uvms-pin test hook: paused"


def start(hook: list[str], cli_args: list[str], cwd: Path, **popen) -> subprocess.Popen:
    """The command in the background (text pipes; its own session, default Ctrl-C)."""
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
    print(f"{PAUSED} {where}", flush=True)
    while True:
        signal.pause()  # a SIGINT handler's KeyboardInterrupt propagates from here


def _pause_at_sample(n: int) -> None:
    from uvms_pin.sim.log import RolloutLog

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


def main(argv: list[str]) -> int:
    split = argv.index("--")
    parser = argparse.ArgumentParser()
    parser.add_argument("--pause-at-sample", type=int)
    parser.add_argument("--pause-after-rows", type=int)
    hooks = parser.parse_args(argv[:split])
    if hooks.pause_at_sample is not None:
        _pause_at_sample(hooks.pause_at_sample)
    if hooks.pause_after_rows is not None:
        _pause_after_rows(hooks.pause_after_rows)
    from uvms_pin.apps.cli.main import main as cli

    return cli(argv[split + 1 :])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
