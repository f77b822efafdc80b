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
__getattr__, __dir__, _lazy_names = lazy_exports(
    __name__,
    {
        "uvms_pin.physics.dynamics": (
            "bias_forces",
            "forward_dynamics",
            "forward_dynamics_derivatives",
            "frame_wrench_to_generalized",
            "kinetic_energy",
            "mass_matrix",
            "potential_energy",
        ),
        "uvms_pin.physics.discrete": ("StepDerivatives", "input_matrix", "step_derivatives"),
        "uvms_pin.hydro.params": ("HydroParams",),
        "uvms_pin.control.base": ("Controller",),
        "uvms_pin.control.measurement": ("Measurement",),
        "uvms_pin.model.uvms": ("UVMS", "HydroBody"),
        "uvms_pin.model.urdf.load": ("load_uvms",),
        "uvms_pin.model.importer.convert": ("import_model",),
        "uvms_pin.model.mount.mount": ("mount_arm",),
        "uvms_pin.model.resources": ("shipped_path",),
        "uvms_pin.results.rollout": ("Rollout",),
        "uvms_pin.results.status": ("RunStatus",),
        "uvms_pin.results.signal": ("Signal",),
        "uvms_pin.scenario.load": ("load_scenario",),
        "uvms_pin.sim.run": ("Scenario", "simulate"),
        "uvms_pin.sim.batch": ("simulate_batch",),
    },
)

_moved.install()

__version__ = "0.1.0"

__all__ = [
    "UVMS",
    "Controller",
    "FunnelViolation",
    "HydroBody",
    "HydroParams",
    "Measurement",
    "ModelError",
    "ModelWarning",
    "ParameterError",
    "Rollout",
    "RunStatus",
    "Scenario",
    "ScenarioError",
    "Signal",
    "SimulationError",
    "StepDerivatives",
    "UvmsPinError",
    "UvmsPinWarning",
    "bias_forces",
    "forward_dynamics",
    "forward_dynamics_derivatives",
    "frame_wrench_to_generalized",
    "import_model",
    "input_matrix",
    "kinetic_energy",
    "load_scenario",
    "load_uvms",
    "mass_matrix",
    "mount_arm",
    "potential_energy",
    "shipped_path",
    "simulate",
    "simulate_batch",
    "step_derivatives",
]
