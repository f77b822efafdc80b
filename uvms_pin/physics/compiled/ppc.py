"""The core's PPC law (src/uvms_core/ppc.hpp) of a model and its settings."""

from __future__ import annotations

from types import ModuleType

import pinocchio as pin

__all__ = ["ppc_to_core"]


def ppc_to_core(core: ModuleType, model: pin.Model, settings: dict[str, object]):
    """The core's PrescribedPerformanceController of ``model`` with ``settings``: the fields
    of its PpcSettings by name (gains, funnels, the task's constants), as the Python law
    `uvms_pin.control.ppc.PrescribedPerformanceController` holds them."""
    compiled = core.PpcSettings()
    for name, value in settings.items():
        setattr(compiled, name, value)
    return core.PrescribedPerformanceController(model.saveToString(), compiled)
