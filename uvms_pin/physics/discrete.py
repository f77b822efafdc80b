"""The discrete step of the plant and its Jacobians: what a DDP-type solver or an MPC
linearises (`uvms_pin.physics.derivatives.step` for the math).

`step_derivatives` takes one control period of fixed substeps of the plant's integrator
(semi-implicit Euler, or RK4 in the local chart: `uvms_pin.sim.integrators`) with the
generalized force held, and returns the end state with d(q+, v+)/d(q, v) and d(q+, v+)/dtau
along the tangent; ``StepDerivatives.dx_du`` with `input_matrix` gives the Jacobian in the
thrusters' forces and the joint torques.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.checks import finite_vector, flag
from uvms_pin.errors import ParameterError
from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.dynamics import CompiledDynamics
from uvms_pin.physics.configuration import checked_configuration
from uvms_pin.physics.derivatives.step import (
    METHODS,
    FixedStepIntegrator,
    StepDerivatives,
    input_matrix,
    step_derivatives_of,
    substeps,
)
from uvms_pin.physics.dynamics import (
    _flow_of_call,
    dynamics_of,
    forward_dynamics,
    forward_dynamics_derivatives,
)
from uvms_pin.physics.reference import check_time

__all__ = ["StepDerivatives", "input_matrix", "step_derivatives"]


def step_derivatives(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    period_s: float,
    *,
    step_s: float | None = None,
    integrator: str | FixedStepIntegrator = "semi_implicit_euler",
    current_world: np.ndarray | None = None,
    flow: FlowField | None = None,
    time_s: float = 0.0,
    tau_ext: np.ndarray | None = None,
    backend: str = "core",
    free_surface: bool = False,
) -> StepDerivatives:
    """The state after ``period_s`` [s] of equal substeps of at most ``step_s`` [s] from
    (q, v) at ``time_s``, tau (and tau_ext) held, and its Jacobians.

    ``integrator``: "semi_implicit_euler" (default) or "rk4" with ``step_s`` (default
    1e-3 s), or the plant's integrator itself, `uvms_pin.sim.integrators.RK4` or
    `SemiImplicitEuler` (its own step_s; then no ``step_s``). The other arguments are those
    of `forward_dynamics_derivatives` (the flow is evaluated at each stage's time; with
    ``free_surface`` a hull the surface cuts adds its wet-fraction terms, one-sided at the
    kinks).

    With ``backend="core"`` the whole period is one compiled call
    (src/uvms_core/step_derivatives.hpp), except with ``free_surface`` (the stages are then
    chained from Python, on the compiled stage derivatives with the surface's terms) or in a
    flow the core has no counterpart of (the Python loop, on the reference, with a warning).
    """
    if isinstance(integrator, str):
        method, step_s = integrator, 1e-3 if step_s is None else step_s
    elif step_s is not None:
        raise ParameterError("give step_s or an integrator object (with its step_s), not both")
    elif isinstance(getattr(integrator, "core_method", None), str):
        method, step_s = integrator.core_method, integrator.step_s
    else:  # None, a number: not an integrator (the sim's FixedStep ones have these two)
        raise ParameterError(
            f"integrator must be one of {METHODS} or a fixed-step integrator (RK4, "
            f"SemiImplicitEuler), got {integrator!r}"
        )
    if method not in METHODS:
        raise ParameterError(f"integrator must be one of {METHODS}, got '{method}'")
    substeps(period_s, step_s)  # checks both
    q, v = checked_configuration("q", q, uvms.model), finite_vector("v", v, uvms.nv)
    tau, time_s = finite_vector("tau", tau, uvms.nv), check_time(time_s)
    free_surface = flag("free_surface", free_surface)
    dynamics = dynamics_of(uvms, backend)
    if isinstance(dynamics, CompiledDynamics) and not free_surface:
        water = _flow_of_call(np.zeros(3) if current_world is None else current_world, flow)
        ext = None if tau_ext is None else finite_vector("tau_ext", tau_ext, uvms.nv)
        out = dynamics.step_derivatives(
            q, v, tau, water, time_s, ext, float(period_s), step_s, method
        )
        if not isinstance(out, Fallback):
            return StepDerivatives(q=out.q, v=out.v, dx_dx=out.dx_dx, dx_dtau=out.dx_dtau)
    common = {
        "current_world": np.zeros(3) if current_world is None else current_world,
        "flow": flow,
        "tau_ext": tau_ext,
        "backend": backend,
        "free_surface": free_surface,
    }

    def derivative(t, qq, vv, tt):
        a = forward_dynamics(uvms, qq, vv, tt, time_s=t, **common)
        return (a, *forward_dynamics_derivatives(uvms, qq, vv, tt, time_s=t, **common))

    return step_derivatives_of(uvms.model, derivative, time_s, q, v, tau, period_s, step_s, method)
