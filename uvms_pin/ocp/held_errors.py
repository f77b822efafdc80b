"""What must not cross crocoddyl's C++ loops: a Python exception raised in a node.

crocoddyl's solvers and mim_solvers' CSQP call the nodes' Python ``calc`` / ``calcDiff`` (and
the state's ``diff``, ``integrate``...) from C++. An exception raised there travels as a
boost.python ``error_already_set`` through C++ frames; where one of them cannot pass it on
(CSQP's loop, ``ShootingProblem.calc``), the C++ runtime calls ``std::terminate``: the process
aborts, and a run loses its rollout. Two things keep exceptions on the Python side:

- `HeldError`: a node's ``calc`` / ``calcDiff`` catches what it raises (a user's cost term, a
  user's flow field), gives values no solver step is accepted through (a huge finite cost:
  NaN is an exception of its own in CSQP, which aborts too) and holds the first error;
  `problems.solve` re-raises it, itself, once the solver has returned. Outside a solve
  (crocoddyl's ``problem.calc`` called directly) the error cannot be raised: a
  `NodeErrorWarning` says what happened and that the node's values are not its own.
- `ctrl_c_deferred`: during a solve, a Ctrl-C (SIGINT) is noted, not raised wherever Python
  happens to be (inside a node, inside the state's ``diff``); when the solve returns, it is
  raised again through the handler that was in place (a command's own Ctrl-C handling).
"""

from __future__ import annotations

import signal
import sys
import threading
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

from uvms_pin.errors import NodeErrorWarning


class HeldError:
    """The first exception a node raised inside crocoddyl, kept until `take` (or, outside a
    solve, reported by a `NodeErrorWarning`)."""

    def __init__(self) -> None:
        self.error: BaseException | None = None
        self.in_solve = False

    def hold(self, exc: Exception, where: str) -> None:
        """Keep ``exc`` (the first one only); ``where``: the method, for the warning."""
        if self.error is None:
            self.error = exc
        if self.in_solve:
            return
        message = (
            f"an OCP node's {where} raised {type(exc).__name__}: {exc}; its outputs are "
            "placeholders (an exception cannot cross crocoddyl's C++ loop; problems.solve "
            "re-raises it)"
        )
        try:
            warnings.warn(message, NodeErrorWarning, stacklevel=3)
        except Exception:  # warnings turned into errors (-W error): not raisable here either
            print(f"uvms-pin: warning: {message}", file=sys.stderr)

    def take(self) -> BaseException | None:
        """The held exception (None: none), forgotten here."""
        error, self.error = self.error, None
        return error


@contextmanager
def ctrl_c_deferred() -> Iterator[None]:
    """Ctrl-C noted, not raised, inside the block; raised when the block ends, by the
    SIGINT handler that was in place. (Only in the main thread, where Python runs signal
    handlers; not when SIGINT is ignored or its handler is not Python's.)"""
    previous = signal.getsignal(signal.SIGINT)
    if (
        threading.current_thread() is not threading.main_thread()
        or previous is None
        or previous is signal.SIG_IGN
    ):
        yield
        return
    noted: list[int] = []
    signal.signal(signal.SIGINT, lambda signum, frame: noted.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        if noted:  # the previous handler runs now (Python's: KeyboardInterrupt from here)
            signal.raise_signal(signal.SIGINT)
