"""The one registry of controller types: each kind's module registers its reader, an unknown
name is refused with the known ones listed."""

from __future__ import annotations

import pytest

from uvms_pin.errors import ParameterError, ScenarioError
from uvms_pin.scenario.controller import REGISTERING_MODULES
from uvms_pin.scenario.controller_parts import CONTROLLERS
from uvms_pin.scenario.registry import Registry
from uvms_pin.scenario.schema import Table

BUILT_IN = (
    "none",
    "ppc",
    "mpc",
    "pi_force",
    "impedance",
    "computed_torque",
    "task_priority",
    "resolved_acceleration",
    "joint_hold",
)


def test_a_registry_registers_and_refuses_unknown_and_twice_registered_names():
    shapes: Registry[str] = Registry("shape", besides="a number of sides")
    assert shapes.register("circle")("round") == "round"  # the decorator gives its entry back
    shapes.register("square")("four sides")
    shapes.register("annulus")("two circles")
    assert shapes["circle"] == "round" and list(shapes) == ["annulus", "circle", "square"]
    assert "square" in shapes and "cube" not in shapes and len(shapes) == 3
    with pytest.raises(ParameterError) as info:
        shapes["circel"]
    message = str(info.value)
    assert message == (
        "must be one of annulus, circle, square or a number of sides, got 'circel' "
        "(did you mean 'circle'?)"
    )
    with pytest.raises(ParameterError, match="shape 'circle' is registered twice"):
        shapes.register("circle")("again")


def test_every_built_in_controller_is_in_the_one_registry():
    assert REGISTERING_MODULES  # imported by the table's reader, so registered
    assert set(CONTROLLERS) == set(BUILT_IN)
    for module in REGISTERING_MODULES:
        readers = [CONTROLLERS[name] for name in CONTROLLERS]
        assert any(getattr(r, "__module__", None) == module.__name__ for r in readers) or any(
            getattr(getattr(r, "func", None), "__module__", None) == module.__name__
            for r in readers
        ), module.__name__


def test_an_unknown_controller_type_lists_every_known_one():
    from uvms_pin.scenario.controller import build_controller
    from uvms_pin.scenario.controller_parts import ControllerContext

    table = Table({"type": "ppcc"}, "controller", "s.toml")
    with pytest.raises(ScenarioError) as info:
        build_controller(table, ControllerContext(uvms=None))
    message = str(info.value)
    assert message.startswith("s.toml: controller.type: must be one of ")
    for name in BUILT_IN:
        assert name in message
    assert "or 'package.module:ClassName', got 'ppcc' (did you mean 'ppc'?)" in message
