"""The core's control laws of the package's controllers."""

from __future__ import annotations

from types import ModuleType
from typing import Any

from uvms_pin.control.ppc import PrescribedPerformanceController
from uvms_pin.physics.compiled.backend import Fallback

__all__ = ["law_to_core"]


def law_to_core(controller: Any, core: ModuleType):
    """The core's law of ``controller``, or the `Fallback` saying why it has none."""
    if type(controller) is not PrescribedPerformanceController:
        return Fallback(f"the controller {type(controller).__name__} is not compiled")
    kernel = getattr(controller, "_kernel", None)
    if kernel is None:
        return Fallback("the controller's Python backend")
    return kernel.kernel
