"""The package namespace: lazy names stay what they are whatever was imported first."""

from __future__ import annotations

import subprocess
import sys


def test_simulate_is_the_function_even_after_its_module_is_imported():
    code = (
        "import uvms_pin.sim.run, uvms_pin.scenario.load, uvms_pin as up\n"
        "assert callable(up.simulate) and up.simulate.__module__ == 'uvms_pin.sim.run'\n"
        "from uvms_pin.sim.settings import SimulationSettings\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
