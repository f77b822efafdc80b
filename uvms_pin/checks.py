"""Checks of arguments that raise `ParameterError` naming the argument and what is wrong,
of what a command is about to allocate (`check_memory`), and of what is physical
(`Plausible`)."""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from uvms_pin.errors import ParameterError, PlausibilityWarning


def finite_vector(name: str, value, size: int) -> np.ndarray:
    """``value`` as a float array of shape (size,) with finite entries, or ParameterError
    (a complex array too: casting it would drop its imaginary part)."""
    if (
        type(value) is np.ndarray
        and value.dtype == np.float64
        and value.shape == (size,)
        and math.isfinite(np.dot(value, value))  # all finite (an overflow: the full check)
    ):
        return value  # the common case without the checks' temporaries (a hot path's inputs)
    if getattr(getattr(value, "dtype", None), "kind", "") == "c":
        raise ParameterError(f"{name} must be {size} real numbers, got a complex array")
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name} must be {size} numbers, got {value!r}") from exc
    if array.shape != (size,):
        raise ParameterError(f"{name} must have shape ({size},), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ParameterError(f"{name} contains a non-finite value: {array}")
    return array


def sized_vector(name: str, value, size: int) -> np.ndarray:
    """``value`` as a read-only (size,) float array: a scalar broadcast, else exactly
    ``size`` finite entries (ParameterError naming ``name`` otherwise)."""
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):  # ragged lists
        array = np.asarray(None)
    if array.dtype.kind not in "iuf":  # no strings, booleans, objects
        raise ParameterError(f"{name} must be a number or a list of numbers, got {value!r}")
    array = array.astype(float)
    if array.ndim == 0:
        array = np.full(size, float(array))
    if array.shape != (size,):
        raise ParameterError(f"{name} must be a scalar or have {size} entries, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ParameterError(f"{name} has non-finite entries: {array}")
    array = array.copy()
    array.flags.writeable = False
    return array


def finite_parameters(
    owner: str, parameters: Mapping[str, object], never: Iterable[str] = ()
) -> None:
    """Every number among ``parameters`` finite, or ParameterError naming ``owner`` and the
    key: a controller's constructor calls it with ``locals()`` (what is not a number or
    numbers, e.g. ``self``, the model, a frame's name, None, is passed over), so that a gain
    of inf or nan in a scenario is refused before the run, not at its first tick.

    Args:
        owner: who is asking, for the message ("seabed_probe").
        parameters: name -> value: a number, or a (nested) list, tuple or array of numbers.
        never: the keys whose +inf means "never" or "none" (a time the jaw opens at):
            accepted; their nan and -inf are not.
    """
    allowed = frozenset(never)
    for key, value in parameters.items():
        array = _numbers(value)
        if array is None:
            continue
        finite = np.isfinite(array)
        if key in allowed:
            finite |= array == math.inf
        if not finite.all():
            also = " (or inf: never)" if key in allowed else ""
            raise ParameterError(f"{owner}: {key} must be finite{also}, got {value!r}")


def _numbers(value) -> np.ndarray | None:
    """``value`` as a float array if it is a number or numbers (not a bool or a string),
    else None."""
    if isinstance(value, bool | str | bytes) or value is None:
        return None
    if isinstance(value, int | float | np.number):
        return np.asarray(value, dtype=float)
    if isinstance(value, list | tuple | np.ndarray):
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            return None  # strings, ragged or mixed: not numbers
        return array if array.size else None
    return None


def number(name: str, value) -> float:
    """``value`` as a float, or ParameterError naming ``name``: a string ("0.1" too), None, a
    bool or what float() refuses is not a number (float() raised ValueError or TypeError)."""
    if isinstance(value, bool | str | bytes) or value is None:
        raise ParameterError(f"{name} must be a number, got {value!r}")
    try:
        return float(value)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name} must be a number, got {value!r}") from exc


def number_fields(record: Any, owner: str | None = None) -> None:
    """Every field of dataclass ``record`` annotated ``float`` (or ``float | None``: None
    allowed) holds a number as `number` has it; else ParameterError naming ``owner`` (the
    class's name by default) and the field: a string or None where a number belongs is
    refused by name here, not by a comparison's TypeError further on."""
    label = type(record).__name__ if owner is None else owner
    for field in fields(record):
        if field.type not in _FLOAT_TYPES:
            continue
        value = getattr(record, field.name)
        if value is None and field.type in _OPTIONAL_FLOAT_TYPES:
            continue
        number(f"{label}: {field.name}", value)


#: the annotations `number_fields` reads (as strings: the package's modules postpone them)
_OPTIONAL_FLOAT_TYPES = frozenset({"float | None", "None | float", float | None})
_FLOAT_TYPES = frozenset({"float", float}) | _OPTIONAL_FLOAT_TYPES


