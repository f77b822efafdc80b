"""A thruster's steady thrust against its command: T = curve(u), u in [-1, 1].

- `QuadraticThrustCurve`: the propeller law T = k n |n| with n the propeller speed, taken
  proportional to the command beyond a deadband d: s = (|u| - d) / (1 - d) for |u| > d,
  else 0, and T = T_fwd s^2 (u > 0) or -T_rev s^2 (u < 0): asymmetric when T_fwd != T_rev
  (a propeller pushes less in reverse).
- `TabulatedThrustCurve`: measured points (u_k, T_k), linear between them (a published
  bollard-pull table such as the T200's, `uvms_pin.model.vehicles.t200`); the deadband is
  where the table is zero.

Both are non-decreasing, so a driver that wants thrust T sends the command
``command_for(T)``: the smallest |u| giving T (T clipped to the curve's range).
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from uvms_pin.checks import nonnegative
from uvms_pin.errors import ParameterError

__all__ = ["QuadraticThrustCurve", "TabulatedThrustCurve", "ThrustCurve"]


class ThrustCurve(ABC):
    """Steady thrust [N] of a command u in [-1, 1]; its inverse for a driver."""

    name: str

    @abstractmethod
    def thrust_N(self, command: np.ndarray) -> np.ndarray:
        """T(u) [N] (commands outside [-1, 1] are clipped)."""

    @abstractmethod
    def command_for(self, thrust_N: np.ndarray) -> np.ndarray:
        """The command of least magnitude whose thrust is ``thrust_N`` clipped to
        [-max_reverse_N, max_forward_N]."""

    @property
    def max_forward_N(self) -> float:
        return float(self.thrust_N(np.array([1.0]))[0])

    @property
    def max_reverse_N(self) -> float:
        return float(-self.thrust_N(np.array([-1.0]))[0])


class QuadraticThrustCurve(ThrustCurve):
    """T = T_fwd s^2 or -T_rev s^2, s = max(|u| - d, 0) / (1 - d) (see the module).

    Args:
        max_forward_N, max_reverse_N: thrust at u = 1 and -u at u = -1 [N], >= 0.
        deadband: d in [0, 1): the command fraction around 0 that gives no thrust.
    """

    def __init__(self, max_forward_N: float, max_reverse_N: float, deadband: float = 0.0):
        for label, value in (("max_forward_N", max_forward_N), ("max_reverse_N", max_reverse_N)):
            nonnegative(label, value)
        if not (0.0 <= deadband < 1.0):
            raise ParameterError(f"deadband must be in [0, 1), got {deadband}")
        self.forward_N, self.reverse_N, self.deadband = (
            float(max_forward_N),
            float(max_reverse_N),
            float(deadband),
        )
        self.name = "quadratic"

    def thrust_N(self, command):
        u = np.minimum(np.maximum(np.asarray(command, dtype=float), -1.0), 1.0)
        s = np.maximum(np.abs(u) - self.deadband, 0.0) / (1.0 - self.deadband)
        return np.where(u >= 0.0, self.forward_N, -self.reverse_N) * s * s

    def command_for(self, thrust_N):
        t = np.asarray(thrust_N, dtype=float)
        full = np.where(t >= 0.0, self.forward_N, self.reverse_N)
        ratio = np.divide(np.abs(t), full, out=np.zeros_like(t), where=full > 0.0)
        s = np.sqrt(np.minimum(ratio, 1.0))
        magnitude = np.where(s > 0.0, self.deadband + (1.0 - self.deadband) * s, 0.0)
        return np.sign(t) * magnitude


class TabulatedThrustCurve(ThrustCurve):
    """Measured (u_k, T_k), linear in between; u_k increasing from -1 to 1, T_k
    non-decreasing, T = 0 at u = 0.

    Args:
        command: u_k (n,) strictly increasing, first -1 and last 1.
        thrust_N: T_k (n,) [N], non-decreasing.
        name: where the points come from (for reports).
    """

    def __init__(self, command: np.ndarray, thrust_N: np.ndarray, name: str = "table"):
        u = np.asarray(command, dtype=float).reshape(-1)
        t = np.asarray(thrust_N, dtype=float).reshape(-1)
        if (
            u.shape != t.shape
            or u.size < 2
            or not (np.all(np.isfinite(u)) and np.all(np.isfinite(t)))
        ):
            raise ParameterError(
                f"thrust table needs matching finite command and thrust arrays, got {u.shape}, {t.shape}"
            )
        if not (np.all(np.diff(u) > 0.0) and u[0] == -1.0 and u[-1] == 1.0):
            raise ParameterError("thrust table commands must increase strictly from -1 to 1")
        if np.any(np.diff(t) < 0.0):
            raise ParameterError("thrust table thrusts must be non-decreasing in the command")
        if float(np.interp(0.0, u, t)) != 0.0:
            raise ParameterError("thrust table must give zero thrust at zero command")
        u.setflags(write=False)
        t.setflags(write=False)
        self.command, self.thrust, self.name = u, t, name
        # the two branches from u = 0 outwards, the reverse one mirrored (u -> -u, T -> -T)
        forward, reverse = u >= 0.0, u <= 0.0
        self._forward = (u[forward], t[forward])
        self._reverse = (-u[reverse][::-1], -t[reverse][::-1])

    def thrust_N(self, command):
        return np.interp(
            np.clip(np.asarray(command, dtype=float), -1.0, 1.0), self.command, self.thrust
        )

    def command_for(self, thrust_N):
        # minimum(maximum()) is np.clip without its per-call dispatch cost
        t = np.minimum(
            np.maximum(np.asarray(thrust_N, dtype=float), self.thrust[0]), self.thrust[-1]
        )
        up = _least_command(*self._forward, t)
        down = -_least_command(*self._reverse, -t)
        return np.where(t > 0.0, up, np.where(t < 0.0, down, 0.0))


def _least_command(command: np.ndarray, thrust: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """On a branch from u = 0 outwards (u increasing from 0, T non-decreasing from 0): the
    least u with T(u) = wanted, for 0 < wanted <= T_max (other entries: anything)."""
    k = np.minimum(np.maximum(np.searchsorted(thrust, wanted, side="left"), 1), thrust.size - 1)
    t0, t1 = thrust[k - 1], thrust[k]
    fraction = np.divide(wanted - t0, t1 - t0, out=np.ones_like(wanted), where=t1 > t0)
    return command[k - 1] + np.minimum(np.maximum(fraction, 0.0), 1.0) * (
        command[k] - command[k - 1]
    )
