"""The property every generated input is held to, and how many inputs each profile draws.

An entry point given any input either returns a valid object or raises a documented error
(`uvms_pin.errors.UvmsPinError`) whose message names what was wrong; never another exception
(a ``KeyError``, a ``MemoryError``, a valid object built through numpy's invalid-value warning), never more than
`SECONDS_PER_INPUT` on one input, never more than `MEMORY_BOUND_BYTES` above the process's
peak resident memory before the input.

Profiles (``HYPOTHESIS_PROFILE``): ``ci`` (default; `make test`): derandomized, the same
inputs on every run and machine; ``campaign`` (`make fuzz`): `CAMPAIGN_FACTOR` times as many,
drawn from the seed ``make fuzz`` passes (``--hypothesis-seed``, printed, so a finding
replays). Neither keeps a database of examples (``database=None``): a finding becomes an
``@example`` or a plain test.
"""

from __future__ import annotations

import functools
import os
import resource
import shutil
import signal
import tempfile
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, event, settings

from uvms_pin.errors import UvmsPinError

#: the longest one input may take [s]
SECONDS_PER_INPUT = 10.0
#: the most one input may raise the process's peak resident memory [bytes]
MEMORY_BOUND_BYTES = 2**30
#: how many more inputs the campaign draws than ``make test``
CAMPAIGN_FACTOR = 6

_COMMON = dict(
    database=None,
    deadline=None,  # the bound is SECONDS_PER_INPUT, enforced by `bounded`
    print_blob=True,
    suppress_health_check=[
        HealthCheck.too_slow,
        HealthCheck.data_too_large,
        HealthCheck.filter_too_much,
        HealthCheck.function_scoped_fixture,
    ],
)
settings.register_profile("ci", derandomize=True, **_COMMON)
settings.register_profile("campaign", **_COMMON)
PROFILE = os.environ.get("HYPOTHESIS_PROFILE", "ci")
settings.load_profile(PROFILE)


ROOT = Path(__file__).resolve().parents[2]


@functools.cache
def _tree() -> tempfile.TemporaryDirectory:
    holder = tempfile.TemporaryDirectory(prefix="uvms-pin-fuzz-")  # removed at exit
    for folder in ("scenarios", "studies", "models"):
        shutil.copytree(ROOT / folder, Path(holder.name) / folder)
    return holder


def copied_tree() -> Path:
    """A copy of scenarios/, studies/ and models/ (made once, removed at exit): a generated
    file written into it finds the files and modules the shipped one next to it names."""
    return Path(_tree().name)


def examples(in_ci: int) -> int:
    """The number of inputs of a test that draws ``in_ci`` in the ci profile."""
    return in_ci * CAMPAIGN_FACTOR if PROFILE == "campaign" else in_ci


class Hang(Exception):
    """An input took longer than `SECONDS_PER_INPUT` (not a documented error: it fails)."""


def _peak_rss_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # KiB on Linux


@contextmanager
def bounded(what: str) -> Iterator[None]:
    """Run the body in at most `SECONDS_PER_INPUT` (else `Hang`) and assert it raised the
    peak resident memory by at most `MEMORY_BOUND_BYTES`."""

    def alarm(signum, frame):
        raise Hang(f"{what}: over {SECONDS_PER_INPUT:g} s")

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, SECONDS_PER_INPUT)
    before = _peak_rss_bytes()
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    grown = _peak_rss_bytes() - before
    assert grown <= MEMORY_BOUND_BYTES, f"{what}: peak memory rose by {grown / 2**20:.0f} MiB"


def outcome(call: Callable[[], Any], what: str, *, named: tuple[str, ...] = ()) -> Any:
    """``call()``'s result, or None when it raised a documented error; the error's message
    must say something and contain every text of ``named`` (the file, the key). Anything
    else propagates and fails the test, and so does a result built through numpy's
    floating-point warnings (an overflow, an invalid value: a NaN on its way into it)."""
    with bounded(what), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuntimeWarning)
        try:
            result = call()
        except UvmsPinError as exc:
            message = str(exc)
            assert message.strip(), f"{what}: {type(exc).__name__} without a message"
            for text in named:
                assert text in message, f"{what}: {text!r} not named in: {message}"
            event(f"refused: {type(exc).__name__}")
            return None
    invalid = [
        str(w.message)
        for w in caught
        if issubclass(w.category, RuntimeWarning) and "invalid value" in str(w.message)
    ]
    assert not invalid, f"{what}: built through {invalid}"
    event("valid")
    return result
