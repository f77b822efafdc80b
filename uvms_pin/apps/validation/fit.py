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
non-negative (damping, added mass) are projected onto p >= 0; one held at 0 by a gradient
that pushes it outwards is left out of the step (an active set).

It stops (`FitResult.stop_reason`) at the first of:

- ``gradient``: the residual is orthogonal to the Jacobian, max_i |J_i . r| / (|J_i| |r|) <
  ``gradient_tolerance`` (scale-free: the cosine between r and each column; at a bound the
  column's component that pushes outwards does not count);
- ``cost``: an accepted step lowered the cost by less than ``cost_tolerance`` (relative);
- ``step``: an accepted step moved no parameter by more than ``step_tolerance`` of its
  Marquardt scale (|dp_i| sqrt((J^T J)_ii) < step_tolerance |r|);
- ``exact``: the RMS of the residual is below ``exact_rms_rad`` (the data are reproduced to
  rounding: the relative criteria above never hold on a zero-residual problem, where r stays
  in the Jacobian's range while it shrinks);
- ``no descent``: lambda passed 1e10 (no step lowers the cost);
- ``iteration cap``: ``max_iterations`` steps tried (not converged).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from uvms_pin.apps.validation.imu_mount import (
    imu_roll_pitch,
    imu_tangent,
    start_sensitivity,
    vehicle_start,
)
from uvms_pin.apps.validation.parameters import HydroParameter, parameter_values
from uvms_pin.apps.validation.pool import TrialSetup
from uvms_pin.apps.validation.sensitivity import (
    SensitiveModel,
    roll_pitch_tangent,
    simulate_with_sensitivity,
)
from uvms_pin.errors import ParameterError, SimulationError
from uvms_pin.model.uvms import UVMS

__all__ = ["STOP_REASONS", "FitResult", "fit_parameters", "simulation_residuals"]


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
    stop_reason: str = ""  # `STOP_REASONS`
    gradient_cosine: float = float("nan")  # max_i |J_i . r| / (|J_i| |r|) at the end

    @property
    def converged(self) -> bool:
        """True unless the fit stopped at its iteration cap."""
        return self.stop_reason != "iteration cap"


#: why `fit_parameters` stopped (module docstring)
STOP_REASONS = ("gradient", "cost", "step", "exact", "no descent", "iteration cap")


def simulation_residuals(
    model: SensitiveModel, setups: Sequence[TrialSetup], step_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """(r (N,), dr/dp (N, n_p)): simulated minus measured roll and pitch [rad] of every
    trial, sample by sample (roll, pitch interleaved), both in the IMU's axes (the model's
    IMU mounting yaw, `uvms_pin.apps.validation.imu_mount`; 0 unless fitted)."""
    residuals, jacobians = [], []
    psi, column = model.imu_yaw_rad, model.imu_yaw_column
    for setup in setups:
        q0, nu0 = vehicle_start(setup.q_vehicle0, setup.nu_vehicle0, psi)
        s0 = np.zeros((12, len(model.parameters)))
        if column is not None:
            s0[:, column] = start_sensitivity(nu0)
        trajectory = simulate_with_sensitivity(model, setup.arm, q0, nu0, setup.time_s, step_s, s0)
        roll_pitch = imu_roll_pitch(trajectory.q_vehicle[:, 3:7], psi)
        residuals.append((roll_pitch - setup.measured).ravel())
        tangent = roll_pitch_tangent(roll_pitch)[:, :, 3:6]  # d(roll, pitch)/dtheta_imu
        jac = tangent @ imu_tangent(psi) @ trajectory.sensitivity[:, 3:6, :]
        if column is not None:
            jac[:, :, column] += tangent[:, :, 2]  # dtheta_imu = ... + e_z dpsi
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


def _gradient_cosine(
    r: np.ndarray, jac: np.ndarray, values: np.ndarray, floor: np.ndarray
) -> float:
    """max_i |J_i . r| / (|J_i| |r|), leaving out the components that push a parameter held
    at its bound (p_i = floor_i, J_i . r > 0: the cost falls only below the bound)."""
    gradient = jac.T @ r
    norms = np.linalg.norm(jac, axis=0) * np.linalg.norm(r)
    cosine = np.abs(gradient) / np.where(norms > 0.0, norms, 1.0)
    held = (values <= floor) & (gradient > 0.0)
    return float(np.max(np.where(held, 0.0, cosine), initial=0.0))


def _check_settings(max_iterations: int, **tolerances: float) -> None:
    """ParameterError for a tolerance that is not positive or ``max_iterations`` < 1."""
    for name, value in tolerances.items():
        if not value > 0.0:
            raise ParameterError(f"{name} must be > 0, got {value}")
    if max_iterations < 1:
        raise ParameterError(f"max_iterations must be >= 1, got {max_iterations}")


def _damped_step(
    values: np.ndarray, r: np.ndarray, jac: np.ndarray, lam: float, floor: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(the candidate values, the scaling diag(J^T J)) of one Levenberg-Marquardt step:
    (J^T J + lam diag(J^T J)) dp = -J^T r, the candidate clipped at the bounds ``floor``."""
    gradient, normal = jac.T @ r, jac.T @ jac
    scale = np.maximum(np.diag(normal), 1e-12 * max(1.0, float(np.max(np.diag(normal)))))
    # a parameter held at its bound by a gradient that pushes it outwards stays there:
    # the step of the others is solved without it (projecting a coupled step onto the
    # bound afterwards would not lower the cost)
    free = ~((values <= floor) & (gradient > 0.0))
    step = np.zeros_like(values)
    reduced = normal[np.ix_(free, free)] + lam * np.diag(scale[free])
    step[free] = np.linalg.solve(reduced, -gradient[free])
    return np.maximum(values + step, floor), scale


def fit_parameters(
    uvms: UVMS,
    setups: Sequence[TrialSetup],
    parameters: Sequence[HydroParameter],
    link: str,
    step_s: float,
    *,
    start: np.ndarray | None = None,
    max_iterations: int = 50,
    cost_tolerance: float = 1e-5,
    gradient_tolerance: float = 1e-3,
    step_tolerance: float = 1e-5,
    exact_rms_rad: float = 1e-11,
    progress: Callable[[str], None] | None = None,
) -> FitResult:
    """Levenberg-Marquardt fit of ``parameters`` of ``link`` to the trials' roll and pitch.

    Starts from ``start`` (default: the values in ``uvms``); stops as the module docstring
    says (``FitResult.stop_reason``), at the latest after ``max_iterations`` steps tried.

    Raises:
        ParameterError: a tolerance that is not positive, ``max_iterations`` < 1.
        SimulationError: the simulation fails at the start values.
    """
    _check_settings(
        max_iterations,
        cost_tolerance=cost_tolerance,
        gradient_tolerance=gradient_tolerance,
        step_tolerance=step_tolerance,
        exact_rms_rad=exact_rms_rad,
    )
    parameters = tuple(parameters)
    values = parameter_values(uvms, parameters, link) if start is None else np.array(start, float)
    first = _evaluate(uvms, parameters, link, values, setups, step_s)
    if first is None:
        raise SimulationError(f"the trials cannot be simulated at the start values {values}")
    r, jac = first
    start_values, history, lam, iteration = values.copy(), [_rms_deg(r)], 1e-3, 0
    floor = np.array([0.0 if p.nonnegative else -np.inf for p in parameters])
    cosine = _gradient_cosine(r, jac, values, floor)
    if progress is not None:
        progress(f"start: RMS {history[0]:.4f} deg, gradient cosine {cosine:.2e}")
    exact_deg = float(np.degrees(exact_rms_rad))
    reason = (
        "exact" if history[0] < exact_deg else "gradient" if cosine < gradient_tolerance else ""
    )
    while not reason:
        if iteration >= max_iterations:
            reason = "iteration cap"
            break
        if lam >= 1e10:
            reason = "no descent"
            break
        iteration += 1
        candidate, scale = _damped_step(values, r, jac, lam, floor)
        trial = _evaluate(uvms, parameters, link, candidate, setups, step_s)
        cost, new_cost = 0.5 * r @ r, np.inf if trial is None else 0.5 * trial[0] @ trial[0]
        if new_cost >= cost:
            lam *= 4.0
            if progress is not None:
                progress(f"iteration {iteration}: rejected (lambda -> {lam:.3g})")
            continue
        moved = np.max(np.abs(candidate - values) * np.sqrt(scale)) / max(np.sqrt(2 * cost), 1e-300)
        values, (r, jac), lam = candidate, trial, max(lam / 3.0, 1e-9)
        history.append(_rms_deg(r))
        cosine = _gradient_cosine(r, jac, values, floor)
        if progress is not None:
            shown = ", ".join(f"{p.name} {x:.5g}" for p, x in zip(parameters, values, strict=True))
            progress(
                f"iteration {iteration}: RMS {history[-1]:.4f} deg, gradient cosine "
                f"{cosine:.2e} ({shown})"
            )
        if history[-1] < exact_deg:
            reason = "exact"
        elif cosine < gradient_tolerance:
            reason = "gradient"
        elif cost - new_cost < cost_tolerance * cost:
            reason = "cost"
        elif moved < step_tolerance:
            reason = "step"
    if progress is not None:
        progress(f"stopped after {iteration} iterations: {reason}")
    fitted = SensitiveModel(uvms, parameters, link, values).uvms
    return FitResult(
        parameters, link, start_values, values, history, iteration, fitted, reason, cosine
    )
