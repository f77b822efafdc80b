"""The core's fixed-step integrator (src/uvms_core/integrators.hpp) of an `Integrator`."""

from __future__ import annotations

from types import ModuleType

from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.sim.integrators import FixedStep, Integrator

__all__ = ["integrator_to_core"]


def integrator_to_core(integrator: Integrator, core: ModuleType):
    """The core's FixedStep of ``integrator`` (RK4, semi-implicit Euler: those whose
    ``core_method`` names a core method), or the `Fallback` saying why none (an adaptive
    integrator, a fixed-step one of your own)."""
    method = getattr(integrator, "core_method", "") if isinstance(integrator, FixedStep) else ""
    if not method:
        return Fallback(f"the integrator {type(integrator).__name__}")
    out = core.FixedStep()
    out.method = getattr(core.Method, method)
    out.step_s = float(integrator.step_s)
    return out
