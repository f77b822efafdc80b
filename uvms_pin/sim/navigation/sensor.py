"""What a kind of navigation sensor is, and the one registry of them (``[sensors.<name>]``).

A sensor kind is one module of this package that calls `register` with its `SensorKind` on
import: its table's keys (its spec's fields, defaults included; the spec's own check runs
where the scenario is read), its random streams, its logged signals, how it is built and
what it reads at a tick (`Tick`). `uvms_pin.sim.navigation.suite` imports every kind
(the one list of them) and runs them without naming any.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from uvms_pin import checks
from uvms_pin.errors import ParameterError

__all__ = [
    "SENSORS",
    "SensorKind",
    "Tick",
    "check_fields",
    "check_nonneg",
    "check_probability",
    "register",
]


@dataclass(frozen=True)
class Tick:
    """The truth the sensors read at one control tick.

    Attributes:
        time_s: t. position_world_m: the vehicle origin (3,). rotation_world_body: R (3, 3).
        velocity_body_m_s, angular_velocity_body_rad_s: v, w in body axes (3,) each.
        acceleration_world_m_s2: the origin's mean acceleration over the last period (3,).
        period_s: the control period dt.
    """

    time_s: float
    position_world_m: np.ndarray
    rotation_world_body: np.ndarray
    velocity_body_m_s: np.ndarray
    angular_velocity_body_rad_s: np.ndarray
    acceleration_world_m_s2: np.ndarray
    period_s: float


@dataclass(frozen=True)
class SensorKind:
    """One kind of navigation sensor.

    Attributes:
        name: its table ``[sensors.<name>]``.
        spec: its table's keys (keyword arguments, numbers) -> its spec, checked.
        streams: its random streams among the suite's (fixed: a run's draws stay).
        columns: its logged signals: name -> [(component, unit)].
        make: (spec, the suite's spec, its streams' generators) -> the sensor.
        read: (sensor, tick) -> its signals' values at the tick.
        keys: its table's keys and their defaults, in order (None: its spec's fields, a
            dataclass's).
        spec_field: where its spec sits in `uvms_pin.sim.navigation.suite.NavigationSpec`
            (None: its name).
    """

    name: str
    spec: Callable[..., Any]
    streams: tuple[int, ...]
    columns: dict[str, list[tuple[str, str]]]
    make: Callable[[Any, Any, list[np.random.Generator]], Any]
    read: Callable[[Any, Tick], dict[str, np.ndarray]]
    keys: tuple[tuple[str, float], ...] | None = None
    spec_field: str | None = None

    @property
    def field(self) -> str:
        """Its spec's field in `uvms_pin.sim.navigation.suite.NavigationSpec`."""
        return self.name if self.spec_field is None else self.spec_field

    def table_keys(self) -> tuple[tuple[str, float], ...]:
        """Its table's keys and their defaults."""
        if self.keys is not None:
            return self.keys
        return tuple((f.name, f.default) for f in fields(self.spec))


#: ``[sensors.<name>]`` -> its kind, filled by each sensor's module on import
SENSORS: dict[str, SensorKind] = {}


def register(kind: SensorKind) -> SensorKind:
    """Add ``kind`` to `SENSORS` (a second kind of the same name is an error)."""
    if SENSORS.setdefault(kind.name, kind) is not kind:
        raise ParameterError(f"a navigation sensor '{kind.name}' is registered already")
    return kind


def check_nonneg(name: str, value: float, *, positive: bool = False) -> None:
    """ParameterError unless ``value`` is a finite number >= 0 (> 0 when ``positive``)."""
    (checks.positive if positive else checks.nonnegative)(name, value)


def check_probability(name: str, value: float) -> None:
    """ParameterError unless ``value`` is a number in [0, 1)."""
    if not (0.0 <= checks.number(name, value) < 1.0):
        raise ParameterError(f"{name} must be in [0, 1), got {value}")


def check_fields(
    spec: Any, label: str, *, positive: tuple[str, ...] = (), probability: tuple[str, ...] = ()
) -> None:
    """ParameterError unless each of ``spec``'s numbers is finite and >= 0 (> 0 for those in
    ``positive``; in [0, 1) for those in ``probability``), naming it after ``label``."""
    for name, value in vars(spec).items():
        if name in probability:
            check_probability(f"{label} {name}", value)
        else:
            check_nonneg(f"{label} {name}", value, positive=name in positive)
