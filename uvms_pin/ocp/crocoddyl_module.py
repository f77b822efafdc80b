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
    _no_leak_report_at_exit()
    return crocoddyl


def _no_leak_report_at_exit() -> None:
    """Turn off nanobind's report of the compiled core's objects alive at exit.

    crocoddyl holds the Python nodes of a problem from C++, where the garbage collector
    cannot see. A script's global problem whose cost term is the script's own class makes
    a cycle through the script's module that the interpreter frees only after the core's
    module: nanobind then names every core object the script holds as "leaked", a false
    alarm pointing at uvms-pin's bindings (tests/ocp/test_exit_report.py)."""
    from uvms_pin.physics.compiled.extension import core_available, core_module

    if core_available():
        core_module().set_leak_warnings(False)


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
