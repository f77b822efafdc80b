"""The closed loop: plant + sensors + controller, integrated in time, logged into a Rollout.

Two control modes:
- sampled (``control_period_s`` set): the controller runs at a fixed rate on a measurement
  of the state at the tick and its output is held (zero-order hold) until the next tick;
- continuous (``control_period_s = None``): the controller is evaluated inside the
  right-hand side, as in the paper's continuous-time analysis.
"""

from __future__ import annotations

import functools
import math
import os
import platform
import time
from dataclasses import dataclass
from importlib import metadata as importlib_metadata
from typing import Any

import numpy as np

from uvms_pin.control.base import Controller
from uvms_pin.errors import FunnelViolation, ParameterError, SimulationError
from uvms_pin.physics.dynamics import kinetic_energy, potential_energy
from uvms_pin.results.progress import Progress
from uvms_pin.results.rollout import Rollout
from uvms_pin.sim.integrators import Adaptive, Integrator
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sensors import SensorSuite

# A speed this large [m/s or rad/s] only comes out of a blown-up integration.
DIVERGED_SPEED = 1e4


# What numerical code raises on a blown-up state (a singular chart Jacobian or mass
# matrix, an overflow): reported as a SimulationError with the partial rollout kept.
class CompiledCoreFailure(ArithmeticError):
    """A numerical failure reported by the compiled core (e.g. M not positive definite)."""


NUMERICAL_FAILURES = (
    np.linalg.LinAlgError,
    FloatingPointError,
    OverflowError,
    ZeroDivisionError,
    CompiledCoreFailure,
)
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
        # Nothing is silently rounded or capped: the run is exactly the one recorded.
        _require_multiple(
            self.duration_s,
            self.log_period_s,
            "duration_s (scenario.duration_s)",
            "log_period_s (output.log_period_s)",
        )
        if self.control_period_s is not None:
            if not (self.control_period_s > 0.0 and math.isfinite(self.control_period_s)):
                raise ParameterError(
                    f"control_period_s must be positive, got {self.control_period_s}"
                )
            _require_multiple(
                self.log_period_s,
                self.control_period_s,
                "log_period_s (output.log_period_s)",
                "control_period_s (control.period_s)",
            )
        step_s = getattr(self.integrator, "step_s", None)
        if step_s is not None:
            # a fixed-step integrator takes equal substeps of each control (or output)
            # interval: a step that does not divide it would be shortened without a trace
            interval, name = (
                (self.control_period_s, "control_period_s (control.period_s)")
                if self.control_period_s is not None
                else (self.log_period_s, "log_period_s (output.log_period_s)")
            )
            _require_multiple(interval, step_s, name, "step_s (integrator.step_s)")

    def log_bytes(self, nq: int, nv: int) -> int:
        """Memory the rollout of this run takes [bytes] (float64 arrays, every sample)."""
        return self.n_log * 8 * _log_width(nq, nv)

    @property
    def n_log(self) -> int:
        return round(self.duration_s / self.log_period_s) + 1

    @property
    def ticks_per_log(self) -> int:
        if self.control_period_s is None:
            return 1
        return round(self.log_period_s / self.control_period_s)


def diverged(q: np.ndarray, v: np.ndarray) -> bool:
    """True for a state only a blown-up integration gives: non-finite, or a speed above
    `DIVERGED_SPEED`."""
    # one reduction each (a sum is NaN or inf if any entry is, the extremes bound |v|); the
    # exact test only when they do not settle it (e.g. a sum beyond 1e308)
    low, high = float(v.min()), float(v.max())
    if math.isfinite(float(q.sum())) and -DIVERGED_SPEED <= low and high <= DIVERGED_SPEED:
        return False
    return not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))) or bool(
        np.max(np.abs(v)) > DIVERGED_SPEED
    )


def _require_multiple(whole: float, part: float, whole_name: str, part_name: str) -> None:
    """ParameterError unless whole = n part for an integer n >= 1 (relative slack 1e-6)."""
    ratio = whole / part
    if ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-6 * max(1.0, ratio):
        raise ParameterError(
            f"{whole_name} = {whole:g} s must be an integer multiple (>= 1) of "
            f"{part_name} = {part:g} s: the run would not be the one recorded"
        )


def _log_width(nq: int, nv: int) -> int:
    """Float64 values logged per sample: the base arrays (`Rollout.allocate`) and the
    controller's signals, bounded by 10 (6 + nv) (the PPC logs 3 x 3 + 5 x 6 + 7 nv: its
    references, errors, funnels and commanded tau)."""
    base = 1 + nq + 2 * nv + 3 * 6 + 2
    return base + 10 * (6 + nv)


