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

SIGTERM (a batch system's time limit, ``kill``) is handled as Ctrl-C is, raising
`Terminated` (a `KeyboardInterrupt`): a run it stops keeps what was simulated, and the
command exits with 143, as a shell reports a process SIGTERM ended.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from uvms_pin.apps.exit_codes import EXIT_INTERRUPTED, EXIT_TERMINATED


class Terminated(KeyboardInterrupt):
    """The stop SIGTERM asks for, raised where a first Ctrl-C would be."""


def stop_status(exc: KeyboardInterrupt) -> tuple[int, str]:
    """(exit status, what to call it) of a stop: 143 "terminated (SIGTERM)" for
    `Terminated`, else 130 "interrupted"."""
    if isinstance(exc, Terminated):
        return EXIT_TERMINATED, "terminated (SIGTERM)"
    return EXIT_INTERRUPTED, "interrupted"


@contextmanager
def sigterm_stops() -> Iterator[None]:
    """SIGTERM raises `Terminated` while the block runs (main thread only), as a first Ctrl-C
    raises `KeyboardInterrupt`: a command without an `InterruptGuard` of its own (identify,
    an import, an export) stops as on Ctrl-C, its ``finally`` blocks and its atomic writes'
    clean-ups run, and `uvms_pin.apps.cli.main` exits 143 saying so; Python's default
    would end the process on the spot, silently, leaving temporary files behind."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum, frame) -> None:
        raise Terminated("terminated by SIGTERM")

    previous = signal.signal(signal.SIGTERM, stop)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


#: the signals the guard handles, and what its messages call them
_NAMES = {signal.SIGINT: "Ctrl-C", signal.SIGTERM: "SIGTERM"}


class InterruptGuard:
    """Installs its SIGINT and SIGTERM handlers for the ``with`` block (main thread only;
    elsewhere it does nothing and Python's default handling stays)."""

    def __init__(self) -> None:
        self.stopping = False  # a first Ctrl-C (or SIGTERM) was raised
        self.pending = False  # one arrived while saving
        self.terminated = False  # SIGTERM arrived: the stop raised is `Terminated`
        self._saving = 0
        self._at_checkpoints = False  # released: a Ctrl-C raises at the next checkpoint
        self._previous: dict = {}

    def __enter__(self) -> InterruptGuard:
        if threading.current_thread() is threading.main_thread():
            self._previous = {sig: signal.signal(sig, self._on_signal) for sig in _NAMES}
        return self

    def __exit__(self, *exc_info) -> None:
        for sig, previous in self._previous.items():
            signal.signal(sig, previous)
        self._previous = {}

    def _on_signal(self, signum, frame) -> None:
        self.terminated |= signum == signal.SIGTERM
        name = _NAMES.get(signum, "a signal")
        if self.stopping or self._saving:
            if not self.pending:
                print(f"uvms-pin: {name}: saving first, please wait", file=sys.stderr, flush=True)
            self.pending = True
            return
        if self._at_checkpoints:
            if not self.pending:
                print(f"uvms-pin: {name}: stopping after this step", file=sys.stderr, flush=True)
            self.pending = True
            return
        self.stopping = True
        raise self._stop()

    def _stop(self) -> KeyboardInterrupt:
        """The exception a stop raises: `Terminated` once SIGTERM arrived."""
        return Terminated("terminated by SIGTERM") if self.terminated else KeyboardInterrupt()

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
            raise self._stop()

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
            raise self._stop()
