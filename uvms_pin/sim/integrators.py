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
from typing import ClassVar

import numpy as np
import pinocchio as pin

from uvms_pin.checks import number_fields, positive
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.physics.derivatives.step import split_interval

Rhs = Callable[[float, np.ndarray, np.ndarray], np.ndarray]
Event = Callable[[float, np.ndarray, np.ndarray], float]
"""A function of (t, q, v) whose downward zero crossing stops an adaptive integration."""
Chart = Callable[[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
"""(q0, delta, v) -> (integrate(q0, delta), Jint(q0, delta)^-1 v): the local chart, e.g. the
compiled plant's ``chart`` (default: `python_chart`)."""


class Integrator(ABC):
    """Advances the state of a Pinocchio model from t0 to t1."""

    @abstractmethod
    def advance(
        self, model: pin.Model, rhs: Rhs, t0: float, q0: np.ndarray, v0: np.ndarray, t1: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Return (q, v) at t1."""

    def advance_through(
        self,
        model: pin.Model,
        rhs: Rhs,
        t0: float,
        q0: np.ndarray,
        v0: np.ndarray,
        times: np.ndarray,
        event: Event | None = None,
        chart: Chart | None = None,
    ) -> list[tuple[float, np.ndarray, np.ndarray]]:
        """(t, q, v) at each of the increasing ``times`` (> t0), in one pass.

        With an ``event`` (adaptive integrators only; fixed-step ones ignore it), the pass
        stops where the event crosses zero downwards: the last entry is then that state.
        ``chart`` (adaptive integrators only) evaluates the local chart; None: Pinocchio's
        integrate and dIntegrate from Python (`python_chart`).
        """
        out = []
        t, q, v = t0, q0, v0
        try:
            for t_next in times:
                q, v = self.advance(model, rhs, t, q, v, float(t_next))
                t = float(t_next)
                out.append((t, q, v))
        except SimulationError as error:  # e.g. the controller raised inside rhs
            error.states = out  # the output times reached before the failure
            raise
        return out


def _chart_rate(model: pin.Model, q0: np.ndarray, delta: np.ndarray, v: np.ndarray) -> np.ndarray:
    """delta_dot with integrate(q0, delta)'s velocity equal to v (body-frame zeta)."""
    jac = pin.dIntegrate(model, q0, delta, pin.ARG1)
    return np.linalg.solve(jac, v)


def python_chart(model: pin.Model) -> Chart:
    """The local chart of ``model`` evaluated from Python (the reference of the core's)."""

    def chart(q0: np.ndarray, delta: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return pin.integrate(model, q0, delta), _chart_rate(model, q0, delta, v)

    return chart


def interval_substeps(t0: float, t1: float, max_step_s: float) -> tuple[int, float]:
    """(n, h): the fewest equal substeps no longer than ``max_step_s`` [s] from t0 to t1
    (one at least; more than `MAX_SUBSTEPS`: ParameterError), as the core splits it."""
    return split_interval(t1 - t0, max_step_s)


@dataclass(frozen=True)
class FixedStep(Integrator):
    """An integrator taking equal substeps no longer than ``step_s`` [s] between t0 and t1,
    in one compiled call per interval when the plant runs in the core (``core_method``: the
    name of its counterpart in src/uvms_core/integrators.hpp)."""

    step_s: float = 1e-3
    core_method: ClassVar[str] = ""

    def __post_init__(self) -> None:
        number_fields(self)
        if not (self.step_s > 0.0 and math.isfinite(self.step_s)):
            raise ParameterError(
                f"{type(self).__name__} step_s must be positive, got {self.step_s}"
            )

    def advance(self, model, rhs, t0, q0, v0, t1):
        n, h = interval_substeps(t0, t1, self.step_s)
        q, v = q0, v0
        for k in range(n):
            q, v = self.step(model, rhs, t0 + k * h, q, v, h)
        return q, v

    @abstractmethod
    def step(self, model, rhs, t, q, v, h):
        """(q, v) one substep h [s] after (q, v) at t."""

    def linear_step(self, h: float, rate_matrix: np.ndarray) -> np.ndarray | None:
        """The matrix Phi of one substep h [s] on the linear system y' = A y, y = (x, x_dot),
        ``rate_matrix`` A = [[0, I], [-K, -C]] (2n x 2n, K, C stiffness and damping over
        mass): y+ = Phi y. The step is stable on it while Phi's spectral radius is <= 1
        (`uvms_pin.sim.stiffness`). None: not known (an integrator of your own; its stiff
        modes are not checked)."""
        return None


@dataclass(frozen=True)
class RK4(FixedStep):
    """Classical 4th-order Runge-Kutta in the local chart (Runge-Kutta-Munthe-Kaas)."""

    core_method: ClassVar[str] = "rk4"

    def step(self, model, rhs, t, q0, v0, h):
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

    def linear_step(self, h, rate_matrix):
        """Phi = R(h A), R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24 (the degree-4 Taylor
        polynomial: stable on the imaginary axis up to |h lambda| = 2 sqrt(2), on the
        negative real axis to 2.785)."""
        z = h * np.asarray(rate_matrix, dtype=float)
        out = term = np.eye(len(z))
        for k in range(1, 5):
            term = term @ z / k
            out = out + term
        return out


@dataclass(frozen=True)
class SemiImplicitEuler(FixedStep):
    """Symplectic Euler: v+ = v + h a(q, v); q+ = integrate(q, h v+). One rhs call per step."""

    step_s: float = 1e-4
    core_method: ClassVar[str] = "semi_implicit_euler"

    def step(self, model, rhs, t, q, v, h):
        v = v + h * rhs(t, q, v)
        return pin.integrate(model, q, h * v), v

    def linear_step(self, h, rate_matrix):
        """v+ = v + h (A_x x + A_v v), x+ = x + h v+: Phi = [[I + h^2 A_x, h (I + h A_v)],
        [h A_x, I + h A_v]] (A's lower blocks A_x, A_v; undamped: stable to h omega = 2)."""
        a = np.asarray(rate_matrix, dtype=float)
        n = len(a) // 2
        eye = np.eye(n)
        a_x, a_v = a[n:, :n], a[n:, n:]
        return np.block([[eye + h * h * a_x, h * (eye + h * a_v)], [h * a_x, eye + h * a_v]])


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
        number_fields(self, "adaptive")
        if self.method not in self._METHODS:
            raise ParameterError(
                f"adaptive method must be one of {self._METHODS}, got '{self.method}'"
            )
        for name in ("rtol", "atol"):
            positive(f"adaptive {name}", getattr(self, name))
        if not self.max_step_s > 0.0:  # inf: no bound
            raise ParameterError(f"adaptive max_step_s must be > 0, got {self.max_step_s}")

    def advance(self, model, rhs, t0, q0, v0, t1):
        _, q, v = self.advance_through(model, rhs, t0, q0, v0, np.array([t1]))[-1]
        return q, v

    def advance_through(self, model, rhs, t0, q0, v0, times, event=None, chart=None):
        """One solve_ivp call from t0 to times[-1] in the chart at q0 (keeps the step size
        and Jacobian history across output times; re-base by calling again). The event,
        if any, is checked on every accepted step and located by root finding."""
        # scipy.integrate is imported where it is used: it takes a quarter second to import,
        # which every start-up would pay otherwise
        from scipy.integrate import solve_ivp

        nv = model.nv
        chart = python_chart(model) if chart is None else chart
        times = np.asarray(times, dtype=float)
        events = None
        if event is not None:

            def chart_event(t: float, y: np.ndarray) -> float:
                return event(t, pin.integrate(model, q0, y[:nv]), y[nv:])

            chart_event.terminal = True
            chart_event.direction = -1.0
            events = [chart_event]

        def chart_rhs(t: float, y: np.ndarray) -> np.ndarray:
            delta, v = y[:nv], y[nv:]
            q, delta_dot = chart(q0, delta, v)
            out = np.empty(2 * nv)
            out[:nv] = delta_dot
            out[nv:] = rhs(t, q, v)
            return out

        y0 = np.concatenate([np.zeros(nv), v0])
        sol = solve_ivp(
            chart_rhs,
            (t0, float(times[-1])),
            y0,
            method=self.method,
            rtol=self.rtol,
            atol=self.atol,
            max_step=self.max_step_s,
            t_eval=times,
            events=events,
        )
        # sol.y is an empty list, not an array, when no output time was reached
        ys = np.reshape(sol.y, (2 * nv, len(sol.t))).T
        out = [
            (float(t), pin.integrate(model, q0, y[:nv]), y[nv:].copy())
            for t, y in zip(sol.t, ys, strict=True)
        ]
        if not sol.success:
            error = SimulationError(
                f"{self.method} failed between t = {t0:.6g} s and {times[-1]:.6g} s: {sol.message}"
            )
            error.states = out  # the output times reached before the failure
            raise error
        if sol.status == 1:  # stopped by the event
            t_event, y_event = float(sol.t_events[0][0]), sol.y_events[0][0]
            out.append((t_event, pin.integrate(model, q0, y_event[:nv]), y_event[nv:].copy()))
        return out
