"""uvms-pin: Underwater Vehicle-Manipulator Systems on Pinocchio."""

from uvms_pin import _moved
from uvms_pin._lazy import lazy_exports
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
    "bias_forces": "uvms_pin.physics.dynamics",
    "forward_dynamics": "uvms_pin.physics.dynamics",
    "frame_wrench_to_generalized": "uvms_pin.physics.dynamics",
    "kinetic_energy": "uvms_pin.physics.dynamics",
    "mass_matrix": "uvms_pin.physics.dynamics",
    "potential_energy": "uvms_pin.physics.dynamics",
    "HydroParams": "uvms_pin.hydro.params",
    "Measurement": "uvms_pin.control.measurement",
    "UVMS": "uvms_pin.model.uvms",
    "HydroBody": "uvms_pin.model.uvms",
    "load_uvms": "uvms_pin.model.urdf.load",
    "mount_arm": "uvms_pin.model.mount.mount",
    "shipped_path": "uvms_pin.model.resources",
    "Rollout": "uvms_pin.results.rollout",
    "load_scenario": "uvms_pin.scenario.load",
    "simulate": "uvms_pin.sim.run",
}


__getattr__, __dir__ = lazy_exports(__name__, _LAZY)

_moved.install()

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
