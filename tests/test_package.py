"""The package namespace: lazy names stay what they are whatever was imported first."""

from __future__ import annotations

import subprocess
import sys

from conftest import heavy_packages_loaded_by


def test_simulate_is_the_function_even_after_its_module_is_imported():
    code = (
        "import uvms_pin.sim.run, uvms_pin.scenario.load, uvms_pin as up\n"
        "assert callable(up.simulate) and up.simulate.__module__ == 'uvms_pin.sim.run'\n"
        "from uvms_pin.sim.settings import SimulationSettings\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_every_public_name_resolves_and_is_documented():
    """``up.X`` for every X of ``__all__``: it resolves, and docs/api.md names it so."""
    from conftest import ROOT

    import uvms_pin as up

    api = (ROOT / "docs" / "api.md").read_text()
    missing = [name for name in up.__all__ if f"`up.{name}`" not in api]
    assert not missing, f"not in docs/api.md as `up.<name>`: {missing}"
    for name in up.__all__:
        assert getattr(up, name) is not None, name
    errors = {name for name in up.__all__ if name.endswith(("Error", "Warning", "Violation"))}
    assert len(set(up.__all__)) == len(up.__all__)
    assert set(up.__all__) == set(up._lazy_names) | errors  # every lazy name is public
    assert set(up.__all__) <= set(dir(up))


def test_the_flat_names_are_the_classes_of_their_modules():
    import uvms_pin as up
    from uvms_pin.control.baselines.pi_force import PIForceController
    from uvms_pin.flow.airy import AiryWave
    from uvms_pin.sim.plant import Plant

    assert (
        up.Plant is Plant and up.AiryWave is AiryWave and up.PIForceController is PIForceController
    )
    assert not hasattr(up, "MpcController")  # its module imports crocoddyl (optional)
    assert up.simulate_batch.__module__ == "uvms_pin.scenario.batch"


def test_importing_the_package_loads_nothing_heavy():
    code = "import uvms_pin as up\nassert 'Plant' in up.__all__ and 'World' in dir(up)"
    heavy = {"pinocchio", "scipy", "matplotlib", "crocoddyl", "pandas"}
    assert heavy_packages_loaded_by(code, heavy) == []
