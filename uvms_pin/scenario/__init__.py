"""Scenario files (TOML) -> the objects of one run; ``simulate(scenario)`` runs it.

    from uvms_pin.scenario import load_scenario, simulate
    rollout = simulate(load_scenario("scenarios/realistic_force_tracking.toml"))

`load` reads a file (`schema` checks every table, `overrides` varies it); one module per
table builds its concept (`water`, `initial`, `world`, `actuation`, `sensors`, `timing`,
`controller`, `ppc`, `baselines`, `custom_controller`); `controller_parts` holds the
pieces several controller tables share (profiles, end-effector frame) and `toml` reads
TOML files with errors that name them.
"""

from uvms_pin._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(
    __name__,
    {
        "uvms_pin.sim.run": ("Scenario", "simulate"),
        "uvms_pin.scenario.load": ("load_scenario", "scenario_from_raw"),
        "uvms_pin.scenario.overrides": ("apply_overrides",),
        "uvms_pin.scenario.baselines": ("baseline_controller_table",),
    },
)
