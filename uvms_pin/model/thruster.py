"""A thruster fixed on the vehicle body: where it pushes, along which axis, how hard.

The static description of the actuator (like a URDF link): the actuation that allocates a
commanded wrench to the thrusters and saturates them is `uvms_pin.sim.actuation`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.vector import cross3


@dataclass(frozen=True)
class Thruster:
    """One fixed thruster on the vehicle body.

    Attributes:
        name: label for reports.
        position_body_m: point of application r (3,) in the vehicle body frame [m].
        direction_body: thrust direction d (3,) for positive thrust (normalised here).
        max_forward_N, max_reverse_N: thrust limits, f in [-max_reverse, max_forward] [N].
    """

    name: str
    position_body_m: np.ndarray
    direction_body: np.ndarray
    max_forward_N: float
    max_reverse_N: float

    def __post_init__(self) -> None:
        r = np.asarray(self.position_body_m, dtype=float).reshape(-1)
        d = np.asarray(self.direction_body, dtype=float).reshape(-1)
        if (
            r.shape != (3,)
            or d.shape != (3,)
            or not (np.all(np.isfinite(r)) and np.all(np.isfinite(d)))
        ):
            raise ParameterError(
                f"thruster '{self.name}': position and direction need 3 finite numbers"
            )
        norm = float(np.linalg.norm(d))
        if norm == 0.0:
            raise ParameterError(f"thruster '{self.name}': direction must be non-zero")
        for label, value in (
            ("max_forward_N", self.max_forward_N),
            ("max_reverse_N", self.max_reverse_N),
        ):
            if not (value >= 0.0 and math.isfinite(value)):
                raise ParameterError(
                    f"thruster '{self.name}': {label} must be finite and >= 0, got {value}"
                )
        object.__setattr__(self, "position_body_m", r)
        object.__setattr__(self, "direction_body", d / norm)

    @property
    def wrench_column(self) -> np.ndarray:
        """[d; r x d]: the body wrench of a unit thrust."""
        return np.r_[self.direction_body, cross3(self.position_body_m, self.direction_body)]
