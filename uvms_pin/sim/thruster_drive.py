"""Thrusters as drives: a command per thruster, its steady thrust on the thrust curve, and
the thrust following it with first-order dynamics and a rate limit.

For each thruster, with the command u held over a control period (the driver sends
u = curve.command_for(f_desired)) and T_ss = curve(u):

    df/dt = clip((T_ss - f) / tau, -r, r)        (tau: time constant [s], r: rate limit [N/s])

solved exactly over the period: while |T_ss - f| > r tau the thrust ramps at r, then it
decays exponentially, f = T_ss - e exp(-t / tau). The plant is given the thrust's mean over
the period (the same impulse as the continuous f(t)); the state f at the ticks is the
solution itself (63.2 % of a step at t = tau). tau = 0 and r = inf: f = T_ss at once.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.model.thrust_curve import ThrustCurve

__all__ = ["ThrusterDrives", "first_order_step"]


def first_order_step(
    thrust_N: np.ndarray,
    steady_N: np.ndarray,
    time_constant_s: np.ndarray,
    rate_limit_N_s: np.ndarray,
    dt_s: float,
) -> tuple[np.ndarray, np.ndarray]:
    """(f(dt), the mean of f over [0, dt]) for df/dt = clip((T_ss - f)/tau, -r, r), f(0) =
    ``thrust_N`` (element-wise; tau = 0 is an instant lag, r = inf no rate limit)."""
    # a handful of drives per vehicle: scalar arithmetic beats numpy's per-call overhead
    ends, means = np.empty(len(thrust_N)), np.empty(len(thrust_N))
    for k, (f, ss, tau, rate) in enumerate(
        zip(
            thrust_N.tolist(),
            steady_N.tolist(),
            time_constant_s.tolist(),
            rate_limit_N_s.tolist(),
            strict=True,
        )
    ):
        ends[k], means[k] = _step_one(f, ss, tau, rate, dt_s)
    return ends, means


def _step_one(f: float, steady: float, tau: float, rate: float, dt: float) -> tuple[float, float]:
    """One drive over one period: a ramp at the rate limit while |T_ss - f| > r tau, then
    the exponential approach T_ss - e exp(-t / tau); (the end value, the mean)."""
    error = steady - f
    band = rate * tau if math.isfinite(rate) else math.inf  # r tau; no rate limit: never ramp
    ramp = min((abs(error) - band) / rate, dt) if abs(error) > band else 0.0
    ramped = f + math.copysign(rate * ramp, error) if ramp > 0.0 else f
    integral = 0.5 * (f + ramped) * ramp
    rest = dt - ramp
    remaining = steady - ramped
    if tau > 0.0:
        decay = math.exp(-rest / tau)
        tail = steady * rest - remaining * tau * (1.0 - decay)
    else:  # no lag: the rest of the period (if any) is at T_ss at once
        decay = 0.0 if rest > 0.0 else 1.0
        tail = steady * rest
    return steady - remaining * decay, (integral + tail) / dt


class ThrusterDrives:
    """The state of a vehicle's thrusters: their thrust f (m,) [N] between ticks.

    Args:
        curves: each thruster's thrust curve.
        time_constant_s: tau per thruster [s], >= 0.
        rate_limit_N_s: r per thruster [N/s], > 0 (inf: none).
    """

    def __init__(
        self,
        curves: Sequence[ThrustCurve],
        time_constant_s: Sequence[float],
        rate_limit_N_s: Sequence[float],
    ):
        self.curves = tuple(curves)
        # thrusters sharing one curve object are evaluated together
        by_curve: dict[int, list[int]] = {}
        for k, curve in enumerate(self.curves):
            by_curve.setdefault(id(curve), []).append(k)
        self._groups = [(self.curves[ks[0]], np.array(ks)) for ks in by_curve.values()]
        self.time_constant_s = np.asarray(time_constant_s, dtype=float)
        self.rate_limit_N_s = np.asarray(rate_limit_N_s, dtype=float)
        m = len(self.curves)
        if self.time_constant_s.shape != (m,) or self.rate_limit_N_s.shape != (m,):
            raise ParameterError(f"one time constant and one rate limit per thruster ({m}) needed")
        if np.any(~np.isfinite(self.time_constant_s)) or np.any(self.time_constant_s < 0.0):
            raise ParameterError(
                f"time constants must be finite and >= 0, got {self.time_constant_s}"
            )
        if np.any(np.isnan(self.rate_limit_N_s)) or np.any(self.rate_limit_N_s <= 0.0):
            raise ParameterError(f"rate limits must be > 0 (inf: none), got {self.rate_limit_N_s}")
        self.thrust_N = np.zeros(m)
        self.period_s: float | None = None

    @property
    def has_dynamics(self) -> bool:
        return bool(np.any(self.time_constant_s > 0.0) or np.any(np.isfinite(self.rate_limit_N_s)))

    def start(self, period_s: float | None) -> None:
        """Thrust zero at t = 0; ``period_s`` the control period (None: a continuous loop,
        where a thruster with dynamics has no held command to follow)."""
        if period_s is None and self.has_dynamics:
            raise ParameterError(
                "thruster dynamics (time_constant_s, rate_limit_N_s) need a sampled loop: "
                "set [control] period_s"
            )
        self.period_s = period_s
        self.thrust_N = np.zeros(len(self.curves))

    def commands(self, desired_N: np.ndarray) -> np.ndarray:
        """The command u (m,) each driver sends for the thrusts ``desired_N``."""
        out = np.empty(len(self.curves))
        for curve, index in self._groups:
            out[index] = curve.command_for(desired_N[index])
        return out

    def steady_thrust_N(self, command: np.ndarray) -> np.ndarray:
        out = np.empty(len(self.curves))
        for curve, index in self._groups:
            out[index] = curve.thrust_N(command[index])
        return out

    def advance(self, command: np.ndarray) -> np.ndarray:
        """Hold ``command`` for one period: the mean thrust over it (m,) [N]; the state moves
        to the thrust at the period's end."""
        steady = self.steady_thrust_N(command)
        if self.period_s is None or not self.has_dynamics:
            self.thrust_N = steady
            return steady
        self.thrust_N, mean = first_order_step(
            self.thrust_N, steady, self.time_constant_s, self.rate_limit_N_s, self.period_s
        )
        return mean
