"""Fit hydrodynamic parameters to measured roll and pitch by Levenberg-Marquardt on the
simulation error.

The residual r(p) stacks, over the trials and their IMU samples, the simulated minus the
measured roll and pitch [rad] of the prescribed-arm simulation (`uvms_pin.apps.validation.
pool`). Its Jacobian is exact to the integrator's order: the state sensitivity S = dx/dp
propagated along each simulation (`uvms_pin.apps.validation.sensitivity`), mapped to roll and
pitch by `roll_pitch_tangent`. Each iteration solves

    (J^T J + lambda diag(J^T J)) dp = -J^T r

(Marquardt's scaling makes the step independent of the parameters' units), accepts dp if the
cost 1/2 |r|^2 falls (lambda / 3), else retries with lambda x 4. Parameters that must stay
non-negative (damping, added mass) are projected onto p >= 0.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from uvms_pin.apps.validation.parameters import HydroParameter, parameter_values
from uvms_pin.apps.validation.pool import TrialSetup
from uvms_pin.apps.validation.sensitivity import (
    SensitiveModel,
    roll_pitch_tangent,
    simulate_with_sensitivity,
)
from uvms_pin.apps.validation.trials import roll_pitch_rad
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.model.uvms import UVMS

__all__ = ["FitResult", "fit_parameters", "simulation_residuals"]


@dataclass(frozen=True)
class FitResult:
    """The fitted values, where the fit started, and the cost at each accepted iterate."""

    parameters: tuple[HydroParameter, ...]
    link: str
    start: np.ndarray
    values: np.ndarray
    rms_deg: list[float]  # RMS of the residual [deg] at the start and each accepted step
    iterations: int  # steps tried, accepted or not
    uvms: UVMS  # the system with the fitted values


def simulation_residuals(
    model: SensitiveModel, setups: Sequence[TrialSetup], step_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """(r (N,), dr/dp (N, n_p)): simulated minus measured roll and pitch [rad] of every
    trial, sample by sample (roll, pitch interleaved)."""
    residuals, jacobians = [], []
    for setup in setups:
        trajectory = simulate_with_sensitivity(
            model, setup.arm, setup.q_vehicle0, setup.nu_vehicle0, setup.time_s, step_s
        )
        roll_pitch = roll_pitch_rad(trajectory.q_vehicle[:, 3:7])
        residuals.append((roll_pitch - setup.measured).ravel())
        jac = roll_pitch_tangent(roll_pitch) @ trajectory.sensitivity[:, :6, :]
        jacobians.append(jac.reshape(-1, jac.shape[-1]))
    return np.concatenate(residuals), np.vstack(jacobians)


def _evaluate(uvms, parameters, link, values, setups, step_s):
    """(r, J) at ``values``, or None where the model is invalid or the simulation fails."""
    try:
        model = SensitiveModel(uvms, parameters, link, values)
        r, jac = simulation_residuals(model, setups, step_s)
    except (ParameterError, SimulationError, np.linalg.LinAlgError):
        return None
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(jac))):
        return None
    return r, jac


def _rms_deg(r: np.ndarray) -> float:
    return float(np.degrees(np.sqrt(np.mean(r**2))))


def fit_parameters(
    uvms: UVMS,
    setups: Sequence[TrialSetup],
    parameters: Sequence[HydroParameter],
    link: str,
    step_s: float,
    *,
    start: np.ndarray | None = None,
    max_iterations: int = 20,
    tolerance: float = 1e-4,
    progress: Callable[[str], None] | None = None,
) -> FitResult:
    """Levenberg-Marquardt fit of ``parameters`` of ``link`` to the trials' roll and pitch.

    Starts from ``start`` (default: the values in ``uvms``); stops when an accepted step
    lowers the cost by less than ``tolerance`` (relative), when lambda grows past 1e10 (no
    step lowers the cost), or after ``max_iterations``.

    Raises:
        SimulationError: the simulation fails at the start values.
    """
    parameters = tuple(parameters)
    values = parameter_values(uvms, parameters, link) if start is None else np.array(start, float)
    first = _evaluate(uvms, parameters, link, values, setups, step_s)
    if first is None:
        raise SimulationError(f"the trials cannot be simulated at the start values {values}")
    r, jac = first
    start_values, history, lam, iteration = values.copy(), [_rms_deg(r)], 1e-3, 0
    if progress is not None:
        progress(f"start: RMS {history[0]:.4f} deg")
    floor = np.array([0.0 if p.nonnegative else -np.inf for p in parameters])
    while iteration < max_iterations and lam < 1e10:
        iteration += 1
        gradient, normal = jac.T @ r, jac.T @ jac
        scale = np.maximum(np.diag(normal), 1e-12 * max(1.0, float(np.max(np.diag(normal)))))
        step = np.linalg.solve(normal + lam * np.diag(scale), -gradient)
        candidate = np.maximum(values + step, floor)
        trial = _evaluate(uvms, parameters, link, candidate, setups, step_s)
        cost, new_cost = 0.5 * r @ r, np.inf if trial is None else 0.5 * trial[0] @ trial[0]
        if new_cost >= cost:
            lam *= 4.0
            continue
        values, (r, jac), lam = candidate, trial, max(lam / 3.0, 1e-9)
        history.append(_rms_deg(r))
        if progress is not None:
            shown = ", ".join(f"{p.name} {x:.5g}" for p, x in zip(parameters, values, strict=True))
            progress(f"iteration {iteration}: RMS {history[-1]:.4f} deg ({shown})")
        if cost - new_cost < tolerance * cost:
            break
    fitted = SensitiveModel(uvms, parameters, link, values).uvms
    return FitResult(parameters, link, start_values, values, history, iteration, fitted)
