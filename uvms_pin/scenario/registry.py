"""Named readers of one kind of scenario table (`Registry`): ``[controller] type = "ppc"``
-> the function that reads a "ppc" table. Each reader registers itself in its own module
(``@CONTROLLERS.register("ppc")``); the table's reader looks the name up, and an unknown
name is refused with the known ones (and the closest) listed."""

from __future__ import annotations

import difflib
from collections.abc import Callable, Iterator
from typing import Generic, TypeVar

from uvms_pin.errors import ParameterError

T = TypeVar("T")


class Registry(Generic[T]):
    """Names -> entries (readers of a table), filled by `register`.

    Args:
        what: what a name names, as messages say it (``"controller type"``).
        besides: what the table accepts besides the names, as messages list it
            (``"'package.module:ClassName'"``), or "".
    """

    def __init__(self, what: str, besides: str = ""):
        self.what = what
        self.besides = besides
        self._entries: dict[str, T] = {}

    def register(self, name: str) -> Callable[[T], T]:
        """A decorator adding its function (or any entry) under ``name``.

        Raises:
            ParameterError: ``name`` is already registered (two readers for one name).
        """

        def add(entry: T) -> T:
            if name in self._entries:
                raise ParameterError(f"{self.what} '{name}' is registered twice")
            self._entries[name] = entry
            return entry

        return add

    def __getitem__(self, name: str) -> T:
        """The entry of ``name``.

        Raises:
            ParameterError: an unknown name; the message lists the known ones (and what is
                accepted besides) and the closest.
        """
        entry = self._entries.get(name)
        if entry is None:
            raise ParameterError(self.unknown(name))
        return entry

    def unknown(self, name: str) -> str:
        """The message for an unknown ``name``: ``must be one of a, b or c, got 'x'`` (the
        names in alphabetical order, whatever order their modules registered them in)."""
        choices = ", ".join(self)
        if self.besides:
            choices = f"{choices} or {self.besides}"
        close = difflib.get_close_matches(name, list(self._entries), n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        return f"must be one of {choices}, got '{name}'{hint}"

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def __iter__(self) -> Iterator[str]:
        """The names, in alphabetical order."""
        return iter(sorted(self._entries))

    def __len__(self) -> int:
        return len(self._entries)
