"""The closed loop: measure -> command -> actuate -> advance -> log, with observers.

One engine for every front end: `uvms_pin.sim.run.simulate` (scenarios, comparisons,
studies), the Gymnasium environments (a policy gives tau, one control period per step), the
live view and the progress bar (observers). Time advances in one of two ways:

- sampled (``control_period_s`` set): the controller runs at a fixed rate on a measurement
  of the state at the tick and its output is held (zero-order hold) through the actuation
  until the next tick, the plant advanced over the period (one compiled call);
- continuous (``control_period_s = None``): the controller is evaluated inside the
  right-hand side, as in the paper's continuous-time analysis.

The state the loop holds is read-only: the measurement a controller receives can never
change the simulation.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from typing import Any

import numpy as np

from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement, read_only
from uvms_pin.errors import (
    ActuationWarning,
    ControllerError,
    FunnelViolation,
    SimulationError,
)
from uvms_pin.results.rollout import Rollout
from uvms_pin.results.status import ERROR, INTERRUPTED, OK, RunStatus, Violation
from uvms_pin.sim.compiled_loop import CompiledLoop, LoopPath
from uvms_pin.sim.divergence import (
    NUMERICAL_FAILURES,
    diverged,
    divergence_context,
    stop_if_implausible,
)
from uvms_pin.sim.integrators import Adaptive
from uvms_pin.sim.log import RolloutLog, described_columns, run_metadata
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.run_start import checked_run_start
from uvms_pin.sim.sample import Observer, Sample
from uvms_pin.sim.sensors import SensorSuite
from uvms_pin.sim.settings import SimulationSettings
from uvms_pin.sim.system import System, SystemState

# The funnel event fires when the margin min(1 - |xi|) reaches -this: just outside, so
# that the controller, evaluated at the located event state, reports the violation.
_EVENT_OVERSHOOT = 1e-6
_NO_SIGNALS: dict[str, np.ndarray] = {}


class ClosedLoop:
    """A plant, its sensors and (optionally) a controller, stepped and observed.

    Args:
        plant: the robot in its world (the system of bodies, `system`, is built from it).
        settings: periods, integrator, duration.
        controller: the law run by `run`; None when the caller gives tau (`step`).
        observers: called with every logged sample (`Observer`).

    State: ``time_s`` [s]; ``state``, the system's (`SystemState`: every body); ``q``
    (nq,), ``v`` (nv,), the robot's part of it; read-only arrays.
    """

    @property
    def state(self) -> SystemState:
        return self._state

    @state.setter
    def state(self, state: SystemState) -> None:
        self._state = state
        self._robot = self.system.robot_state(state.q, state.v)

    @property
    def q(self) -> np.ndarray:
        """The robot's configuration (nq,), a read-only view of the state."""
        return self._robot[0]

    @property
    def v(self) -> np.ndarray:
        """The robot's generalized velocity (nv,), a read-only view of the state."""
        return self._robot[1]

    def __init__(
        self,
        plant: Plant,
        settings: SimulationSettings,
        controller: Controller | None = None,
        observers: Sequence[Observer] = (),
        *,
        compiled: bool = True,
    ):
        # the sampled loop may run in the core (`compiled_loop`), and the period of a system
        # with free objects (`uvms_pin.sim.system.period`)
        self.compiled = compiled
        self.plant = plant
        self.system = System(plant, compiled=compiled)
        self.settings = settings
        self.controller = controller
        self.observers = list(observers)
        self.time_s = 0.0
        layout = self.system.layout
        self.state = SystemState(read_only(np.zeros(layout.nq)), read_only(np.zeros(layout.nv)))
        self.sensors: SensorSuite | None = None
        self._last_tau_applied: np.ndarray | None = None  # continuous loop: the last stage's
        self.stiff_modes: dict[str, Any] = {}  # the explicit stiff modes checked at `start`

    # ---- the steps of the loop ------------------------------------------------------------
    def start(self, q0: np.ndarray, v0: np.ndarray, sensors: SensorSuite) -> None:
        """t = 0 at (q0, v0) (the quaternion normalised), measured by ``sensors`` (seeded
        noise), the environment anchored at the end-effector, the controller reset.

        Raises what `uvms_pin.sim.run_start.checked_run_start` raises (a bad state, an
        overlap, a continuous controller for a system stepped period by period, a stiff mode;
        the checked modes' record is ``stiff_modes``).
        """
        state, self.stiff_modes = checked_run_start(self.system, q0, v0, self.settings)
        self.time_s, self.state = 0.0, SystemState(read_only(state.q), read_only(state.v))
        self.sensors = sensors
        self.plant.actuation.start(self.settings.control_period_s)
        sensors.start_navigation(self.settings.control_period_s)
        sensors.start_seeing(self.plant, self.system.layout, self.settings.control_period_s)
        if self.controller is not None:
            with self._controller_code("reset"):
                self.controller.reset()
        self.system.start(self.state)

    def measure(self, held_wrench: np.ndarray | None = None) -> tuple[Measurement, np.ndarray]:
        """(what the sensors give now, the true contact wrench (6,) [N; N m] world axes), plus
        ``held_wrench`` (on held objects: `SensorConfig.held_object_wrench`).

        Raises SimulationError when a body reached the free surface and the plant stops
        there (``stop_at_surface``)."""
        q, v = self._robot
        self.plant.check_submerged(self.time_s, q)
        contact = self.plant.contact_wrench(q, v)
        contact = contact if held_wrench is None else contact + held_wrench
        return self.sensors.measure(self.time_s, q, v, contact), contact

    def observe(self, held_wrench: np.ndarray | None = None) -> tuple[Measurement, np.ndarray]:
        """`measure`, then, once per control tick, the navigation sensors and the estimator
        (`SensorSuite.navigate`) and the cameras in the loop (`SensorSuite.see`): (what the
        controller is given, the true contact wrench)."""
        measurement, contact = self.measure(held_wrench)
        q, v = self._robot
        measured = self.sensors.navigate(self.time_s, q, v, measurement)
        return self.sensors.see(self.time_s, self.state, measured), contact

    def command(self, measurement: Measurement) -> np.ndarray:
        """The controller's tau (nv,) for ``measurement`` (SimulationError if it is not nv
        finite numbers)."""
        t = measurement.time_s
        try:  # inline, not the context manager: this is the hot path
            tau = np.asarray(self.controller.compute(t, measurement), dtype=float)
        except SimulationError:  # a funnel violation is the law's own verdict
            raise
        except Exception as exc:
            raise _controller_failed(self.controller, "compute", t, exc) from exc
        if tau.shape != (self.plant.uvms.nv,) or not (
            math.isfinite(float(tau.sum())) or np.all(np.isfinite(tau))  # exact if in doubt
        ):
            raise SimulationError(f"controller returned an invalid tau at t = {t:.6g} s: {tau}")
        return tau

    def actuate(self, tau_commanded: np.ndarray) -> np.ndarray:
        """What the thrusters and joints apply of ``tau_commanded`` (nv,)."""
        return self.plant.actuation.apply(tau_commanded)

    def step(self, tau_applied: np.ndarray) -> None:
        """Advance one control period with ``tau_applied`` held.

        Raises SimulationError when the state diverges or a compiled solve fails."""
        t0, period = self.time_s, self.settings.control_period_s
        t1 = t0 + period
        try:
            q, v = self.system.advance(
                self.settings.integrator, t0, self.state.q, self.state.v, tau_applied, t1
            )
        except (SimulationError, *NUMERICAL_FAILURES) as exc:
            raise _diverged(t0, t1, exc, self._context((t0, t1), tau_applied)) from exc
        if diverged(q, v):
            raise _diverged(t0, t1, None, self._context((t0, t1), tau_applied))
        q.setflags(write=False)  # new arrays of the plant's: frozen, not copied
        v.setflags(write=False)
        self.state = SystemState(q, v)
        # the tick's time, tick * period: no accumulated rounding
        self.time_s = round(t1 / period) * period

    def sample(
        self,
        measurement: Measurement,
        contact: np.ndarray,
        tau_commanded: np.ndarray,
        tau_applied: np.ndarray,
    ) -> Sample:
        """The loop now, as its observers see it."""
        controller = self.controller
        signals = self.plant.actuation.signals()
        signals.update(self.sensors.navigation_signals())
        if controller is not None:
            with self._controller_code("signals"):
                signals = {**controller.signals(), **signals}
        signals.update(self.system.log.signals(self.state.q, self.state.v))
        return Sample(
            self.time_s,
            self.q,
            self.v,
            measurement,
            contact,
            self.plant.disturbance_wrench(self.time_s),
            tau_commanded,
            tau_applied,
            signals or _NO_SIGNALS,
        )

    def _context(self, span_s: tuple[float, float], tau_applied: np.ndarray | None) -> str:
        """What stood out over ``span_s`` from the current state (`divergence_context`)."""
        return divergence_context(self.plant, span_s, self.q, self.v, tau_applied)

    @contextmanager
    def _controller_code(self, method: str) -> Iterator[None]:
        """The controller's ``method`` runs in the block: what it raises (a funnel violation
        aside) stops the run as a `ControllerError` naming the method and the time."""
        try:
            yield
        except SimulationError:
            raise
        except Exception as exc:
            raise _controller_failed(self.controller, method, self.time_s, exc) from exc

    def notify(self, sample: Sample) -> None:
        for observer in self.observers:
            observer.on_sample(sample)

    # ---- a whole run ------------------------------------------------------------------------
    def run(self, q0: np.ndarray, v0: np.ndarray, sensors: SensorSuite, log: RolloutLog) -> Rollout:
        """Run the controller from (q0, v0) for ``settings.duration_s``, every logged sample
        to ``log`` and the observers; the rollout, with status ``ok``.

        Raises:
            FunnelViolation, SimulationError: the run stopped early; the exception's
                ``rollout`` attribute holds the rollout up to the last logged sample, its
                status saying when and why.
            KeyboardInterrupt: likewise, with status ``interrupted``.
        """
        self.observers.insert(0, log)
        wall_start = time.perf_counter()
        span = [0.0, 0.0]  # the interval being integrated, for a divergence message
        path = LoopPath()
        log.rollout.metadata["closed_loop"] = path.record()
        try:
            self.start(q0, v0, sensors)
            # as simulated: anchored, and how its period is stepped
            log.rollout.metadata["world"] = self.system.log.record(self.settings.integrator)
            log.rollout.metadata["stiff_modes"] = self.stiff_modes
            # the pipeline, chosen once: why the loop is not compiled (continuous-time
            # control among the reasons), or the compiled loop
            compiled, path.reason = CompiledLoop.build(self, log)
            if self.settings.control_period_s is None:
                self._run_continuous(span)
            else:
                self._run_sampled(span, log, path, compiled)
        except NUMERICAL_FAILURES as exc:
            error = _diverged(*span, exc, self._context(tuple(span), self._last_tau_applied))
            raise _stopped(log, wall_start, error) from exc
        except SimulationError as exc:  # FunnelViolation included
            raise _stopped(log, wall_start, exc) from exc.__cause__  # e.g. the controller's
        except KeyboardInterrupt as exc:  # Ctrl-C: the caller may keep what was simulated
            exc.rollout = _finished(
                log, wall_start, RunStatus(INTERRUPTED, str(exc) or "interrupted by the user")
            )
            raise
        finally:
            log.rollout.metadata["closed_loop"] = path.record()
            log.rollout.metadata.update(self.system.log.solves_record())
            self.observers.remove(log)
            dropped = self.plant.actuation.dropped()
            if dropped is not None:
                warnings.warn(dropped, ActuationWarning, stacklevel=2)
        rollout = _finished(log, wall_start, RunStatus(OK))
        stop_if_implausible(self.plant.uvms, rollout, v0)  # finite, but is it physics?
        return rollout

    def _tick(self, logged: bool) -> np.ndarray:
        """Measure, command and actuate at the current state; log if ``logged``."""
        measurement, contact = self.observe()
        tau = self.command(measurement)
        tau_applied = self.actuate(tau)
        if logged:
            self.notify(self.sample(measurement, contact, tau, tau_applied))
        return tau_applied

    def _run_sampled(
        self, span: list[float], log: RolloutLog, path: LoopPath, compiled: CompiledLoop | None
    ) -> None:
        """Every tick, in chunks of ``compiled`` ticks when the whole loop has a compiled
        counterpart (`CompiledLoop`); a tick the core hands back, and every tick otherwise,
        in Python."""
        settings = self.settings
        ticks_per_log = settings.ticks_per_log
        n_ticks = (settings.n_log - 1) * ticks_per_log
        tick = 0
        while tick <= n_ticks:
            if compiled is not None:
                reached, stopped = compiled.run(tick)
                path.compiled_ticks += reached - tick
                tick = reached
                if not stopped:
                    continue
                if tick > n_ticks:
                    return
            path.python_ticks += 1
            tau_applied = self._tick(tick % ticks_per_log == 0)
            if tick == n_ticks:
                return
            span[:] = self.time_s, self.time_s + settings.control_period_s
            self.step(tau_applied)
            tick += 1

    def _run_continuous(self, span: list[float]) -> None:
        """One integrator pass per re-basing segment, states at the log times; the
        controller is evaluated inside the right-hand side. With an adaptive integrator the
        controller's barrier is extended beyond its funnels for trial stages, and the funnel
        margin is an event on accepted steps."""
        settings, system, controller = self.settings, self.system, self.controller
        plant = system.plant
        adaptive = isinstance(settings.integrator, Adaptive)
        log_times = np.arange(settings.n_log) * settings.log_period_s

        sensors, actuation, command = self.sensors, plant.actuation, self.command

        def at(t: float, q: np.ndarray, v: np.ndarray) -> tuple[Measurement, np.ndarray]:
            # q is the chart's, new at every stage; v is a view of the solver's state: a copy
            q.setflags(write=False)
            v = v.copy()
            v.setflags(write=False)
            contact = plant.contact_wrench(q, v)
            return sensors.measure(t, q, v, contact), contact

        def rhs(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
            # a stage of a blown-up step: a divergence, not a bad argument to the dynamics
            if not (math.isfinite(q.sum()) and math.isfinite(v.sum())):
                context = divergence_context(plant, (t, t), self.q, self.v, self._last_tau_applied)
                raise SimulationError(
                    f"simulation diverged: a non-finite state at t = {t:.6g} s; {context}"
                )
            measurement, contact = at(t, q, v)
            tau_applied = actuation.apply(command(measurement))
            self._last_tau_applied = tau_applied  # for a divergence message
            acceleration = system.acceleration(t, q, v, tau_applied, contact_world=contact)
            # an adaptive solver would shrink its step on a non-finite stage until it gives
            # up with a message that does not say why: stop at once instead (a sum is NaN or
            # inf if any entry is; the exact test only when it is)
            if not math.isfinite(acceleration.sum()) and not np.all(np.isfinite(acceleration)):
                context = divergence_context(plant, (t, t), q, v, tau_applied)
                raise SimulationError(
                    f"simulation diverged: non-finite acceleration at t = {t:.6g} s; {context}"
                )
            return acceleration

        def margin_event(t: float, q: np.ndarray, v: np.ndarray) -> float:
            command(at(t, q, v)[0])
            with self._controller_code("funnel_margin"):
                return controller.funnel_margin() + _EVENT_OVERSHOOT

        self._tick(True)
        logged = 1
        per_segment = max(1, round(settings.rebase_period_s / settings.log_period_s))
        while logged < settings.n_log:
            t0 = log_times[logged - 1]
            times = log_times[logged : logged + per_segment]
            span[:] = t0, times[-1]
            states, failure = self._integrate(rhs, t0, times, margin_event if adaptive else None)
            for t, q, v in states:
                if diverged(q, v):
                    raise _diverged(t0, t, None, self._context((t0, t), self._last_tau_applied))
                self.time_s, self.state = float(t), SystemState(read_only(q), read_only(v))
                system.settle(q, v)  # the friction's anchors move at the log times
                on_log = abs(t - log_times[logged]) < 1e-9
                # an event stop is not a log time: the controller raises the violation there
                self._tick(on_log)
                if not on_log:
                    raise SimulationError(
                        f"funnel event at t = {t:.6g} s but the controller found no violation"
                    )
                logged += 1
            if failure is not None:
                raise failure

    def _integrate(self, rhs, t0: float, times: np.ndarray, event):
        """(states reached, the failure that stopped the pass or None)."""
        controller = self.controller
        with self._controller_code("set_funnel_extension"):
            controller.set_funnel_extension(event is not None)
        try:
            compiled = self.plant.compiled
            states = self.settings.integrator.advance_through(
                self.system.model, rhs, t0, self.state.q, self.state.v, times, event,
                chart=None if compiled is None else compiled.chart,
            )  # fmt: skip
        except SimulationError as exc:  # log the states reached before the failure
            return getattr(exc, "states", []), exc
        finally:
            controller.set_funnel_extension(False)
        return states, None


def _controller_failed(
    controller: Controller, method: str, time_s: float, exc: Exception
) -> ControllerError:
    """The `ControllerError` of ``exc``, raised by ``controller.method`` at ``time_s``; with
    the frames of the user's code when the controller is not one of uvms-pin's."""
    users = not type(controller).__module__.startswith("uvms_pin.")
    return ControllerError(method, time_s, exc, users=users)


def _diverged(t0: float, t1: float, exc: BaseException | None, context: str) -> SimulationError:
    """The divergence between t0 and t1 (``exc``: what the solve raised, None if the state
    came back non-finite or absurd), with ``context``: what stood out at t0."""
    cause = "" if exc is None else f" ({type(exc).__name__}: {exc})"
    return SimulationError(
        f"simulation diverged between t = {t0:.6g} s and {t1:.6g} s{cause}; {context}"
    )


def _finished(log: RolloutLog, wall_start: float, status: RunStatus) -> Rollout:
    """The log's rollout with how the run ended and what it cost."""
    rollout = log.finish()
    wall = time.perf_counter() - wall_start
    simulated = float(rollout.time_s[-1]) if len(rollout) else 0.0
    if not status.ok and status.time_s is None:
        status = RunStatus(status.kind, status.reason, simulated, status.violation)
    rollout.set_status(status)
    rollout.metadata.update(
        wall_time_s=wall,
        simulated_time_s=simulated,
        real_time_factor=simulated / wall if wall > 0 else math.inf,
    )
    return rollout


def _stopped(log: RolloutLog, wall_start: float, exc: SimulationError) -> SimulationError:
    """``exc`` with the rollout up to the stop attached (``exc.rollout``)."""
    violation = None
    if isinstance(exc, FunnelViolation):
        violation = Violation(exc.level, exc.component, exc.time_s, exc.error, exc.bound)
    time_s = violation.time_s if violation is not None else None
    kind = type(exc).__name__
    if isinstance(exc, ControllerError):
        kind, time_s = ERROR, exc.time_s
    if exc.user_traceback:
        log.rollout.metadata["error_traceback"] = exc.user_traceback
    exc.rollout = _finished(log, wall_start, RunStatus(kind, str(exc), time_s, violation))
    return exc


def simulate_closed_loop(
    plant: Plant,
    controller: Controller,
    sensors: SensorSuite,
    q0: np.ndarray,
    v0: np.ndarray,
    settings: SimulationSettings,
    *,
    metadata: dict[str, Any] | None = None,
    observers: Sequence[Observer] = (),
    compiled: bool = True,
) -> Rollout:
    """Run ``controller`` on ``plant`` from (q0, v0) for ``settings.duration_s``.

    Returns the rollout (status ``ok``); the run's settings, versions and model are added to
    ``metadata``. ``compiled``: a sampled loop whose every part the core knows runs in the
    core (`uvms_pin.sim.compiled_loop`; False: in Python, tick by tick, and a system with
    free objects integrated in Python); the metadata's ``closed_loop`` says which path ran
    (and ``world.integration`` how free objects were stepped). Raises as `ClosedLoop.run`.
    """
    from uvms_pin.sim.settings import check_log_fits

    loop = ClosedLoop(plant, settings, controller, observers, compiled=compiled)
    check_log_fits(settings, plant.uvms.nq, plant.uvms.nv, loop.system.log.n_columns)
    meta = {**(metadata or {}), **run_metadata(plant, settings)}
    if sensors.navigation is not None:
        meta["signal_units"].update(described_columns(sensors.navigation.signal_columns()))
    log = RolloutLog(plant.uvms, settings.n_log, meta, backend=plant.backend, system=loop.system)
    return loop.run(q0, v0, sensors, log)
