"""crocoddyl and mim_solvers, or an error saying how to install them (optional dependencies)."""

from __future__ import annotations

from types import ModuleType

from uvms_pin.errors import OptionalDependencyError


def crocoddyl_module() -> ModuleType:
    """The crocoddyl module (OptionalDependencyError if it is not installed)."""
    try:
        import crocoddyl
    except ImportError as exc:
        raise OptionalDependencyError(
            "uvms_pin.ocp needs crocoddyl: pip install 'uvms-pin[ocp]' (crocoddyl >= 3.2)"
        ) from exc
    return crocoddyl


def mim_solvers_module() -> ModuleType:
    """The mim_solvers module (its CSQP solver; OptionalDependencyError if it is not
    installed). crocoddyl is imported first: the mim-solvers 0.3 wheel's libcrocoddyl finds
    its Boost libraries only once crocoddyl's own extension has loaded them."""
    crocoddyl_module()
    try:
        import mim_solvers
    except ImportError as exc:
        raise OptionalDependencyError(
            "the 'csqp' solver needs mim-solvers: pip install 'uvms-pin[ocp]' "
            f"(mim-solvers >= 0.3): {exc}"
        ) from exc
    return mim_solvers
