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
from dataclasses import dataclass
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
# The funnel event fires when the margin min(1 - |xi|) reaches -this: just outside, so
# that the controller, evaluated at the located event state, reports the violation.
_EVENT_OVERSHOOT = 1e-6


@dataclass(frozen=True)
class SimulationSettings:
    """How to integrate and log.

    Attributes:
        duration_s: simulated time T [s].
        integrator: a fixed-step or adaptive `Integrator`.
        log_period_s: logging interval [s]; a multiple of the control period if sampled.
        control_period_s: controller period [s] (zero-order hold) or None = continuous.
        seed: master seed of every random draw in the run (recorded in the rollout).
        rebase_period_s: continuous mode only: length of one adaptive-integrator pass
            (the local chart of the free-flyer is re-based at its start).
    """

    duration_s: float
    integrator: Integrator
    log_period_s: float = 0.01
    control_period_s: float | None = None
    seed: int = 0
    rebase_period_s: float = 0.5

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
        arm_joint_names=uvms.arm_joint_names,
        arm_position_lower_rad=model.lowerPositionLimit[7:].tolist(),
        arm_position_upper_rad=model.upperPositionLimit[7:].tolist(),
    )
    rollout = Rollout.allocate(settings.n_log, model.nq, model.nv, meta)
    controller.reset()
    plant.attach(q0)

    def measure(t: float, q: np.ndarray, v: np.ndarray) -> tuple[Any, np.ndarray]:
        contact = plant.contact_wrench(q, v)
        return sensors.measure(t, q, v, contact), contact

    def command(t: float, measurement) -> tuple[np.ndarray, np.ndarray]:
        tau = np.asarray(controller.compute(t, measurement), dtype=float)
        if tau.shape != (model.nv,) or not np.all(np.isfinite(tau)):
            raise SimulationError(f"controller returned an invalid tau at t = {t:.6g} s: {tau}")
        return tau, plant.actuation.apply(tau)

    def continuous_rhs(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        measurement, contact = measure(t, q, v)
        _, tau_applied = command(t, measurement)
        return plant.acceleration(t, q, v, tau_applied, contact)

    def log(k: int, t: float, q, v, tau, tau_applied, contact, measured) -> None:
        rollout.time_s[k] = t
        rollout.q[k] = q
        rollout.v[k] = v
        rollout.tau[k] = tau_applied
        rollout.signal("tau_commanded", model.nv)[k] = tau
        rollout.wrench_contact_world[k] = contact
        rollout.wrench_measured_world[k] = measured
        rollout.wrench_disturbance_body[k] = plant.disturbance_wrench(t)
        rollout.kinetic_energy_J[k] = kinetic_energy(uvms, q, v, backend=plant.backend)
        rollout.potential_energy_J[k] = potential_energy(uvms, q)
        for name, values in controller.signals().items():
            rollout.signal(name, values.size)[k] = values

    def check_finite(t0: float, t1: float, q: np.ndarray, v: np.ndarray) -> None:
        if (
            not (np.all(np.isfinite(q)) and np.all(np.isfinite(v)))
            or np.max(np.abs(v)) > _DIVERGED_SPEED
        ):
            raise SimulationError(f"simulation diverged between t = {t0:.6g} s and {t1:.6g} s")

    def sample(k: int, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Measure and command at an accepted state; log it if k is a log index."""
        measurement, contact = measure(t, q, v)
        tau, tau_applied = command(t, measurement)
        if k >= 0:
            log(k, t, q, v, tau, tau_applied, contact, measurement.wrench_world)
            if progress is not None:
                progress(t, settings.duration_s)
        return tau_applied

    wall_start = time.perf_counter()
    log_times = np.arange(settings.n_log) * settings.log_period_s
    logged = 0
    try:
        q, v = q0, v0
        if settings.control_period_s is None:
            # continuous control: one integrator pass per re-basing segment, states at the
            # log times; the controller is evaluated inside the right-hand side. With an
            # adaptive integrator the controller's barrier is extended beyond its funnels
            # for trial stages, and the funnel margin is an event on accepted steps.
            adaptive = isinstance(settings.integrator, Adaptive)

            def margin_event(t: float, q: np.ndarray, v: np.ndarray) -> float:
                measurement, _ = measure(t, q, v)
                controller.compute(t, measurement)
                return controller.funnel_margin() + _EVENT_OVERSHOOT

            sample(0, 0.0, q, v)
            logged = 1
            per_segment = max(1, round(settings.rebase_period_s / settings.log_period_s))
            while logged < settings.n_log:
                t0 = log_times[logged - 1]
                times = log_times[logged : logged + per_segment]
                controller.set_funnel_extension(adaptive)
                try:
                    states = settings.integrator.advance_through(
                        model, continuous_rhs, t0, q, v, times, margin_event if adaptive else None
                    )
                finally:
                    controller.set_funnel_extension(False)
                for t, q, v in states:
                    check_finite(t0, t, q, v)
                    on_log = logged < settings.n_log and abs(t - log_times[logged]) < 1e-9
                    # an event stop is not a log time: sampling there raises the violation
                    sample(logged if on_log else -1, t, q, v)
                    if not on_log:
                        raise SimulationError(
                            f"funnel event at t = {t:.6g} s but the controller found no violation"
                        )
                    logged += 1
        else:
            ticks_per_log = settings.ticks_per_log
            tick_s = settings.control_period_s
            n_ticks = (settings.n_log - 1) * ticks_per_log
            for tick in range(n_ticks + 1):
                t = tick * tick_s
                on_log = tick % ticks_per_log == 0
                tau_applied = sample(logged if on_log else -1, t, q, v)
                logged += on_log
                if tick == n_ticks:
                    break
                q, v = plant.advance(settings.integrator, t, q, v, tau_applied, t + tick_s)
                check_finite(t, t + tick_s, q, v)
    except (FunnelViolation, SimulationError) as exc:
        rollout.truncate(logged)
        _finish(rollout, wall_start, settings, type(exc).__name__, str(exc))
        exc.rollout = rollout
        raise
    _finish(rollout, wall_start, settings, "ok", "")
    return rollout


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
