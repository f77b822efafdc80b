"""Reading the TOML tables a user writes (scenarios, studies): typed values, checked, and every
key accounted for.

A `Table` is read key by key; each read checks the value's type and range and names the
file and the key (``scenario.toml: water.waves.period_s: must be positive, got -4``), or
the override that set the value (``override 'water.waves.period_s=-4': ...``). Keys nobody
read are reported by `Table.finish` with the closest known key.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from uvms_pin.checks import Plausible, seed_value
from uvms_pin.errors import ParameterError, PlausibilityWarning, ScenarioError, UvmsPinError
from uvms_pin.scenario.overrides import closest


class Table:
    """One TOML table, read key by key; leftovers are reported as unknown keys.

    Args:
        data: the table (a dict; anything else is an error naming ``where``).
        where: its dotted name in the file (``"water.waves"``; ``""`` for the top level).
        source: the file, as messages name it.
        overridden: each overridden dotted key (without index) -> the override's text, so
            that an error about a value an override set names the override.
        error: the exception type of the errors (`ScenarioError`; a study's `StudyError`).
        label: how messages name the table, when not by its dotted name (a study's
            ``parameter[2] 'environment.stiffness_N_m'``).
    """

    def __init__(
        self,
        data: Any,
        where: str,
        source: str,
        overridden: dict[str, str] | None = None,
        error: type[UvmsPinError] = ScenarioError,
        label: str | None = None,
    ):
        if not isinstance(data, dict):
            raise error(f"{source}: [{where}] must be a table, got {type(data).__name__}")
        self._data = dict(data)
        self.where = where
        self.source = source
        self.label = label
        self._overridden = overridden or {}
        self._error = error
        self._asked: set[str] = set()  # every key the reader knows, for suggestions

    @classmethod
    def empty(cls, where: str, source: str, error: type[UvmsPinError] = ScenarioError) -> Table:
        """A table the file does not have (every key takes its default)."""
        return cls({}, where, source, error=error)

    def full(self, key: str) -> str:
        """``key``'s dotted name in the file."""
        return f"{self.where}.{key}" if self.where else key

    @property
    def title(self) -> str:
        """The table as messages name it: its label, else ``[dotted.name]``."""
        return self.label if self.label is not None else f"[{self.where}]"

    def _override_of(self, where: str) -> str | None:
        """The override that set ``where`` (a dotted name in the file): the key itself, or
        a table (or list element) holding it that an override replaced whole."""
        if where in self._overridden:
            return self._overridden[where]
        for text in self._overridden.values():
            if where.startswith((f"{text}.", f"{text}[")):
                return text
        return None

    def error(self, key: str, msg: str) -> UvmsPinError:
        """The error about ``key``: naming the override that set it (and the key, when the
        override set a whole table holding it), else the file."""
        where = self.full(key)
        if where in self._overridden:
            return self._error(f"override '{self._overridden[where]}': {msg}")
        override = self._override_of(where)
        if override is not None:
            return self._error(f"override '{override}': {where}: {msg}")
        named = where if self.label is None else f"{self.label}: {key}"
        return self._error(f"{self.source}: {named}: {msg}")

    def plausible(self, key: str, value: float, law: Plausible) -> float:
        """``value`` of ``key`` judged by ``law``: refused (an error naming the key, or the
        override that set it) if it cannot be physical, warned if far from usual."""
        refusal = law.refusal(value)
        if refusal is not None:
            raise self.error(key, refusal)
        warning = law.warning(value)
        if warning is not None:
            where = self.full(key)
            override = self._override_of(where)
            if override is not None and where in self._overridden:
                message = f"override '{override}': {warning}"
            elif override is not None:
                message = f"override '{override}': {where} = {warning}"
            else:
                message = f"{self.source}: {where} = {warning}"
            warnings.warn(message, PlausibilityWarning, stacklevel=2)
        return value

    def fail(self, msg: str) -> UvmsPinError:
        """An error about the table as a whole (naming the override that replaced it)."""
        override = self._override_of(self.where) if self.label is None else None
        if override is not None:
            return self._error(f"override '{override}': {self.title}: {msg}")
        return self._error(f"{self.source}: {self.title}: {msg}")

    @property
    def data(self) -> dict[str, Any]:
        """The keys not read yet, as they are (a copy)."""
        return dict(self._data)

    def has(self, key: str) -> bool:
        self._asked.add(key)
        return key in self._data

    def number(
        self,
        key: str,
        default: float | None = None,
        *,
        positive: bool = False,
        nonneg: bool = False,
    ) -> float:
        self._asked.add(key)
        if key not in self._data:
            if default is None:
                raise self.error(key, "is required")
            return float(default)
        value = self._data.pop(key)
        if not is_number(value):
            raise self.error(key, f"must be a finite number, got {value!r}")
        if positive and value <= 0:
            raise self.error(key, f"must be positive, got {value}")
        if nonneg and value < 0:
            raise self.error(key, f"must be >= 0, got {value}")
        return float(value)

    def optional_number(self, key: str, **kw) -> float | None:
        return self.number(key, **kw) if key in self._data else None

    def integer(
        self,
        key: str,
        default: int | None = None,
        *,
        minimum: int | None = None,
        maximum: int | None = None,
    ) -> int:
        self._asked.add(key)
        if key not in self._data and default is None:
            raise self.error(key, "is required")
        value = self._data.pop(key, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, f"must be an integer, got {value!r}")
        if minimum is not None and value < minimum:
            raise self.error(key, f"must be >= {minimum}, got {value}")
        if maximum is not None and value > maximum:
            raise self.error(key, f"must be <= {maximum}, got {value}")
        return value

    def seed(self, key: str, default: int) -> int:
        """A seed: an integer in [0, 2^63 - 1] (`uvms_pin.checks.seed_value`)."""
        value = self.integer(key, default)
        try:
            return seed_value(self.full(key), value)
        except ParameterError as exc:
            raise self.error(key, str(exc).removeprefix(f"{self.full(key)} ")) from None

    def string(
        self, key: str, default: str | None = None, choices: tuple[str, ...] | None = None
    ) -> str:
        self._asked.add(key)
        if key not in self._data:
            if default is None:
                raise self.error(key, "is required")
            return default
        value = self._data.pop(key)
        if not isinstance(value, str):
            raise self.error(key, f"must be a string, got {value!r}")
        if choices is not None and value not in choices:
            raise self.error(key, f"must be one of {', '.join(choices)}, got '{value}'")
        return value

    def boolean(self, key: str, default: bool) -> bool:
        self._asked.add(key)
        value = self._data.pop(key, default)
        if not isinstance(value, bool):
            raise self.error(key, f"must be true or false, got {value!r}")
        return value

    def vector(
        self, key: str, size: int | None, default=None, *, nonneg: bool = False
    ) -> np.ndarray:
        self._asked.add(key)
        if key not in self._data:
            if default is None:
                raise self.error(key, "is required")
            return np.array(default, dtype=float)
        value = self._data.pop(key)
        if is_number(value, finite=False) and size is not None:
            value = [value] * size
        if not isinstance(value, list) or not all(is_number(x, finite=False) for x in value):
            raise self.error(key, f"must be a list of numbers, got {value!r}")
        arr = np.array(value, dtype=float)
        if size is not None and arr.size != size:
            raise self.error(key, f"needs {size} numbers, got {arr.size}")
        if not np.all(np.isfinite(arr)):
            raise self.error(key, "has a non-finite value")
        if nonneg and np.any(arr < 0):
            raise self.error(key, f"must be >= 0, got {arr.tolist()}")
        return arr

    def table(self, key: str) -> Table | None:
        """The sub-table ``key`` (None if absent)."""
        self._asked.add(key)
        if key not in self._data:
            return None
        return Table(
            self._data.pop(key), self.full(key), self.source, self._overridden, self._error
        )

    def table_or_empty(self, key: str) -> Table:
        """The sub-table ``key``, or an empty one (every key takes its default)."""
        found = self.table(key)
        return (
            Table({}, self.full(key), self.source, self._overridden, self._error)
            if (found is None)
            else found
        )

    def tables(self, key: str) -> list[Table]:
        """The array of tables ``[[key]]`` (an empty list if absent)."""
        self._asked.add(key)
        entries = self._data.pop(key, [])
        if not isinstance(entries, list):
            raise self.error(key, f"must be an array of tables ([[{self.full(key)}]])")
        return [
            Table(entry, f"{self.full(key)}[{k}]", self.source, self._overridden, self._error)
            for k, entry in enumerate(entries)
        ]

    def pop_raw(self, key: str, default: Any = None) -> Any:
        self._asked.add(key)
        return self._data.pop(key, default)

    def rest(self) -> dict[str, Any]:
        """Every key not read yet (and the table is then finished)."""
        out, self._data = self._data, {}
        return out

    def finish(self) -> None:
        """An error for keys nobody read, naming the override that set one if any, with the
        closest known key."""
        if not self._data:
            return
        unknown = sorted(self._data)
        known = self._asked - set(unknown)
        for key in unknown:
            full = self.full(key)
            whole = self._override_of(self.where) if self.where else None
            if whole is not None and full not in self._overridden:  # it replaced this table
                hint = closest(key, known)
                raise self._error(
                    f"override '{whole}': unknown key '{full}'"
                    + (f"; did you mean '{self.full(hint)}'?" if hint else "")
                )
            for dotted, text in self._overridden.items():
                if dotted == full or dotted.startswith(full + "."):
                    hint = closest(key, known)
                    fixed = (self.full(hint) + text[len(full) :]) if hint else None
                    raise self._error(
                        f"override '{text}': unknown key '{full}'"
                        + (f"; did you mean '{fixed}'?" if fixed else "")
                    )
        hints = [f"'{k}' -> '{closest(k, known)}'" for k in unknown if closest(k, known)]
        raise self._error(
            f"{self.source}: {self.title} has unknown key(s): {', '.join(unknown)}"
            + (f" (did you mean {', '.join(hints)}?)" if hints else "")
        )


def is_number(value: Any, *, finite: bool = True) -> bool:
    """A TOML number (not a boolean), finite unless ``finite`` is False."""
    return (
        isinstance(value, int | float)
        and not isinstance(value, bool)
        and (not finite or math.isfinite(value))
    )
