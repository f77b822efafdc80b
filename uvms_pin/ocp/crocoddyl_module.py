"""crocoddyl, or an error saying how to install it (it is an optional dependency)."""

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
