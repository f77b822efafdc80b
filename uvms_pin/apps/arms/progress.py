"""Progress lines of an arm comparison: while an arm runs, and when it is done."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable


class ArmProgress:
    """Progress of one arm's run as text lines, one per tenth of the simulated duration.

    Picklable (worker processes get one); ``emit`` receives each line.
    """

    def __init__(self, arm: str, emit: Callable[[str], None]):
        self.arm = arm
        self.emit = emit
        self.start = time.perf_counter()
        self.next_fraction = 0.1

    def __call__(self, t_s: float, duration_s: float) -> None:
        fraction = t_s / duration_s if duration_s > 0 else 1.0
        if fraction + 1e-9 < self.next_fraction:
            return
        while self.next_fraction <= fraction + 1e-9:
            self.next_fraction += 0.1
        elapsed = time.perf_counter() - self.start
        self.emit(f"  {self.arm}: t = {t_s:.3g}/{duration_s:g} s ({elapsed:.0f} s)")


def print_to_stderr(line: str) -> None:
    """Default line sink of worker processes (a module function: picklable)."""
    print(line, file=sys.stderr, flush=True)


def done_line(row: dict, start: float) -> str:
    """The line of an arm that is done: its status and the time since ``start``
    (a `time.perf_counter` value)."""
    return f"{row['arm']}: {row['status']} ({time.perf_counter() - start:.0f} s elapsed)"
