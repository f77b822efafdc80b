"""Scenario files (TOML) -> the objects of one run; ``simulate(scenario)`` runs it.

    from uvms_pin.scenario import load_scenario, simulate
    rollout = simulate(load_scenario("scenarios/realistic_force_tracking.toml"))

`load` reads a file (`schema` checks every table, `overrides` varies it); one module per
table builds its concept (`water`, `initial`, `world`, `actuation`, `sensors`, `timing`,
`controller`, `ppc`, `baselines`, `custom_controller`).
"""

from uvms_pin._lazy import lazy_exports

_EXPORTS = {
    "Scenario": "uvms_pin.sim.run",
    "apply_overrides": "uvms_pin.scenario.overrides",
    "baseline_controller_table": "uvms_pin.scenario.baselines",
    "load_scenario": "uvms_pin.scenario.load",
    "scenario_from_raw": "uvms_pin.scenario.load",
    "simulate": "uvms_pin.sim.run",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
