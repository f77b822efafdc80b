"""A named, unit-carrying record a controller logs: ``Signal(values, components, unit)``.

A controller's ``signals()`` returns name -> 1-D array (columns ``<name>.0``, ``<name>.1``,
... without units) or name -> `Signal`, whose columns are ``<name>.<component>_<unit>``
in the rollout's table (`uvms_pin.results.table`); the rollout's metadata keeps the names
and units (``signal_units``), so a saved rollout reads back with them.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from uvms_pin.errors import ParameterError

__all__ = ["Signal", "component_label", "described", "unit_suffix"]

_COMPONENT = re.compile(r"^[A-Za-z_][\w]*$")


@dataclass(frozen=True, init=False)
class Signal:
    """One logged quantity: its values, a name per component and a unit per component.

    Args:
        values: the components' values now (a 1-D array or a number).
        components: a name per component (identifiers: ``"x"``, ``"roll"``,
            ``"joint_2"``), in the order of ``values``.
        unit: the unit as text (``"m"``, ``"m/s"``, ``"N m"``, ``"rad"``, ``""`` for none),
            one for every component or a sequence of one per component.

    Raises:
        ParameterError: a name that is not an identifier, repeated names, or as many names
            or units as there are values.
    """

    values: np.ndarray
    components: tuple[str, ...]
    units: tuple[str, ...]

    def __init__(self, values, components: Sequence[str], unit: str | Sequence[str] = ""):
        array = np.atleast_1d(np.asarray(values, dtype=float))
        names = tuple(str(c) for c in components)
        units = (unit,) * len(names) if isinstance(unit, str) else tuple(str(u) for u in unit)
        if array.ndim != 1 or array.size != len(names) or len(units) != len(names):
            raise ParameterError(
                f"Signal: {array.size} value(s), {len(names)} component name(s) and "
                f"{len(units)} unit(s) must agree (values of shape {array.shape})"
            )
        bad = [c for c in names if not _COMPONENT.match(c)]
        if bad or len(set(names)) != len(names):
            raise ParameterError(
                f"Signal: component names must be distinct identifiers, got {list(names)}"
            )
        object.__setattr__(self, "values", array)
        object.__setattr__(self, "components", names)
        object.__setattr__(self, "units", units)

    def describe(self) -> dict[str, list[str]]:
        """What the rollout's metadata keeps of it: component names and units."""
        return described(self.components, self.units)


def described(components: Sequence[str], units: Sequence[str]) -> dict[str, list[str]]:
    """A signal's entry in the rollout's ``signal_units`` metadata: its columns' component
    names and units (a `Signal`'s, or a thruster's or sensor's columns)."""
    return {"components": list(components), "units": list(units)}


def component_label(name: str) -> str:
    """A model's name (a joint's, an object's: ``oberon7/finger_left_joint``) as a component
    name: each character that is not an ASCII letter, digit or underscore an underscore, and
    an underscore before a leading digit."""
    label = re.sub(r"\W", "_", name, flags=re.ASCII)
    return label if label[:1].isalpha() or label[:1] == "_" else f"_{label}"


def unit_suffix(unit: str) -> str:
    """A unit as a column-name suffix: ``"m/s"`` -> ``"m_s"``, ``"N m"`` -> ``"Nm"``."""
    return re.sub(r"\W+", "", unit.replace("/", "_"))
