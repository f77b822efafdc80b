"""uvms-pin: Underwater Vehicle-Manipulator Systems on Pinocchio."""

from uvms_pin.dynamics import (
    bias_forces,
    forward_dynamics,
    frame_wrench_to_generalized,
    kinetic_energy,
    mass_matrix,
    potential_energy,
)
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
from uvms_pin.hydro.params import HydroParams
from uvms_pin.measurement import Measurement
from uvms_pin.model import UVMS, HydroBody, load_uvms
from uvms_pin.mount import mount_arm
from uvms_pin.resources import shipped_path
from uvms_pin.rollout import Rollout
from uvms_pin.scenario import load_scenario, simulate

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
