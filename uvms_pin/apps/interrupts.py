"""Ctrl-C while a command saves what it ran: the save finishes, then the command stops.

The first Ctrl-C raises `KeyboardInterrupt` where the program is, as Python does (a run
stops and keeps its rollout). From then on, and inside every `InterruptGuard.saving` block,
a further Ctrl-C is only noted: a user pressing it twice (the first seems slow to act) must
not cut the save of the partial rollout in half. Once the saving block ends, a Ctrl-C noted
during it raises (stopping what follows, the figures); the files already renamed into place
are whole (`uvms_pin.results.atomic`).

After `InterruptGuard.release` (the run saved, its figures to draw) a Ctrl-C is still only
noted, and raised at the next `InterruptGuard.checkpoint`, between two figures. Raised where
the program is, it could land inside a library's import or a class body, where Python turns
it into another exception (an exception in ``__set_name__`` becomes a RuntimeError) and the
command would end in a traceback instead of saying what it kept.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager


class InterruptGuard:
    """Installs its SIGINT handler for the ``with`` block (main thread only; elsewhere it
    does nothing and Python's default handling stays)."""

    def __init__(self) -> None:
        self.stopping = False  # a first Ctrl-C was raised
        self.pending = False  # a Ctrl-C arrived while saving
        self._saving = 0
        self._at_checkpoints = False  # released: a Ctrl-C raises at the next checkpoint
        self._previous = None
        self._installed = False

    def __enter__(self) -> InterruptGuard:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._on_sigint)
            self._installed = True
        return self

    def __exit__(self, *exc_info) -> None:
        if self._installed:
            signal.signal(signal.SIGINT, self._previous)
            self._installed = False

    def _on_sigint(self, signum, frame) -> None:
        if self.stopping or self._saving:
            if not self.pending:
                print("uvms-pin: Ctrl-C: saving first, please wait", file=sys.stderr, flush=True)
            self.pending = True
            return
        if self._at_checkpoints:
            if not self.pending:
                print("uvms-pin: Ctrl-C: stopping after this step", file=sys.stderr, flush=True)
            self.pending = True
            return
        self.stopping = True
        raise KeyboardInterrupt

    @contextmanager
    def saving(self) -> Iterator[None]:
        """A block that must not be cut by Ctrl-C; one noted during it raises at its end
        (unless the command is already stopping for a first one)."""
        self._saving += 1
        try:
            yield
        finally:
            self._saving -= 1
        if self.pending and not self._saving and not self.stopping:
            self.pending = False
            self.stopping = True
            raise KeyboardInterrupt

    def release(self) -> None:
        """The saving is done: a further Ctrl-C stops what follows at its next `checkpoint`
        (a first one was handled)."""
        self.stopping = False
        self.pending = False
        self._at_checkpoints = True

    def checkpoint(self) -> None:
        """Raise `KeyboardInterrupt` here if a Ctrl-C was noted since `release`."""
        if self.pending and self._at_checkpoints:
            self.pending = False
            self.stopping = True
            raise KeyboardInterrupt
