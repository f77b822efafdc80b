"""What pushes the vehicle besides the water: disturbance wrenches on its body."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from uvms_pin.checks import finite_vector, number_fields
from uvms_pin.errors import ParameterError


@dataclass(frozen=True)
class SinusoidalDisturbance:
    """delta(t) = amplitude sin(2 pi t / period + phase), a body wrench on the vehicle.

    The paper's: amplitude 0.15 N on x, y, z, period 7 s.
    """

    amplitude: np.ndarray = field(default_factory=lambda: np.array([0.15, 0.15, 0.15, 0, 0, 0]))
    period_s: float = 7.0
    phase_rad: float = 0.0

    def __post_init__(self) -> None:
        number_fields(self)
        object.__setattr__(
            self, "amplitude", finite_vector("disturbance amplitude", self.amplitude, 6)
        )
        if not (self.period_s > 0.0 and math.isfinite(self.period_s)):
            raise ParameterError(f"disturbance period_s must be positive, got {self.period_s}")
        if not math.isfinite(self.phase_rad):
            raise ParameterError(f"disturbance phase_rad must be finite, got {self.phase_rad}")

    def __call__(self, time_s: float) -> np.ndarray:
        return self.amplitude * math.sin(2.0 * math.pi * time_s / self.period_s + self.phase_rad)


Disturbance = Callable[[float], np.ndarray]
"""Any function of time returning a (6,) body wrench [N; N m] on the vehicle."""
