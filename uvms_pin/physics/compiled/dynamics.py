"""The compiled dynamics of a UVMS: its hydrodynamic bodies as the core's `HydroBodies`
(src/uvms_core/hydro_bodies.hpp) and the `Dynamics` built from them (dynamics.hpp).

`CompiledDynamics` has the interface of `uvms_pin.physics.reference.ReferenceDynamics`: the
calls in a uniform current go straight to C++; a call in a flow the core has no counterpart of
(a varying or sheared current) runs on the reference, with a `CoreFallbackWarning`.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from types import ModuleType

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.compiled.flow import flow_to_core
from uvms_pin.physics.compiled.hull import surface_bodies_to_core
from uvms_pin.physics.configuration import NORM_TOLERANCE, checked_configuration
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
        self._jacobians_shape = (3, uvms.nv, uvms.nv)  # the public derivatives' array
        self._derivatives = None  # core.Derivatives, built on first use
        self._step_derivatives = None  # core.StepDerivatives, built on first use
        self._batch = None  # core.BatchDerivatives, the last built (`batch_derivatives`)
        # the calls in a uniform current: the C++ methods themselves (no Python in between)
        self.mass_matrix = self.core.mass_matrix
        self.bias_forces = self.core.bias_forces
        self.forward_dynamics = self.core.forward_dynamics
        # the calls in a flow (the reference's arguments, the flow the k-th): the C++ method
        # in a flow the core has a counterpart of, else the reference's, with a warning
        self.mass_matrix_in = self._in_flow(self.core.mass_matrix_in, reference.mass_matrix_in, 1)
        self.bias_forces_in = self._in_flow(self.core.bias_forces_in, reference.bias_forces_in, 2)
        self.forward_dynamics_in = self._in_flow(
            self.core.forward_dynamics_in, reference.forward_dynamics_in, 3
        )
        # (da/dq, da/dv, da/dtau) in the core (src/uvms_core/derivatives.hpp): its own copy of
        # these dynamics, built on first use; the arguments of the reference
        # (`uvms_pin.physics.derivatives.reference`) after its ``uvms``
        self.forward_dynamics_derivatives = self._in_flow(
            self._core_derivatives,
            functools.partial(reference_derivatives, reference.uvms),
            3,
            "these derivatives",
        )
        # one period's step Jacobians (`_core_period`), or the Fallback of a flow the core
        # has no counterpart of (the caller chains the reference's stages)
        self.step_derivatives = self._in_flow(self._core_period, None, 3)

    def batch_derivatives(self, num_threads: int):
        """The core's BatchDerivatives on ``num_threads`` threads (the last one is kept: each
        thread holds its own copy of the dynamics)."""
        if self._batch is None or self._batch.num_threads != num_threads:
            self._batch = core_module().BatchDerivatives(self.core, num_threads)
        return self._batch

    def flow_struct(self, flow: FlowField | None):
        """The core's FlowField of ``flow`` (None: still water), or its `Fallback`."""
        return self._flow_struct(flow)

    def _flow_struct(self, flow: FlowField | None):
        """The core's FlowField of ``flow`` (the last one is kept: a flow is immutable), or
        its Fallback."""
        if self._flow[0] is not flow or self._flow[1] is None:
            self._flow = (flow, flow_to_core(flow, core_module()))
        return self._flow[1]

    def _in_flow(
        self,
        compiled: Callable,
        reference: Callable | None,
        flow_at: int,
        what: str = "these dynamics",
    ) -> Callable:
        """The call ``reference(*args)`` (``args[flow_at]`` a FlowField or None) made by
        ``compiled`` with the core's FlowField in its place, or, in a flow the core has no
        counterpart of, by ``reference`` itself with a `CoreFallbackWarning` naming ``what``
        (no ``reference``: the `Fallback` is returned)."""

        def call(*args):
            flow = self._flow_struct(args[flow_at])
            if isinstance(flow, Fallback):
                if reference is None:
                    return flow
                flow.warn(what, stacklevel=4)
                return reference(*args)
            return compiled(*args[:flow_at], flow, *args[flow_at + 1 :])

        return call

    def public_derivatives(
        self, q, v, tau, flow: FlowField | None, time_s: float, tau_ext, free_surface: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The public call's (da/dq, da/dv, da/dtau) in one compiled call (q's manifold check
        included), or None in a flow the core has no counterpart of (the caller's path then
        warns and runs the reference). Bad input: the ParameterError of the reference's
        checks (q's names the joint off the manifold)."""
        last_flow, flow_struct = self._flow
        if last_flow is not flow or flow_struct is None:  # (`_flow_struct`, inlined: per call)
            flow_struct = self._flow_struct(flow)
        if isinstance(flow_struct, Fallback):
            return None
        if self._derivatives is None:
            self._derivatives = core_module().Derivatives(self.core)
        out = np.empty(self._jacobians_shape)
        try:
            self._derivatives.call(
                q, v, tau, flow_struct, time_s, tau_ext, free_surface, NORM_TOLERANCE, out
            )
            return out[0], out[1], out[2]
        except ParameterError:
            checked_configuration("q", q, self._reference.uvms.model)  # (names the joint)
            raise

    def _core_derivatives(self, *args) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """`Derivatives.forward_dynamics_derivatives` of the core (built on first use)."""
        if self._derivatives is None:
            self._derivatives = core_module().Derivatives(self.core)
        out = self._derivatives.forward_dynamics_derivatives(*args)
        return out.da_dq, out.da_dv, out.da_dtau

    def _core_period(self, *args):
        """The core's `StepJacobians` of one period (src/uvms_core/step_derivatives.hpp), its
        `StepDerivatives` built on first use: ``args`` are (q, v, tau, flow, time_s, tau_ext,
        period_s) and the substeps' ``step_s`` and ``method`` ("rk4", "semi_implicit_euler")."""
        core = core_module()
        if self._step_derivatives is None:
            self._step_derivatives = core.StepDerivatives(self.core)
        *period, step_s, method = args
        integrator = core.FixedStep()
        integrator.method, integrator.step_s = getattr(core.Method, method), float(step_s)
        return self._step_derivatives.period(*period, integrator)
