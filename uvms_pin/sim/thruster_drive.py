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
    # inf * 0 (no rate limit, no time constant) is resolved by the np.where's below
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        error = steady_N - thrust_N
        band = rate_limit_N_s * time_constant_s  # the ramp lasts until |error| = r tau
        ramp_s = np.where(np.abs(error) > band, (np.abs(error) - band) / rate_limit_N_s, 0.0)
        ramp_s = np.minimum(np.nan_to_num(ramp_s, nan=0.0), dt_s)
        ramping = ramp_s > 0.0
        ramped = np.where(ramping, thrust_N + np.sign(error) * rate_limit_N_s * ramp_s, thrust_N)
        integral = np.where(ramping, 0.5 * (thrust_N + ramped) * ramp_s, 0.0)
        rest_s = dt_s - ramp_s
        remaining = steady_N - ramped
        # no lag: the rest of the period (if any) is at T_ss at once
        instant = np.where(rest_s > 0.0, 0.0, 1.0)
        decay = np.where(time_constant_s > 0.0, np.exp(-rest_s / time_constant_s), instant)
        # the integral of T_ss - e exp(-t/tau) over the rest h: T_ss h - e tau (1 - exp(-h/tau))
        lag = np.where(time_constant_s > 0.0, remaining * time_constant_s * (1.0 - decay), 0.0)
        tail = steady_N * rest_s - lag
    end = steady_N - remaining * decay
    return end, (integral + tail) / dt_s


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
        return np.array(
            [c.command_for(np.array([f]))[0] for c, f in zip(self.curves, desired_N, strict=True)]
        )

    def steady_thrust_N(self, command: np.ndarray) -> np.ndarray:
        return np.array(
            [c.thrust_N(np.array([u]))[0] for c, u in zip(self.curves, command, strict=True)]
        )

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
