"""Time integrators on the configuration manifold (free-flyer = SE(3) x R^n).

Every integrator advances (q, v) from t0 to t1 for a right-hand side
``rhs(t, q, v) -> zeta_dot``. Positions are never added as vectors: a step is taken in
the local chart q = integrate(q0, delta) around the step's starting point, where the
kinematics read delta_dot = Jint(q0, delta)^-1 zeta (Jint = d integrate / d delta,
Pinocchio's dIntegrate). In that chart the ODE is Euclidean, so classical Runge-Kutta and
scipy's adaptive methods keep their order, and the result is mapped back with
``pin.integrate`` (re-based on the manifold at every step or output interval).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

from uvms_pin.errors import ParameterError, SimulationError

Rhs = Callable[[float, np.ndarray, np.ndarray], np.ndarray]


class Integrator(ABC):
    """Advances the state of a Pinocchio model from t0 to t1."""

    @abstractmethod
    def advance(
        self, model: pin.Model, rhs: Rhs, t0: float, q0: np.ndarray, v0: np.ndarray, t1: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Return (q, v) at t1."""


def _chart_rate(model: pin.Model, q0: np.ndarray, delta: np.ndarray, v: np.ndarray) -> np.ndarray:
    """delta_dot with integrate(q0, delta)'s velocity equal to v (body-frame zeta)."""
    jac = pin.dIntegrate(model, q0, delta, pin.ARG1)
    return np.linalg.solve(jac, v)


def _substeps(t0: float, t1: float, max_step_s: float) -> tuple[int, float]:
    n = max(1, math.ceil((t1 - t0) / max_step_s - 1e-9))
    return n, (t1 - t0) / n


@dataclass(frozen=True)
class RK4(Integrator):
    """Classical 4th-order Runge-Kutta in the local chart (Runge-Kutta-Munthe-Kaas).

    Takes equal substeps no longer than ``step_s`` [s] between t0 and t1.
    """

    step_s: float = 1e-3

    def __post_init__(self) -> None:
        if not (self.step_s > 0.0 and math.isfinite(self.step_s)):
            raise ParameterError(f"RK4 step_s must be positive, got {self.step_s}")

    def advance(self, model, rhs, t0, q0, v0, t1):
        n, h = _substeps(t0, t1, self.step_s)
        q, v = q0, v0
        for k in range(n):
            q, v = self._step(model, rhs, t0 + k * h, q, v, h)
        return q, v

    @staticmethod
    def _step(model, rhs, t, q0, v0, h):
        a1 = rhs(t, q0, v0)
        d1 = v0  # Jint(q0, 0) = identity
        delta2 = 0.5 * h * d1
        v2 = v0 + 0.5 * h * a1
        q2 = pin.integrate(model, q0, delta2)
        d2 = _chart_rate(model, q0, delta2, v2)
        a2 = rhs(t + 0.5 * h, q2, v2)
        delta3 = 0.5 * h * d2
        v3 = v0 + 0.5 * h * a2
        q3 = pin.integrate(model, q0, delta3)
        d3 = _chart_rate(model, q0, delta3, v3)
        a3 = rhs(t + 0.5 * h, q3, v3)
        delta4 = h * d3
        v4 = v0 + h * a3
        q4 = pin.integrate(model, q0, delta4)
        d4 = _chart_rate(model, q0, delta4, v4)
        a4 = rhs(t + h, q4, v4)
        delta = (h / 6.0) * (d1 + 2.0 * d2 + 2.0 * d3 + d4)
        v = v0 + (h / 6.0) * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        return pin.integrate(model, q0, delta), v


@dataclass(frozen=True)
class SemiImplicitEuler(Integrator):
    """Symplectic Euler: v+ = v + h a(q, v); q+ = integrate(q, h v+). One rhs call per step."""

    step_s: float = 1e-4

    def __post_init__(self) -> None:
        if not (self.step_s > 0.0 and math.isfinite(self.step_s)):
            raise ParameterError(f"SemiImplicitEuler step_s must be positive, got {self.step_s}")

    def advance(self, model, rhs, t0, q0, v0, t1):
        n, h = _substeps(t0, t1, self.step_s)
        q, v = q0, v0
        for k in range(n):
            v = v + h * rhs(t0 + k * h, q, v)
            q = pin.integrate(model, q, h * v)
        return q, v


@dataclass(frozen=True)
class Adaptive(Integrator):
    """scipy ``solve_ivp`` (LSODA, Radau, BDF, RK45, DOP853) over one interval in the chart.

    The chart is re-based at every call, i.e. at every control or output interval, which
    keeps delta small. Stiff closed loops (a prescribed-performance controller near its
    funnel edge) want LSODA or Radau.
    """

    method: str = "LSODA"
    rtol: float = 1e-6
    atol: float = 1e-8
    max_step_s: float = math.inf

    _METHODS = ("LSODA", "Radau", "BDF", "RK45", "RK23", "DOP853")

    def __post_init__(self) -> None:
        if self.method not in self._METHODS:
            raise ParameterError(
                f"adaptive method must be one of {self._METHODS}, got '{self.method}'"
            )
        if not (self.rtol > 0.0 and self.atol > 0.0 and self.max_step_s > 0.0):
            raise ParameterError("adaptive rtol, atol and max_step_s must be positive")

    def advance(self, model, rhs, t0, q0, v0, t1):
        nv = model.nv

        def chart_rhs(t: float, y: np.ndarray) -> np.ndarray:
            delta, v = y[:nv], y[nv:]
            q = pin.integrate(model, q0, delta)
            out = np.empty(2 * nv)
            out[:nv] = _chart_rate(model, q0, delta, v)
            out[nv:] = rhs(t, q, v)
            return out

        y0 = np.concatenate([np.zeros(nv), v0])
        sol = solve_ivp(
            chart_rhs,
            (t0, t1),
            y0,
            method=self.method,
            rtol=self.rtol,
            atol=self.atol,
            max_step=self.max_step_s,
            t_eval=[t1],
        )
        if not sol.success:
            raise SimulationError(
                f"{self.method} failed between t = {t0:.6g} s and {t1:.6g} s: {sol.message}"
            )
        y1 = sol.y[:, -1]
        return pin.integrate(model, q0, y1[:nv]), y1[nv:].copy()
