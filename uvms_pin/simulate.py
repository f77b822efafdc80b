"""The closed loop: plant + sensors + controller, integrated in time, logged into a Rollout.

Two control modes:
- sampled (``control_period_s`` set): the controller runs at a fixed rate on a measurement
  of the state at the tick and its output is held (zero-order hold) until the next tick;
- continuous (``control_period_s = None``): the controller is evaluated inside the
  right-hand side, as in the paper's continuous-time analysis.
"""

from __future__ import annotations

import math
import platform
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from importlib import metadata as importlib_metadata
from typing import Any

import numpy as np

from uvms_pin.controllers.base import Controller
from uvms_pin.dynamics import kinetic_energy, potential_energy
from uvms_pin.errors import FunnelViolation, ParameterError, SimulationError
from uvms_pin.integrators import Adaptive, Integrator
from uvms_pin.plant import Plant
from uvms_pin.rollout import Rollout
from uvms_pin.sensors import SensorSuite

Progress = Callable[[float, float], None]

# A speed this large [m/s or rad/s] only comes out of a blown-up integration.
_DIVERGED_SPEED = 1e4
# Retries of an adaptive interval, each with a 4x smaller max step, when a trial stage
# (not an accepted state) lands outside a funnel.
_ADAPTIVE_RETRIES = 4


@dataclass(frozen=True)
class SimulationSettings:
    """How to integrate and log.

    Attributes:
        duration_s: simulated time T [s].
        integrator: a fixed-step or adaptive `Integrator`.
        log_period_s: logging interval [s]; a multiple of the control period if sampled.
        control_period_s: controller period [s] (zero-order hold) or None = continuous.
        seed: master seed of every random draw in the run (recorded in the rollout).
    """

    duration_s: float
    integrator: Integrator
    log_period_s: float = 0.01
    control_period_s: float | None = None
    seed: int = 0

    def __post_init__(self) -> None:
        if not (self.duration_s > 0.0 and math.isfinite(self.duration_s)):
            raise ParameterError(f"duration_s must be positive, got {self.duration_s}")
        if not (self.log_period_s > 0.0 and math.isfinite(self.log_period_s)):
            raise ParameterError(f"log_period_s must be positive, got {self.log_period_s}")
        if self.control_period_s is not None:
            if not (self.control_period_s > 0.0 and math.isfinite(self.control_period_s)):
                raise ParameterError(
                    f"control_period_s must be positive, got {self.control_period_s}"
                )
            ratio = self.log_period_s / self.control_period_s
            if ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-6:
                raise ParameterError(
                    f"log_period_s ({self.log_period_s}) must be an integer multiple of "
                    f"control_period_s ({self.control_period_s})"
                )

    @property
    def n_log(self) -> int:
        return round(self.duration_s / self.log_period_s) + 1

    @property
    def ticks_per_log(self) -> int:
        if self.control_period_s is None:
            return 1
        return round(self.log_period_s / self.control_period_s)


def package_versions() -> dict[str, str]:
    """Versions of the packages a result depends on (recorded in every rollout)."""
    out = {"python": platform.python_version()}
    for name in ("uvms-pin", "pin", "numpy", "scipy"):
        try:
            out[name] = importlib_metadata.version(name)
        except importlib_metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