def available_memory_bytes() -> int | None:
    """Memory the system can give this process now [bytes], or None if unknown."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def check_log_fits(settings: SimulationSettings, nq: int, nv: int) -> None:
    """ParameterError, before anything is allocated, if the rollout would take more than half
    of the available memory (the other half: figures, the saved copy, the rest of the run)."""
    needed = settings.log_bytes(nq, nv)
    available = available_memory_bytes()
    if available is not None and needed > available // 2:
        raise ParameterError(
            f"the log of this run would take {needed / 2**30:.3g} GiB "
            f"({settings.n_log} samples: duration_s {settings.duration_s:g} s / log_period_s "
            f"{settings.log_period_s:g} s), more than half of the {available / 2**30:.3g} GiB "
            "available: shorten scenario.duration_s or lengthen output.log_period_s"
        )


def package_versions() -> dict[str, str]:
    """Versions of the packages a result depends on (recorded in every rollout)."""
    return dict(_package_versions())


@functools.cache
def _package_versions() -> dict[str, str]:
    # read once per process: the installed metadata does not change under a running study,
    # and parsing it costs ~10 ms, a tenth of a short study run
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
        KeyboardInterrupt: likewise, with status ``interrupted``.
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
        arm_joint_kinds=[_joint_kind(model, name) for name in uvms.arm_joint_names],
        arm_position_lower_rad=model.lowerPositionLimit[7:].tolist(),
        arm_position_upper_rad=model.upperPositionLimit[7:].tolist(),
    )
    check_log_fits(settings, model.nq, model.nv)
    rollout = Rollout.allocate(settings.n_log, model.nq, model.nv, meta)
    controller.reset()
    plant.attach(q0)

    def measure(t: float, q: np.ndarray, v: np.ndarray) -> tuple[Any, np.ndarray]:
        contact = plant.contact_wrench(q, v)
        return sensors.measure(t, q, v, contact), contact

    def command(t: float, measurement) -> tuple[np.ndarray, np.ndarray]:
        tau = np.asarray(controller.compute(t, measurement), dtype=float)
        if tau.shape != (model.nv,) or not (
            math.isfinite(float(tau.sum())) or np.all(np.isfinite(tau))  # exact if in doubt
        ):
            raise SimulationError(f"controller returned an invalid tau at t = {t:.6g} s: {tau}")
        return tau, plant.actuation.apply(tau)

    def continuous_rhs(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        measurement, contact = measure(t, q, v)
        _, tau_applied = command(t, measurement)
        acceleration = plant.acceleration(t, q, v, tau_applied, contact)
        # an adaptive solver would shrink its step on a non-finite stage until it gives up
        # with a message that does not say why: stop at once instead
        if not np.all(np.isfinite(acceleration)):
            raise SimulationError(f"simulation diverged: non-finite acceleration at t = {t:.6g} s")
        return acceleration

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
        if diverged(q, v):
            raise SimulationError(f"simulation diverged between t = {t0:.6g} s and {t1:.6g} s")

    def sample(k: int, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Measure and command at an accepted state; log it if k is a log index."""
        plant.check_submerged(t, q)
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
    span = [0.0, 0.0]  # the interval being integrated, for a divergence message
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
                span[:] = t0, times[-1]
                failure = None
                try:
                    states = settings.integrator.advance_through(
                        model,
                        continuous_rhs,
                        t0,
                        q,
                        v,
                        times,
                        margin_event if adaptive else None,
                        chart=plant.chart(),
                    )
                except SimulationError as exc:  # log the states reached before the failure
                    states, failure = getattr(exc, "states", []), exc
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
                if failure is not None:
                    raise failure
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
                span[:] = t, t + tick_s
                try:
                    q, v = plant.advance(settings.integrator, t, q, v, tau_applied, t + tick_s)
                except SimulationError as exc:  # a failed solve inside the compiled core
                    raise CompiledCoreFailure(str(exc)) from exc
                check_finite(t, t + tick_s, q, v)
    except NUMERICAL_FAILURES as exc:
        error = SimulationError(
            f"simulation diverged between t = {span[0]:.6g} s and {span[1]:.6g} s "
            f"({type(exc).__name__}: {exc})"
        )
        _stopped(rollout, logged, wall_start, settings, error)
        raise error from exc
    except SimulationError as exc:  # FunnelViolation included
        _stopped(rollout, logged, wall_start, settings, exc)
        raise
    except KeyboardInterrupt as exc:  # Ctrl-C: the caller may keep what was simulated
        rollout.truncate(logged)
        _finish(rollout, wall_start, settings, "interrupted", "interrupted by the user")
        exc.rollout = rollout
        raise
    _finish(rollout, wall_start, settings, "ok", "")
    return rollout


def _joint_kind(model, joint_name: str) -> str:
    """'prismatic' or 'revolute' (names the units of the joint's columns in a table)."""
    shortname = model.joints[model.getJointId(joint_name)].shortname()
    prismatic = ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismatic")
    return "prismatic" if shortname.startswith(prismatic) else "revolute"


def _stopped(
    rollout: Rollout,
    logged: int,
    wall_start: float,
    settings: SimulationSettings,
    exc: SimulationError,
) -> None:
    """Keep the samples logged before the stop and attach the rollout to the exception."""
    rollout.truncate(logged)
    _finish(rollout, wall_start, settings, type(exc).__name__, str(exc))
    if isinstance(exc, FunnelViolation):
        rollout.metadata["violation"] = {
            "level": exc.level,
            "component": exc.component,
            "time_s": exc.time_s,
            "error": exc.error,
            "bound": exc.bound,
        }
    exc.rollout = rollout


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
