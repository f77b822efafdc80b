"""BlueROV2 Heavy: 8 Blue Robotics T200 thrusters (4 vectored horizontal, 4 vertical).

Geometry (models/README.md section 7): von Benzon et al. 2022 (J. Mar. Sci. Eng. 10, 1898),
thruster allocation of their BlueROV2 Heavy simulator, given there in NED (x forward,
y starboard, z down) and converted here to the body frame x forward, y left, z up
(y and z change sign). Horizontal thrusters at (+-0.156, +-0.111, -0.085) m, their axes
45 deg off the surge axis; vertical thrusters at (+-0.120, +-0.218, 0) m, axes along z.
Positive thrust pushes along ``direction_body``; every T200 can thrust both ways.

T200 thrust at 16 V: the ends of Blue Robotics' measured table (`uvms_pin.model.vehicles.t200`,
1900 and 1100 us): 5.25 kgf forward, 4.07 kgf reverse (the nozzle favours the forward
direction; the technical details round the reverse to 4.1 kgf). The scenarios' limits and
``curve = "t200_16v"`` therefore agree. `T200.thrust_N` is the quadratic
command law f = F_max u |u| used for a normalised command u in [-1, 1] (thrust grows
with the square of propeller speed, which grows about linearly with the ESC command).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.model.thruster import Thruster
from uvms_pin.model.vehicles.t200 import t200_16v_curve

__all__ = ["T200", "T200_16V", "thrusters"]


@dataclass(frozen=True)
class T200:
    """A T200 at one supply voltage: thrust limits [N] and the command-to-thrust law."""

    voltage_V: float
    max_forward_N: float
    max_reverse_N: float

    def thrust_N(self, command: float) -> float:
        """f(u) = F_fwd u^2 (u >= 0), -F_rev u^2 (u < 0), u the command in [-1, 1]."""
        if not (math.isfinite(command) and -1.0 <= command <= 1.0):
            raise ParameterError(f"T200 command must be in [-1, 1], got {command}")
        limit = self.max_forward_N if command >= 0.0 else self.max_reverse_N
        return math.copysign(limit * command * command, command)


T200_16V = T200(16.0, t200_16v_curve().max_forward_N, t200_16v_curve().max_reverse_N)

_H = math.sqrt(0.5)
# name, position (FLU) [m], direction (FLU) for positive thrust
_LAYOUT = (
    ("front_right_horizontal", (0.156, -0.111, -0.085), (_H, _H, 0.0)),
    ("front_left_horizontal", (0.156, 0.111, -0.085), (_H, -_H, 0.0)),
    ("rear_right_horizontal", (-0.156, -0.111, -0.085), (_H, -_H, 0.0)),
    ("rear_left_horizontal", (-0.156, 0.111, -0.085), (_H, _H, 0.0)),
    ("front_right_vertical", (0.120, -0.218, 0.0), (0.0, 0.0, 1.0)),
    ("front_left_vertical", (0.120, 0.218, 0.0), (0.0, 0.0, 1.0)),
    ("rear_right_vertical", (-0.120, -0.218, 0.0), (0.0, 0.0, 1.0)),
    ("rear_left_vertical", (-0.120, 0.218, 0.0), (0.0, 0.0, 1.0)),
)


def thrusters(model: T200 = T200_16V, offset_body_m=(0.0, 0.0, 0.0)) -> list[Thruster]:
    """The 8 thrusters for `uvms_pin.sim.actuation.ThrustersAndJointLimits`.

    Args:
        model: the T200 model giving the thrust limits.
        offset_body_m: added to every position, e.g. to refer them to another body origin.
    """
    offset = np.asarray(offset_body_m, dtype=float)
    return [
        Thruster(
            name,
            np.asarray(position) + offset,
            np.asarray(direction),
            model.max_forward_N,
            model.max_reverse_N,
        )
        for name, position, direction in _LAYOUT
    ]