def simulate_closed_loop(
    plant: Plant,
    controller: Controller,
    sensors: SensorSuite,
    q0: np.ndarray,
    v0: np.ndarray,
    settings: SimulationSettings,
    *,
    metadata: dict[str, Any] | None = None,
    progress: Progress | None = None,
) -> Rollout:
    """Run the closed loop from (q0, v0) for ``settings.duration_s``.

    Returns the rollout (``metadata['status'] == 'ok'``).

    Raises:
        FunnelViolation, SimulationError: the run stopped early; the exception's
            ``rollout`` attribute holds the rollout up to the last logged sample with
            ``metadata['status']`` and ``metadata['error']`` set.
    """
    uvms = plant.uvms
    model = uvms.model
    q0 = np.asarray(q0, dtype=float)
    v0 = np.asarray(v0, dtype=float)
    if q0.shape != (model.nq,) or v0.shape != (model.nv,):
        raise ParameterError(
            f"q0 must have {model.nq} and v0 {model.nv} entries, got {q0.shape}, {v0.shape}"
        )
    if not (np.all(np.isfinite(q0)) and np.all(np.isfinite(v0))):
        raise ParameterError("initial state has a non-finite value")
    q0 = q0.copy()
    q0[3:7] /= np.linalg.norm(q0[3:7])

    meta = dict(metadata or {})
    meta.update(
        seed=settings.seed,
        duration_s=settings.duration_s,
        log_period_s=settings.log_period_s,
        control_period_s=settings.control_period_s,
        integrator=type(settings.integrator).__name__,
        integrator_settings=dict(vars(settings.integrator)),
        versions=package_versions(),
        model_source=uvms.source,
    )
    rollout = Rollout.allocate(settings.n_log, model.nq, model.nv, meta)
    controller.reset()
    plant.attach(q0)

    def measure(t: float, q: np.ndarray, v: np.ndarray) -> tuple[Any, np.ndarray]:
        contact = plant.contact_wrench(q, v)
        return sensors.measure(t, q, v, contact), contact

    def held_rhs(tau: np.ndarray) -> Callable:
        return lambda t, q, v: plant.acceleration(t, q, v, tau)

    def continuous_rhs(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        measurement, contact = measure(t, q, v)
        tau = controller.compute(t, measurement)
        return plant.acceleration(t, q, v, tau, contact)

    def log(k: int, t: float, q, v, tau, contact, measured) -> None:
        rollout.time_s[k] = t
        rollout.q[k] = q
        rollout.v[k] = v
        rollout.tau[k] = tau
        rollout.wrench_contact_world[k] = contact
        rollout.wrench_measured_world[k] = measured
        rollout.wrench_disturbance_body[k] = plant.disturbance_wrench(t)
        rollout.kinetic_energy_J[k] = kinetic_energy(uvms, q, v)
        rollout.potential_energy_J[k] = potential_energy(uvms, q)
        for name, values in getattr(controller, "last_signals", {}).items():
            values = np.atleast_1d(values)
            rollout.signal(name, values.size)[k] = values

    wall_start = time.perf_counter()
    q, v = q0, v0
    logged = 0
    n_ticks = (settings.n_log - 1) * settings.ticks_per_log
    tick_s = settings.log_period_s / settings.ticks_per_log
    try:
        for tick in range(n_ticks + 1):
            t = tick * tick_s
            measurement, contact = measure(t, q, v)
            tau = np.array(controller.compute(t, measurement), dtype=float)
            if tau.shape != (model.nv,) or not np.all(np.isfinite(tau)):
                raise SimulationError(f"controller returned an invalid tau at t = {t:.6g} s: {tau}")
            if tick % settings.ticks_per_log == 0:
                log(logged, t, q, v, tau, contact, measurement.wrench_world)
                logged += 1
                if progress is not None:
                    progress(t, settings.duration_s)
            if tick == n_ticks:
                break
            rhs = continuous_rhs if settings.control_period_s is None else held_rhs(tau)
            q, v = _advance(settings.integrator, model, rhs, t, q, v, t + tick_s)
            if (
                not (np.all(np.isfinite(q)) and np.all(np.isfinite(v)))
                or np.max(np.abs(v)) > _DIVERGED_SPEED
            ):
                raise SimulationError(
                    f"simulation diverged between t = {t:.6g} s and {t + tick_s:.6g} s"
                )
    except (FunnelViolation, SimulationError) as exc:
        rollout.truncate(logged)
        _finish(rollout, wall_start, settings, type(exc).__name__, str(exc))
        exc.rollout = rollout
        raise
    _finish(rollout, wall_start, settings, "ok", "")
    return rollout


def _advance(integrator: Integrator, model, rhs, t0, q0, v0, t1):
    """One interval; adaptive trial stages outside a funnel are retried with smaller steps."""
    for attempt in range(_ADAPTIVE_RETRIES + 1):
        try:
            return integrator.advance(model, rhs, t0, q0, v0, t1)
        except FunnelViolation:
            if not isinstance(integrator, Adaptive) or attempt == _ADAPTIVE_RETRIES:
                raise
            max_step = min(integrator.max_step_s, t1 - t0) / 4.0
            integrator = replace(integrator, max_step_s=max_step)
    raise AssertionError("unreachable")


def _finish(
    rollout: Rollout, wall_start: float, settings: SimulationSettings, status: str, error: str
) -> None:
    wall = time.perf_counter() - wall_start
    simulated = float(rollout.time_s[-1]) if len(rollout) else 0.0
    rollout.metadata.update(
        status=status,
        error=error,
        wall_time_s=wall,
        simulated_time_s=simulated,
        real_time_factor=simulated / wall if wall > 0 else math.inf,
    )
