"""uvms-pin: Underwater Vehicle-Manipulator Systems on Pinocchio."""

import sys
from importlib import import_module
from types import ModuleType
from typing import Any

from uvms_pin.errors import (
    FunnelViolation,
    ModelError,
    ModelWarning,
    ParameterError,
    ScenarioError,
    SimulationError,
    UvmsPinError,
    UvmsPinWarning,
)

# The rest is imported on first use (PEP 562): ``uvms-pin --help`` and argument errors
# then answer without loading Pinocchio and SciPy.
_LAZY = {
    "bias_forces": "uvms_pin.dynamics",
    "forward_dynamics": "uvms_pin.dynamics",
    "frame_wrench_to_generalized": "uvms_pin.dynamics",
    "kinetic_energy": "uvms_pin.dynamics",
    "mass_matrix": "uvms_pin.dynamics",
    "potential_energy": "uvms_pin.dynamics",
    "HydroParams": "uvms_pin.hydro.params",
    "Measurement": "uvms_pin.measurement",
    "UVMS": "uvms_pin.model",
    "HydroBody": "uvms_pin.model",
    "load_uvms": "uvms_pin.model",
    "mount_arm": "uvms_pin.mount",
    "shipped_path": "uvms_pin.resources",
    "Rollout": "uvms_pin.rollout",
    "load_scenario": "uvms_pin.scenario",
    "simulate": "uvms_pin.scenario",
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'uvms_pin' has no attribute '{name}'")
    value = getattr(import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})


class _Package(ModuleType):
    """The package module: importing the submodule ``uvms_pin.simulate`` must not hide the
    function ``uvms_pin.simulate`` (the import system binds a submodule onto its package)."""

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _LAZY and isinstance(value, ModuleType):
            return  # the submodule stays reachable through sys.modules
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


__version__ = "0.1.0"

__all__ = [
    "UVMS",
    "FunnelViolation",
    "HydroBody",
    "HydroParams",
    "Measurement",
    "ModelError",
    "ModelWarning",
    "ParameterError",
    "Rollout",
    "ScenarioError",
    "SimulationError",
    "UvmsPinError",
    "UvmsPinWarning",
    "bias_forces",
    "forward_dynamics",
    "frame_wrench_to_generalized",
    "kinetic_energy",
    "load_scenario",
    "load_uvms",
    "mass_matrix",
    "mount_arm",
    "potential_energy",
    "shipped_path",
    "simulate",
]
