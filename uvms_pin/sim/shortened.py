"""Shortened runs: the ``UVMS_PIN_MAX_DURATION_S`` environment variable caps the simulated
duration of every scenario run, loudly.

The documentation's test runs every snippet of README.md and docs/ with it set (ten-second
runs then take one); you can set it too, to try a long comparison or study quickly. A
shortened run is never mistaken for the scenario's: a `ShortenedRunWarning` names the file
and both durations when the scenario is loaded (``uvms-pin`` prints it), the rollout records
the scenario's own duration as ``metadata["shortened_from_s"]`` (and the shortened one in its
parameters), ``uvms-pin run`` repeats it on its last line, and `make results` refuses to
run while the variable is set.

The shortened duration is the largest whole number of log periods within the cap (at least
one), so that every period still divides it: nothing else about the run changes.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping

from uvms_pin.errors import ParameterError

#: the environment variable: a duration cap [s] (a positive number), unset or empty: none
MAX_DURATION_ENV = "UVMS_PIN_MAX_DURATION_S"


def max_duration_s(environ: Mapping[str, str] | None = None) -> float | None:
    """The cap [s] ``UVMS_PIN_MAX_DURATION_S`` sets in ``environ`` (default: the process's
    environment), or None when it is unset or empty.

    Raises:
        ParameterError: the value is not a positive finite number (named with the variable).
    """
    text = (os.environ if environ is None else environ).get(MAX_DURATION_ENV, "").strip()
    if not text:
        return None
    try:
        cap_s = float(text)
    except ValueError:
        cap_s = math.nan
    if not (math.isfinite(cap_s) and cap_s > 0.0):
        raise ParameterError(
            f"environment variable {MAX_DURATION_ENV}={text!r}: needs a positive number of "
            "seconds (the cap on simulated durations), or unset it"
        )
    return cap_s


def shortened_duration_s(duration_s: float, log_period_s: float, cap_s: float) -> float | None:
    """The duration [s] a run of ``duration_s`` logged every ``log_period_s`` gets under a
    cap of ``cap_s``: the largest whole number n >= 1 of log periods with n log_period_s <=
    cap_s; None when the run is not longer than that (it stays as it is)."""
    periods = max(1, math.floor(cap_s / log_period_s * (1.0 + 1e-9)))
    shortened_s = periods * log_period_s
    if shortened_s >= duration_s * (1.0 - 1e-9):
        return None
    return shortened_s


def shortened_message(source: str, duration_s: float, shortened_s: float, cap_s: float) -> str:
    """The warning a shortened run gives: the file, the variable and both durations."""
    return (
        f"{source}: {MAX_DURATION_ENV}={cap_s:g} is set: this run simulates {shortened_s:g} s "
        f"of the scenario's {duration_s:g} s (scenario.duration_s), a shortened run"
    )