def positive(name: str, value: float) -> float:
    """``value`` as a float, finite and > 0, or ParameterError naming ``name``."""
    value = number(name, value)
    if not (math.isfinite(value) and value > 0.0):
        raise ParameterError(f"{name} must be finite and > 0, got {value}")
    return value


def nonnegative(name: str, value: float) -> float:
    """``value`` as a float, finite and >= 0, or ParameterError naming ``name``."""
    value = number(name, value)
    if not (math.isfinite(value) and value >= 0.0):
        raise ParameterError(f"{name} must be finite and >= 0, got {value}")
    return value


@dataclass(frozen=True)
class Plausible:
    """What a physical quantity can be (``possible``: beyond, it is refused) and what it
    usually is (``usual``: beyond, a `PlausibilityWarning`), in ``unit``.

    ``usual_text`` says what the usual range is ("fresh to sea water"); ``impossible_text``
    why the possible one ends ("no liquid is that dense"); ``hints``: the likely slip below
    the range and above it ("a <volume> in litres?", "a <mass> in grams?").
    """

    unit: str
    usual: tuple[float, float]
    possible: tuple[float, float]
    usual_text: str
    impossible_text: str
    hints: tuple[str, str] = ("", "")

    def _hint(self, value: float) -> str:
        hint = self.hints[0] if value < self.usual[0] else self.hints[1]
        return f"; {hint}" if hint else ""

    def refusal(self, value: float) -> str | None:
        """Why ``value`` cannot be (for an error naming it), or None."""
        return self._outside(
            value, self.possible, f"cannot be physical: {self.impossible_text}", "possible: "
        )

    def warning(self, value: float) -> str | None:
        """Why ``value`` is suspicious (for a warning naming it), or None."""
        return self._outside(value, self.usual, f"is far outside {self.usual_text}", "")

    def _outside(
        self, value: float, bounds: tuple[float, float], verdict: str, range_label: str
    ) -> str | None:
        """None if ``value`` is within ``bounds``, else the ``verdict`` on it with the
        range (``range_label``: what the range is) and the hint of its side."""
        low, high = bounds
        if low <= value <= high:
            return None
        return (
            f"{value:g} {self.unit} {verdict} "
            f"({range_label}{low:g} to {high:g} {self.unit}){self._hint(value)}"
        )

    def check(self, name: str, value: float) -> float:
        """``value``; ParameterError naming ``name`` if it cannot be physical, a
        `PlausibilityWarning` if it is far from usual."""
        refusal = self.refusal(value)
        if refusal is not None:
            raise ParameterError(f"{name} = {refusal}")
        warning = self.warning(value)
        if warning is not None:
            warnings.warn(f"{name} = {warning}", PlausibilityWarning, stacklevel=3)
        return value


#: seeds are recorded in rollouts, JSON and the study table's int64 column
MAX_SEED = 2**63 - 1


def flag(name: str, value) -> bool:
    """``value`` as a bool (Python's or numpy's), or ParameterError: "yes", 1 or None are
    refused rather than read by their truth (the compiled core would not take them)."""
    if value is False or value is True:  # (the common case first: this is on every call)
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    raise ParameterError(f"{name} must be True or False, got {value!r}")


def seed_value(name: str, value) -> int:
    """``value`` as a seed: an integer in [0, 2^63 - 1] (numpy's generators take no negative
    seed, and a study table stores seeds as int64); ParameterError naming ``name`` else."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise ParameterError(f"{name} must be an integer in [0, 2^63 - 1], got {value!r}")
    if not 0 <= int(value) <= MAX_SEED:
        raise ParameterError(f"{name} must be an integer in [0, 2^63 - 1], got {value}")
    return int(value)


def thread_count(num_threads: int | None) -> int:
    """``num_threads`` checked (a positive integer), or every core for None."""
    if num_threads is None:
        return os.cpu_count() or 1
    if isinstance(num_threads, bool) or not isinstance(num_threads, int) or num_threads < 1:
        raise ParameterError(f"num_threads must be a positive integer, got {num_threads!r}")
    return num_threads


def available_memory_bytes() -> int | None:
    """Memory the system can give this process now [bytes], or None if unknown."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def check_memory(
    needed_bytes: float,
    what: str,
    remedy: str,
    error: Callable[[str], Exception] = ParameterError,
) -> None:
    """Raise ``error(message)`` before anything is allocated if ``what`` would take more than
    half of the memory available (the other half: what the command allocates besides).

    Args:
        needed_bytes: the estimate [bytes]. what: the thing and its size, for the message
            ("the log of this run (500001 samples: ...)"). remedy: what to change.
        error: makes the exception from the message (an exception type, or a function
            that names the file and the entry).
    """
    available = available_memory_bytes()
    if available is not None and needed_bytes > available // 2:
        raise error(
            f"{what} would take {needed_bytes / 2**30:.3g} GiB, more than half of the "
            f"{available / 2**30:.3g} GiB available: {remedy}"
        )
