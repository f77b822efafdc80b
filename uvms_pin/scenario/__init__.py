"""Scenario files (TOML) -> the objects of one run; ``simulate(scenario)`` runs it.

from uvms_pin.scenario import load_scenario, simulate
rollout = simulate(load_scenario("scenarios/realistic_force_tracking.toml"))
"""

from uvms_pin._lazy import lazy_exports

_EXPORTS = {
    "Scenario": "uvms_pin.sim.run",
    "apply_overrides": "uvms_pin.scenario.overrides",
    "load_scenario": "uvms_pin.scenario.scenario",
    "simulate": "uvms_pin.sim.run",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
