"""The module paths of 0.1 still import, as the same modules, saying where they went."""

from __future__ import annotations

import importlib.util
import subprocess
import sys

import pytest

from uvms_pin._moved import MOVED, new_path


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)


@pytest.mark.parametrize("old", sorted(k for k, v in MOVED.items() if isinstance(v, str)))
def test_every_moved_path_leads_to_a_module_that_exists(old):
    assert importlib.util.find_spec(new_path(f"uvms_pin.{old}")) is not None


def test_an_old_path_is_the_new_module_with_a_deprecation_warning():
    result = _run(
        "import warnings\n"
        "warnings.simplefilter('error', DeprecationWarning)\n"
        "import uvms_pin.control.base as new\n"
        "try:\n"
        "    import uvms_pin.controllers.base\n"
        "except DeprecationWarning as w:\n"
        "    print(w)\n"
        "warnings.simplefilter('ignore', DeprecationWarning)\n"
        "from uvms_pin.controllers.base import Controller\n"
        "assert Controller is new.Controller\n"
        "import uvms_pin.controllers.base as old\n"
        "assert old is new and old.__spec__.name == 'uvms_pin.control.base'\n"
        "from uvms_pin.environment import LinearSpring, SinusoidalDisturbance\n"
        "from uvms_pin.physics.contact import LinearSpring as L\n"
        "assert L is LinearSpring\n"
        "import uvms_pin as up\n"
        "assert callable(up.simulate)\n"
    )
    assert result.returncode == 0, result.stderr
    assert "uvms_pin.controllers moved to uvms_pin.control" in result.stdout


def test_a_split_module_names_what_it_no_longer_has():
    result = _run(
        "import warnings; warnings.simplefilter('ignore')\n"
        "import uvms_pin.environment as old\n"
        "try:\n"
        "    old.no_such_thing\n"
        "except AttributeError as e:\n"
        "    print(e)\n"
    )
    assert result.returncode == 0, result.stderr
    assert "module 'uvms_pin.environment' has no attribute 'no_such_thing'" in result.stdout
