"""Prescribed-performance building blocks (Bechlioulis & Rovithakis; paper Section 4).

A performance function bounds an error from both sides, ``-rho(t) < e(t) < rho(t)``, with

    rho(t) = (rho0 - rho_inf) exp(-l t) + rho_inf,     rho0 > rho_inf > 0,  l > 0.

The error is normalized, ``xi = e / rho`` in (-1, 1), and mapped to the whole real line by

    eps(xi) = ln((1 + xi) / (1 - xi)) = 2 artanh(xi),   r(xi) = d eps / d xi = 2 / (1 - xi^2).

Everything is vectorized over components (one rho per error component). eps and r are
undefined at |xi| >= 1; the functions here never return NaN or inf silently: they raise,
and :func:`check_funnel` turns a violation into a :class:`~uvms_pin.errors.FunnelViolation`
naming the component, the time, the error and the bound.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from uvms_pin.errors import FunnelViolation, ParameterError


def check_funnel_bounds(
    rho0: np.ndarray, rho_inf: np.ndarray, decay_rate_per_s: np.ndarray, names: Sequence[str]
) -> None:
    """rho0 > rho_inf > 0 and l > 0 for every component (1-D arrays of one size, one name
    each); ParameterError naming the funnel otherwise."""
    for j, name in enumerate(names):
        if not rho_inf[j] > 0.0:
            raise ParameterError(f"funnel '{name}': rho_inf = {rho_inf[j]} must be > 0")
        if not rho0[j] > rho_inf[j]:
            raise ParameterError(
                f"funnel '{name}': rho0 = {rho0[j]} must be > rho_inf = {rho_inf[j]}"
            )
        if not decay_rate_per_s[j] > 0.0:
            raise ParameterError(
                f"funnel '{name}': decay_rate_per_s = {decay_rate_per_s[j]} must be > 0"
            )


class PerformanceFunction:
    """Exponentially decaying funnels rho_j(t), one per error component.

    Args:
        rho0: initial bounds rho_j(0) (same unit as the error), scalar or (m,).
        rho_inf: steady-state bounds rho_j(inf) (same unit), scalar or (m,).
        decay_rate_per_s: decay rates l_j [1/s], scalar or (m,).
        names: optional component names, used in error messages.

    Scalars broadcast against the arrays; the result is 1-D with m components.

    Raises:
        ParameterError: a value is non-finite, the shapes do not broadcast to one 1-D size,
            or rho0 > rho_inf > 0 and l > 0 fail for a component (named in the message).
    """

    def __init__(
        self,
        rho0: ArrayLike,
        rho_inf: ArrayLike,
        decay_rate_per_s: ArrayLike,
        names: Sequence[str] | None = None,
    ):
        arrays = []
        for label, value in (
            ("rho0", rho0),
            ("rho_inf", rho_inf),
            ("decay_rate_per_s", decay_rate_per_s),
        ):
            array = np.atleast_1d(np.asarray(value, dtype=float))
            if array.ndim != 1:
                raise ParameterError(f"{label} must be a scalar or a 1-D array, got {array.shape}")
            if not np.all(np.isfinite(array)):
                raise ParameterError(f"{label} has non-finite entries: {array}")
            arrays.append(array)
        try:
            rho0_arr, rho_inf_arr, rate_arr = np.broadcast_arrays(*arrays)
        except ValueError as exc:
            shapes = [a.shape for a in arrays]
            raise ParameterError(
                f"rho0, rho_inf, decay_rate_per_s shapes {shapes} do not broadcast"
            ) from exc
        size = rho0_arr.shape[0]
        if names is None:
            names = [f"component {j}" for j in range(size)]
        names = [str(name) for name in names]
        if len(names) != size:
            raise ParameterError(f"{len(names)} names given for {size} funnel components")
        check_funnel_bounds(rho0_arr, rho_inf_arr, rate_arr, names)
        self.rho0 = rho0_arr.copy()
        self.rho_inf = rho_inf_arr.copy()
        self.decay_rate_per_s = rate_arr.copy()
        self.names = tuple(names)
        self._gap = self.rho0 - self.rho_inf
        self._negative_rate = -self.decay_rate_per_s
        for array in (self.rho0, self.rho_inf, self.decay_rate_per_s, self._gap):
            array.flags.writeable = False

    @property
    def size(self) -> int:
        """Number of components m."""
        return self.rho0.shape[0]

    def value(self, time_s: float) -> np.ndarray:
        """rho(t) = (rho0 - rho_inf) exp(-l t) + rho_inf, shape (m,)."""
        return self._gap * np.exp(self._negative_rate * time_s) + self.rho_inf

    def derivative(self, time_s: float) -> np.ndarray:
        """rho_dot(t) = -l (rho0 - rho_inf) exp(-l t) [unit/s], shape (m,)."""
        return (
            -self.decay_rate_per_s
            * (self.rho0 - self.rho_inf)
            * np.exp(-self.decay_rate_per_s * time_s)
        )

    def __repr__(self) -> str:
        return (
            f"PerformanceFunction(rho0={self.rho0.tolist()}, rho_inf={self.rho_inf.tolist()}, "
            f"decay_rate_per_s={self.decay_rate_per_s.tolist()})"
        )


def normalized_error(error: ArrayLike, rho: ArrayLike) -> np.ndarray:
    """xi = e / rho, component-wise (rho > 0). Dimensionless."""
    rho = np.asarray(rho, dtype=float)
    if np.any(~(rho > 0.0)):
        raise ParameterError(f"performance bounds must be > 0, got {rho}")
    return np.asarray(error, dtype=float) / rho


def _require_inside(xi: np.ndarray, what: str) -> None:
    if np.any(~(np.abs(xi) < 1.0)):
        raise ParameterError(
            f"{what} is undefined for |xi| >= 1 (or NaN), got xi = {xi}; "
            "call check_funnel first to report a FunnelViolation"
        )


def transformed_error(xi: ArrayLike) -> np.ndarray:
    """eps(xi) = ln((1 + xi) / (1 - xi)) = 2 artanh(xi), for |xi| < 1.

    Raises:
        ParameterError: some |xi| >= 1 or NaN (instead of returning inf / NaN).
    """
    xi = np.asarray(xi, dtype=float)
    _require_inside(xi, "transformed_error")
    return 2.0 * np.arctanh(xi)


def transformation_gain(xi: ArrayLike) -> np.ndarray:
    """r(xi) = d eps / d xi = 2 / (1 - xi^2), for |xi| < 1 (r >= 2).

    Raises:
        ParameterError: some |xi| >= 1 or NaN.
    """
    xi = np.asarray(xi, dtype=float)
    _require_inside(xi, "transformation_gain")
    return 2.0 / (1.0 - xi * xi)


def check_funnel(
    *,
    level: str,
    names: Sequence[str],
    time_s: float,
    error: ArrayLike,
    bound: ArrayLike,
) -> np.ndarray:
    """Return xi = error / bound, or raise if any component left its funnel.

    A component is violated when ``|error_j| >= bound_j`` (``|xi_j| >= 1``) or when xi_j is
    not finite (a NaN error can never be reported as "inside").

    Args:
        level: name of the funnel level, e.g. ``"first"`` or ``"second"``.
        names: one name per component, e.g. ``["f_x", ..., "yaw"]``.
        time_s: current time [s].
        error: errors e (m,).
        bound: bounds rho(t) > 0 (m,).

    Raises:
        FunnelViolation: for the violated component with the largest |xi| (NaN first),
            carrying level, component name, time, error and bound.
    """
    error = np.asarray(error, dtype=float)
    bound = np.asarray(bound, dtype=float)
    if error.shape != bound.shape or error.ndim != 1 or len(names) != error.shape[0]:
        raise ParameterError(
            f"check_funnel: error {error.shape}, bound {bound.shape} and {len(names)} names "
            "must describe the same number of components"
        )
    xi = normalized_error(error, bound)
    violated = ~(np.abs(xi) < 1.0)
    if np.any(violated):
        severity = np.where(np.isnan(xi), np.inf, np.abs(xi))
        j = int(np.argmax(np.where(violated, severity, -1.0)))
        raise FunnelViolation(
            level=level,
            component=str(names[j]),
            time_s=float(time_s),
            error=float(error[j]),
            bound=float(bound[j]),
        )
    return xi


def max_abs(values: np.ndarray | list[float]) -> float:
    """max_j |values_j| of a 1-D array or list of floats; NaN if any value is NaN.

    A NaN must never pass a funnel check (``max_abs(xi) < 1``), and Python's ``max`` may skip
    one, so a NaN sum turns the answer into NaN. Python floats: for the 6 to ~20 components
    of a funnel level this costs less than numpy's reductions.
    """
    items = values.tolist() if isinstance(values, np.ndarray) else values
    largest = max(map(abs, items))
    total = sum(items)
    return largest if total == total else math.nan


def transformed_error_extended(xi: ArrayLike, clamp: float) -> np.ndarray:
    """eps(xi) inside |xi| <= clamp, continued linearly (slope r(clamp)) beyond it.

    Only for integrating a continuous-time closed loop: a trial stage outside the funnel
    then sees a transformed error that keeps growing, so an implicit integrator's stage
    equations have no solution out there (a flat, clamped extension would give one).
    """
    xi = np.asarray(xi, dtype=float)
    inside = np.clip(xi, -clamp, clamp)
    return 2.0 * np.arctanh(inside) + (2.0 / (1.0 - clamp * clamp)) * (xi - inside)


def barrier_extended(xi: ArrayLike, clamp: float) -> np.ndarray:
    """b(xi) = r(xi) eps(xi) inside |xi| <= clamp, continued linearly beyond it (see
    `transformed_error_extended`); b'(xi) = 4 xi eps / (1 - xi^2)^2 + r^2."""
    xi = np.asarray(xi, dtype=float)
    inside = np.clip(xi, -clamp, clamp)
    one_minus = 1.0 - inside * inside
    eps = 2.0 * np.arctanh(inside)
    r = 2.0 / one_minus
    slope = 4.0 * inside * eps / (one_minus * one_minus) + r * r
    return r * eps + slope * (xi - inside)
