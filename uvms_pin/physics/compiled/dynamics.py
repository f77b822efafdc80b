"""The compiled dynamics of a UVMS: its hydrodynamic bodies as the core's `HydroBodies`
(src/uvms_core/hydro_bodies.hpp) and the `Dynamics` built from them (dynamics.hpp).

`CompiledDynamics` has the interface of `uvms_pin.physics.reference.ReferenceDynamics`: the
calls in a uniform current go straight to C++; a call in a flow the core has no counterpart of
(a varying or sheared current) runs on the reference, with a `CoreFallbackWarning`.
"""

from __future__ import annotations

from types import ModuleType

import numpy as np

from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.compiled.flow import flow_to_core
from uvms_pin.physics.compiled.hull import surface_bodies_to_core
from uvms_pin.physics.derivatives.reference import (
    forward_dynamics_derivatives as reference_derivatives,
)
from uvms_pin.physics.reference import ReferenceDynamics


def hydro_bodies_to_core(uvms: UVMS, core: ModuleType):
    """The core's `HydroBodies` of ``uvms``: per-joint added mass (at the joint origin, joint
    axes), volume and centre of buoyancy, and every damped link's placement and damping."""
    bodies = core.HydroBodies()
    bodies.water_density_kg_m3 = float(uvms.water_density_kg_m3)
    bodies.added_mass_per_joint = list(uvms.added_mass_per_joint)
    bodies.volume_per_joint_m3 = [float(v) for v in uvms.volume_per_joint_m3]
    bodies.center_of_buoyancy_per_joint_m = list(uvms.center_of_buoyancy_per_joint_m)
    damped = []
    hull_of_damped = uvms.surface_bodies.hull_of_damped
    for k, body in enumerate(uvms.hydro_bodies_with_damping):
        entry = core.DampedBody()
        entry.hull_index = int(hull_of_damped[k])
        entry.joint_id = int(body.joint_id)
        entry.action_joint_to_body = body.action_joint_to_body
        entry.rotation_in_joint = body.placement_in_joint.rotation
        entry.position_in_joint_m = body.placement_in_joint.translation
        entry.linear_damping = body.params.linear_damping
        entry.quadratic_damping = body.params.quadratic_damping
        damped.append(entry)
    bodies.damped_bodies = damped
    bodies.surface_bodies = surface_bodies_to_core(uvms.surface_bodies, core)
    bodies.added_mass_without_hull_per_joint = list(
        uvms.surface_bodies.added_mass_without_hull_per_joint
    )
    return bodies


class CompiledDynamics:
    """M, h and the forward dynamics of one UVMS in the compiled core.

    Like ``uvms.data`` it reads the model when built: a UVMS changed in place afterwards
    needs ``uvms.copy()`` (or `with_model` / `with_hydro`), which builds a new one.
    """

    def __init__(self, uvms: UVMS, reference: ReferenceDynamics):
        core = core_module()
        self.core = core.Dynamics(uvms.model.saveToString(), hydro_bodies_to_core(uvms, core))
        self._reference = reference
        self._flow: tuple[FlowField | None, object] = (None, None)  # the last flow converted
        self._derivatives = None  # core.Derivatives, built on first use
        self._step_derivatives = None  # core.StepDerivatives, built on first use
        # the calls in a uniform current: the C++ methods themselves (no Python in between)
        self.mass_matrix = self.core.mass_matrix
        self.bias_forces = self.core.bias_forces
        self.forward_dynamics = self.core.forward_dynamics

    def _flow_struct(self, flow: FlowField | None):
        """The core's FlowField of ``flow`` (the last one is kept: a flow is immutable), or
        its Fallback."""
        if self._flow[0] is not flow or self._flow[1] is None:
            self._flow = (flow, flow_to_core(flow, core_module()))
        return self._flow[1]

    def mass_matrix_in(
        self, q: np.ndarray, flow: FlowField | None, time_s: float, free_surface: bool = False
    ):
        compiled = self._flow_struct(flow)
        if isinstance(compiled, Fallback):
            compiled.warn("these dynamics", stacklevel=4)
            return self._reference.mass_matrix_in(q, flow, time_s, free_surface)
        return self.core.mass_matrix_in(q, compiled, time_s, free_surface)

    def bias_forces_in(
        self,
        q: np.ndarray,
        v: np.ndarray,
        flow: FlowField | None,
        time_s: float,
        free_surface: bool = False,
    ):
        compiled = self._flow_struct(flow)
        if isinstance(compiled, Fallback):
            compiled.warn("these dynamics", stacklevel=4)
            return self._reference.bias_forces_in(q, v, flow, time_s, free_surface)
        return self.core.bias_forces_in(q, v, compiled, time_s, free_surface)

    def forward_dynamics_in(
        self,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        flow: FlowField | None,
        time_s: float,
        tau_ext: np.ndarray | None = None,
        free_surface: bool = False,
    ):
        compiled = self._flow_struct(flow)
        if isinstance(compiled, Fallback):
            compiled.warn("these dynamics", stacklevel=4)
            return self._reference.forward_dynamics_in(
                q, v, tau, flow, time_s, tau_ext, free_surface
            )
        return self.core.forward_dynamics_in(q, v, tau, compiled, time_s, tau_ext, free_surface)

    def forward_dynamics_derivatives(
        self,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        flow: FlowField | None,
        time_s: float,
        tau_ext: np.ndarray | None = None,
        free_surface: bool = False,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(da/dq, da/dv, da/dtau) in the core (src/uvms_core/derivatives.hpp): its own copy
        of these dynamics, built on first use; a flow the core has no counterpart of runs on
        the reference (`uvms_pin.physics.derivatives.reference`), with a warning."""
        compiled = core_module().FlowField() if flow is None else self._flow_struct(flow)
        if isinstance(compiled, Fallback):
            compiled.warn("these derivatives", stacklevel=4)
            return reference_derivatives(
                self._reference.uvms, q, v, tau, flow, time_s, tau_ext, free_surface
            )
        if self._derivatives is None:
            self._derivatives = core_module().Derivatives(self.core)
        out = self._derivatives.forward_dynamics_derivatives(
            q, v, tau, compiled, time_s, tau_ext, free_surface
        )
        return out.da_dq, out.da_dv, out.da_dtau

    def step_derivatives(
        self,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        flow: FlowField | None,
        time_s: float,
        tau_ext: np.ndarray | None,
        period_s: float,
        step_s: float,
        method: str,
    ):
        """The core's `StepJacobians` of one period (src/uvms_core/step_derivatives.hpp) in
        substeps of at most ``step_s`` of ``method`` ("rk4", "semi_implicit_euler"), or the
        Fallback of a flow it has no counterpart of."""
        core = core_module()
        compiled = core.FlowField() if flow is None else self._flow_struct(flow)
        if isinstance(compiled, Fallback):
            return compiled
        if self._step_derivatives is None:
            self._step_derivatives = core.StepDerivatives(self.core)
        integrator = core.FixedStep()
        integrator.method, integrator.step_s = getattr(core.Method, method), float(step_s)
        return self._step_derivatives.period(
            q, v, tau, compiled, time_s, tau_ext, period_s, integrator
        )
