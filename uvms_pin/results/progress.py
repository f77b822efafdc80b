"""Progress of a simulation, fed with simulated time: a bar where someone watches (a
terminal, a notebook), text lines where nobody does (a log file, a pipe).

The closed loop reports progress through a plain callable ``progress(t_s, duration_s)`` after
each logged sample; `progress_printer` makes one for a run (``simulate(progress=True)``, the
``uvms-pin run`` progress) and closes it when the run ends.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TextIO

from uvms_pin.errors import ParameterError

#: ``progress(t_s, duration_s)``: called by the closed loop after every logged sample.
Progress = Callable[[float, float], None]

#: A bar appears only once a run has taken this long [s of wall time]: short runs, tests
#: and sweeps stay silent, long runs show where they are.
BAR_DELAY_S = 2.0


class ProgressBar:
    """``tqdm.auto`` bar over simulated seconds; use as ``with ProgressBar(label) as bar``.

    ``tqdm.auto`` picks the notebook widget inside Jupyter (needs ``ipywidgets``) and a text
    bar on a terminal. The bar counts simulated seconds, so its rate is the real-time factor.
    """

    def __init__(self, label: str, duration_s: float, delay_s: float = BAR_DELAY_S):
        from tqdm.auto import tqdm

        self._bar = tqdm(
            total=round(duration_s, 9),
            desc=label,
            unit="s sim",
            delay=delay_s,
            dynamic_ncols=True,
            bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]",
        )

    def __call__(self, t_s: float, duration_s: float) -> None:
        self._bar.update(round(t_s, 9) - self._bar.n)

    def __enter__(self) -> ProgressBar:
        return self

    def __exit__(self, *exc) -> None:
        self._bar.close()


@dataclass
class ProgressLines:
    """Progress as text lines on ``stream`` (a log file or a pipe: no redrawing), one when
    ``delay_s`` of wall time has passed, then one every ``interval_s``, and the last one::

        realistic_force_tracking [#########                     ] t =   3.000/10 s  elapsed    4.1 s  left ~    9.6 s
    """

    label: str
    duration_s: float
    stream: TextIO
    delay_s: float = 0.0
    interval_s: float = 10.0

    def __post_init__(self) -> None:
        self.start = time.perf_counter()
        self.next_s = self.delay_s  # wall time of the next line, from the start
        self.printed = False

    def __call__(self, t_s: float, duration_s: float) -> None:
        elapsed = time.perf_counter() - self.start
        # the last line only after a first one: a run shorter than the delay prints nothing
        if elapsed < self.next_s and not (self.printed and t_s >= duration_s):
            return
        self.next_s, self.printed = elapsed + self.interval_s, True
        fraction = t_s / duration_s if duration_s > 0 else 1.0
        # nothing simulated yet: no rate to extrapolate from
        left = f"{elapsed * (1.0 - fraction) / fraction:6.1f}" if fraction > 0 else "     ?"
        bar = "#" * int(30 * fraction)
        self.stream.write(
            f"{self.label} [{bar:<30}] t = {t_s:7.3f}/{duration_s:g} s  elapsed "
            f"{elapsed:6.1f} s  left ~{left} s\n"
        )
        self.stream.flush()


@contextmanager
def progress_printer(
    label: str, duration_s: float, *, delay_s: float = BAR_DELAY_S, stream: TextIO | None = None
) -> Iterator[Progress]:
    """The progress of one run, closed when the block ends: a `ProgressBar` in a notebook or
    on a terminal, `ProgressLines` when ``stream`` (stderr) is a file or a pipe. Nothing is
    shown before ``delay_s`` of wall time: short runs stay silent."""
    stream = sys.stderr if stream is None else stream
    if _in_notebook() or stream.isatty():
        with ProgressBar(label, duration_s, delay_s) as bar:
            yield bar
    else:
        yield ProgressLines(label, duration_s, stream, delay_s)


def _in_notebook() -> bool:
    shell = sys.modules.get("IPython")
    ipython = getattr(shell, "get_ipython", lambda: None)() if shell else None
    return type(ipython).__name__ == "ZMQInteractiveShell"


def callback_or_none(progress: bool | Progress | None) -> Progress | None:
    """``False``/``None``: no reporting; a callable ``(t_s, duration_s)``: itself.

    ``True`` is not accepted here: the caller opens a `ProgressBar` for it, because the
    bar must be closed when the run ends.
    """
    if progress is None or progress is False:
        return None
    if callable(progress):
        return progress
    raise ParameterError(
        f"progress must be True, False, None or a callable (t_s, duration_s), got {progress!r}"
    )
