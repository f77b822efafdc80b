"""The discrete step of the plant and its Jacobians: what a DDP-type solver or an MPC
linearises (`uvms_pin.physics.derivatives.step` for the math).

`step_derivatives` takes one control period of semi-implicit Euler substeps (the plant's
`SemiImplicitEuler` integrator) with the generalized force held, and returns the end state
with d(q+, v+)/d(q, v) and d(q+, v+)/dtau along the tangent; ``StepDerivatives.dx_du`` with
`input_matrix` gives the Jacobian in the thrusters' forces and the joint torques.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.checks import finite_vector
from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.derivatives.step import StepDerivatives, input_matrix, step_derivatives_of
from uvms_pin.physics.dynamics import forward_dynamics, forward_dynamics_derivatives

__all__ = ["StepDerivatives", "input_matrix", "step_derivatives"]


def step_derivatives(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    period_s: float,
    *,
    step_s: float = 1e-3,
    current_world: np.ndarray | None = None,
    flow: FlowField | None = None,
    time_s: float = 0.0,
    tau_ext: np.ndarray | None = None,
    backend: str = "core",
    free_surface: bool = False,
) -> StepDerivatives:
    """The state after ``period_s`` [s] of semi-implicit Euler substeps of at most
    ``step_s`` [s] from (q, v) at ``time_s``, tau (and tau_ext) held, and its Jacobians.

    The other arguments are those of `forward_dynamics_derivatives` (the flow is evaluated
    at each substep's time; with ``free_surface`` a hull the surface cuts adds its
    wet-fraction terms, one-sided at the kinks).
    """
    q, v = finite_vector("q", q, uvms.nq), finite_vector("v", v, uvms.nv)
    tau = finite_vector("tau", tau, uvms.nv)
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

    return step_derivatives_of(uvms.model, derivative, float(time_s), q, v, tau, period_s, step_s)
