"""Progress of a simulation: a tqdm bar (terminal or notebook) fed with simulated time.

`simulate_closed_loop` reports progress through a plain callable ``progress(t_s, duration_s)``
after each logged sample; this module turns ``progress=True`` into such a callable.
"""

from __future__ import annotations

from collections.abc import Callable

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
