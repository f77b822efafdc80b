"""Scenario files (TOML) -> the objects of one run; ``simulate(scenario)`` runs it.

    from uvms_pin.scenario import load_scenario, simulate
    rollout = simulate(load_scenario("scenarios/realistic_force_tracking.toml"))

`load` reads a file or a dict (`schema` checks every table, `overrides` varies it); one
module per table builds its concept (`water`, `initial`, `world`, `actuation`, `sensors`,
`timing`, `controller`...); each kind of controller is one module (`ppc`, `baselines`,
`mpc`, `tracking_controllers`, `custom_controller`) that registers its reader in the one
registry `controller_parts.CONTROLLERS` (a `registry.Registry`); `controller_parts` holds
the pieces several controller tables share (profiles, end-effector frame), `batch` runs one
scenario under many overrides on threads and `toml` reads TOML files with errors that name
them.
"""

from uvms_pin._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(
    __name__,
    {
        "uvms_pin.sim.run": ("Scenario", "simulate"),
        "uvms_pin.scenario.load": ("load_scenario", "scenario_from_dict"),
        "uvms_pin.scenario.batch": ("simulate_batch",),
        "uvms_pin.scenario.overrides": ("apply_overrides",),
        "uvms_pin.scenario.baselines": ("baseline_controller_table",),
    },
)
