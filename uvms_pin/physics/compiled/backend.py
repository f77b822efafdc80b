"""Which implementation computes: the compiled core or the Python reference.

`Backend` is the one object that decides, for the dynamics, the plant and the PPC law: a
concept's compiled counterpart is built through `Backend.counterpart`, which gives either the
counterpart or a `Fallback` saying why the reference computes instead (the reference was
asked for, or the core has no counterpart of something the caller uses). A fallback the
caller did not ask for is reported once with a `CoreFallbackWarning`.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import TypeVar

from uvms_pin.errors import CoreFallbackWarning, ParameterError
from uvms_pin.physics.compiled.extension import core_module

BACKENDS = ("core", "python")
T = TypeVar("T")


@dataclass(frozen=True)
class Fallback:
    """Why the Python reference computes something instead of the compiled core."""

    reason: str
    asked: bool = False  # True: the caller chose the reference (nothing to warn about)

    def warn(self, what: str, stacklevel: int = 3) -> None:
        """A `CoreFallbackWarning` naming ``what`` runs on the reference, unless asked for."""
        if not self.asked:
            warnings.warn(
                f"the compiled core does not support {self.reason}: the Python reference "
                f"computes {what} (slower)",
                CoreFallbackWarning,
                stacklevel=stacklevel,
            )


@dataclass(frozen=True)
class Backend:
    """``"core"`` (the compiled core, the default) or ``"python"`` (the reference)."""

    name: str = "core"

    def __post_init__(self) -> None:
        if self.name not in BACKENDS:
            raise ParameterError(f"backend must be one of {BACKENDS}, got {self.name!r}")

    @property
    def compiled(self) -> bool:
        return self.name == "core"

    def counterpart(self, build: Callable[[ModuleType], T | Fallback]) -> T | Fallback:
        """``build(core)``, the compiled counterpart of a concept (or its own `Fallback`);
        the reference's `Fallback` when this backend is "python"."""
        if not self.compiled:
            return Fallback("the Python backend", asked=True)
        return build(core_module())


_NAMED = {name: Backend(name) for name in BACKENDS}


def backend_named(name: str | Backend) -> Backend:
    """The `Backend` called ``name`` (ParameterError for another name)."""
    if isinstance(name, Backend):
        return name
    backend = _NAMED.get(name) if isinstance(name, str) else None
    if backend is None:
        raise ParameterError(f"backend must be one of {BACKENDS}, got {name!r}")
    return backend
