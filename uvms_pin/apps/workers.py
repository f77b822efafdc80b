"""Local worker processes of a command (a sweep's, `compare-arms --jobs`'s): started with
Ctrl-C ignored, stopped at once when the command stops.

A terminal's Ctrl-C reaches the whole process group: each worker would print its own
KeyboardInterrupt traceback, so the workers ignore it and the command alone handles it, then
stops them (`stop_pool`). SIGTERM keeps its default in them: it is how they are stopped,
and a SIGTERM sent to the command alone (`kill PID`, a supervisor) must not leave them
running on their own once the command, which handles it (`uvms_pin.apps.interrupts`), is
gone.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from concurrent.futures import Executor

__all__ = ["stop_pool", "workers_signals"]


@contextlib.contextmanager
def workers_signals() -> Iterator[None]:
    """A block in which worker processes are started (forked, or a Dask cluster's): they
    inherit SIGINT ignored (Python keeps an ignored SIGINT) and SIGTERM at its default."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    previous_term = signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        signal.signal(signal.SIGTERM, previous_term)


def stop_pool(pool: Executor) -> None:
    """Stop a process pool's workers now: their running and queued tasks are dropped (a
    rerun runs them). ``shutdown(wait=False)`` alone returns at once but forgets its
    processes, and the interpreter's exit then waits for every task already handed to a
    worker: a Ctrl-C that printed its message would hang for as long as those tasks take."""
    processes = list((getattr(pool, "_processes", None) or {}).values())  # before shutdown
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.terminate()
    for process in processes:
        process.join()
