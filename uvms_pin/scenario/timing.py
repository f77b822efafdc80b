"""``[integrator]``, ``[control]`` and ``[output]``: how the run is integrated (and on which
backend), how often the controller runs, how often the state is logged."""

from __future__ import annotations

import math
from collections.abc import Callable

from uvms_pin.checks import Plausible
from uvms_pin.physics.compiled.backend import BACKENDS
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.integrators import RK4, Adaptive, FixedStep, Integrator, SemiImplicitEuler


def _seconds(usual: tuple[float, float], usual_text: str, hints=("", "")) -> Plausible:
    """A duration [s]: any positive one is possible, ``usual`` the range runs use."""
    return Plausible("s", usual, (0.0, math.inf), usual_text, "", hints)


#: A fixed integrator step [s]: a UVMS's fastest dynamics (a stiff contact, the joint
#: drives) want ~1e-4 s, its slowest are seconds; below 1e-5 s a run takes 1e5 steps per
#: simulated second, above 0.05 s RK4 steps over the joints' dynamics
STEP = _seconds(
    (1e-5, 0.05), "the steps a UVMS run needs", ("every simulated second takes 1/step steps", "")
)
#: A controller's period [s]: real controllers run at 10 Hz to 10 kHz
CONTROL_PERIOD = _seconds((1e-4, 0.1), "controller rates of 10 Hz to 10 kHz")


def _fixed_step(kind: type[Integrator]) -> Callable[[Table], Integrator]:
    return lambda t: kind(t.plausible("step_s", t.number("step_s", 1e-3, positive=True), STEP))


def _adaptive(method: str) -> Callable[[Table], Integrator]:
    return lambda t: Adaptive(
        method,
        rtol=t.number("rtol", 1e-6, positive=True),
        atol=t.number("atol", 1e-8, positive=True),
        max_step_s=t.number("max_step_s", math.inf, positive=True),
    )


#: [integrator] method -> how the integrator is built from the table
INTEGRATORS: dict[str, Callable[[Table], Integrator]] = {
    "rk4": _fixed_step(RK4),
    "semi_implicit_euler": _fixed_step(SemiImplicitEuler),
    **{method: _adaptive(method) for method in Adaptive._METHODS},
}


def build_integrator(t: Table) -> tuple[Integrator, str]:
    """The integrator and the plant's backend ("core": compiled, "python": the reference)."""
    backend = t.string("backend", "core", BACKENDS)
    method = t.string("method", "rk4", tuple(INTEGRATORS))
    out = INTEGRATORS[method](t)
    t.finish()
    return out, backend


def build_control_period(t: Table) -> float | None:
    """[control] period_s: the controller's period [s]; None = continuous control."""
    period = t.optional_number("period_s", positive=True)
    if period is not None:
        t.plausible("period_s", period, CONTROL_PERIOD)
    t.finish()
    return period


def passive_period(
    period_s: float | None, integrator: Integrator, log_period_s: float, passive: bool
) -> float | None:
    """The control period of a run: ``period_s`` as given; without one, a run with no
    controller (``passive``) and a fixed-step integrator whose step divides the log period is
    sampled at that step: nothing is controlled, and the constraints solved once a period
    (the joint limits) are solved at every step. Otherwise None: continuous control (an
    adaptive integrator keeps its own steps; a step that does not divide the log period is
    refused by `SimulationSettings`, naming the step)."""
    if period_s is not None or not passive or not isinstance(integrator, FixedStep):
        return period_s
    ratio = log_period_s / integrator.step_s
    if ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-6 * ratio:
        return None
    return float(integrator.step_s)


def build_log_period(t: Table) -> float:
    """[output] log_period_s [s] (default 0.01)."""
    period = t.number("log_period_s", 0.01, positive=True)
    t.finish()
    return period
