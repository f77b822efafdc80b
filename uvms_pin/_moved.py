"""Module paths of uvms-pin 0.1 that moved when the package was arranged in layers.

``import uvms_pin.controllers.base`` (or any path below) still works: it gives the module at
its new place, the same object, and warns once with a `DeprecationWarning` naming that place.
New code imports the new path (docs/architecture.md has the map). Paths whose last part now
names something else are not kept: ``uvms_pin.simulate`` is the function `uvms_pin.simulate`
(the closed loop it also named is `uvms_pin.sim.closed_loop`).
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings
from types import ModuleType

#: old path (below ``uvms_pin.``) -> new path; a package's entry covers its modules. A module
#: that was split maps to its parts (a tuple): its names are found in them, in order.
MOVED: dict[str, str | tuple[str, ...]] = {
    "actuation": "sim.actuation",
    "atomic": "results.atomic",
    "cli": "apps.cli.main",
    "cli_types": "apps.arguments",
    "core": ("physics.compiled.extension", "physics.compiled.backend", "physics.dynamics"),
    "dynamics": "physics.dynamics",
    "environment": ("physics.contact", "physics.disturbance"),
    "integrators": "sim.integrators",
    "kinematics": "physics.kinematics",
    "measurement": "control.measurement",
    "metrics": "results.metrics",
    "mount": "model.mount.mount",
    "native_stderr": "model.native_stderr",
    "outdir": "results.outdir",
    "overrides": "scenario.overrides",
    "plant": "sim.plant",
    "progress": "results.progress",
    "resources": "model.resources",
    "rollout": "results.rollout",
    "rollout_table": "results.table",
    "sensors": "sim.sensors",
    "summary": "model.summary",
    "tomlfile": "scenario.toml",
    "trim": "model.trim",
    "arms": "apps.arms",
    "arms.catalog": "model.mount.catalog",
    "arms.reference": "model.mount.split",
    "compare": "apps.compare",
    "controllers": "control",
    "controllers.custom": "scenario.custom_controller",
    "controllers.task": "control.baselines.task",
    "controllers.pi_force": "control.baselines.pi_force",
    "controllers.impedance": "control.baselines.impedance",
    "controllers.computed_torque": "control.baselines.computed_torque",
    "export": "apps.export",
    "gym": "apps.gym",
    "study": "apps.study",
    "validation": "apps.validation",
    "vehicles": "model.vehicles",
    "viz": "apps.viz",
    "viz.controller_comparison": "apps.compare.figures",
    "viz.errors": "errors",
    "viz.figures": "results.figures.kinds",
    "viz.paper_figures": "results.figures.paper",
    "viz.plots": "results.figures.standard",
    "viz.pool_figures": "apps.validation.figures",
}

_PREFIX = "uvms_pin."


def new_path(old: str) -> str | tuple[str, ...] | None:
    """The new full path (or paths, for a split module) of the old full module path
    ``old``, or None if it did not move."""
    if not old.startswith(_PREFIX):
        return None
    parts = old[len(_PREFIX) :].split(".")
    for k in range(len(parts), 0, -1):
        moved = MOVED.get(".".join(parts[:k]))
        if isinstance(moved, tuple):
            return tuple(_PREFIX + m for m in moved) if k == len(parts) else None
        if moved is not None:
            return _PREFIX + ".".join([moved, *parts[k:]])
    return None


class _SplitModule(ModuleType):
    """An old module that was split: its names, looked up in the parts in order."""

    def __init__(self, name: str, parts: tuple[ModuleType, ...]):
        super().__init__(
            name, f"moved: its names are now in {', '.join(p.__name__ for p in parts)}"
        )
        self._parts = parts

    def __getattr__(self, attribute: str):
        for part in self._parts:
            if hasattr(part, attribute):
                return getattr(part, attribute)
        raise AttributeError(f"module '{self.__name__}' has no attribute '{attribute}'")


class _Alias(importlib.abc.Loader):
    """Loads an old path as the module at its new place (the same object)."""

    def __init__(self, new: str | tuple[str, ...]):
        self.new = new
        self._spec = None

    def create_module(self, spec) -> ModuleType:
        where = self.new if isinstance(self.new, str) else " and ".join(self.new)
        warnings.warn(
            f"{spec.name} moved to {where}; import it from there",
            DeprecationWarning,
            stacklevel=2,
        )
        if not isinstance(self.new, str):
            return _SplitModule(spec.name, tuple(map(importlib.import_module, self.new)))
        module = importlib.import_module(self.new)
        self._spec = module.__spec__  # the import system sets the alias's; put it back below
        return module

    def exec_module(self, module: ModuleType) -> None:
        """Nothing to run (the module was imported at its new place): its own spec back."""
        if self._spec is not None:
            module.__spec__ = self._spec


class MovedModuleFinder(importlib.abc.MetaPathFinder):
    """Finds the old paths of `MOVED` (before the path finder, which no longer can)."""

    def find_spec(self, fullname, path=None, target=None):
        new = new_path(fullname)
        if new is None or fullname in sys.modules:
            return None
        for path in (new,) if isinstance(new, str) else new:
            if importlib.util.find_spec(path) is None:
                return None
        return importlib.util.spec_from_loader(fullname, _Alias(new))


def install() -> None:
    """Put the finder first on ``sys.meta_path`` (once per process)."""
    if not any(isinstance(f, MovedModuleFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, MovedModuleFinder())
