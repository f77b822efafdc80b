"""uvms_pin/checks.py: `finite_parameters`, what a controller's constructor calls with its
``locals()``; the scalar checks; `number_fields`, what a self-checking dataclass calls first
(and every such dataclass of the package, walked)."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import math
import pkgutil

import numpy as np
import pytest

import uvms_pin
from uvms_pin.checks import finite_parameters, nonnegative, number_fields, positive
from uvms_pin.errors import ParameterError


def test_numbers_nested_lists_and_arrays_that_are_finite_pass_and_the_rest_is_passed_over():
    finite_parameters(
        "probe",
        {
            "self": object(), "frame": "alpha_jaw_link", "none": None, "flag": True,
            "gain": 3, "ramp_s": 0.5, "gains": (1.0, 2.0), "array": np.ones(3),
            "waypoints": [[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]], "empty": [],
            "names": ["a", "b"], "numpy": np.float32(2.0),
        },
    )  # fmt: skip


@pytest.mark.parametrize(
    "key, value",
    [
        ("gain", math.inf),
        ("gain", -math.inf),
        ("gain", math.nan),
        ("gains", [1.0, math.nan]),
        ("waypoints", [[0.0, 0.0, 0.0], [1.0, math.inf, 0.0]]),
        ("array", np.array([0.0, -np.inf])),
        ("numpy", np.float64("nan")),
    ],
)
def test_a_non_finite_number_anywhere_in_a_value_is_refused_naming_its_owner_and_key(key, value):
    with pytest.raises(ParameterError, match=rf"^probe: {key} must be finite, got"):
        finite_parameters("probe", {"ok": 1.0, key: value})


def test_never_keys_accept_plus_infinity_only():
    finite_parameters("probe", {"open_at_s": math.inf}, never=("open_at_s",))
    for bad in (-math.inf, math.nan):
        with pytest.raises(ParameterError, match=r"open_at_s must be finite \(or inf: never\)"):
            finite_parameters("probe", {"open_at_s": bad}, never=("open_at_s",))
    with pytest.raises(ParameterError, match="close_at_s must be finite, got inf"):
        finite_parameters("probe", {"close_at_s": math.inf}, never=("open_at_s",))


@pytest.mark.parametrize("value", ["0.1", None, True, [0.1], {"bound": 0.1}, "abc"])
@pytest.mark.parametrize("check", [positive, nonnegative])
def test_a_value_that_is_not_a_number_is_refused_by_name(check, value):
    """A string (even one that reads as a number), None, a bool, a list or a table: a
    ParameterError naming the value's owner (float() raised ValueError or TypeError, or
    took "0.1" and True as numbers)."""
    with pytest.raises(ParameterError, match="step_s must be a number"):
        check("step_s", value)
    assert check("step_s", np.float32(0.5)) == 0.5 and check("step_s", 2) == 2.0


@dataclasses.dataclass
class _Record:
    gain: float = 1.0
    limit_s: float | None = None
    name: str = "probe"
    weights: tuple[float, ...] = (1.0,)


@pytest.mark.parametrize("field, value", [("gain", "1.0"), ("gain", None), ("gain", True),
                                          ("gain", [1.0]), ("limit_s", "x")])  # fmt: skip
def test_number_fields_refuses_what_is_not_a_number_in_a_float_field_by_owner_and_name(
    field, value
):
    with pytest.raises(ParameterError, match=rf"^_Record: {field} must be a number, got"):
        number_fields(_Record(**{field: value}))
    with pytest.raises(ParameterError, match=rf"^probe: {field} must be a number"):
        number_fields(_Record(**{field: value}), "probe")


def test_number_fields_passes_numbers_an_optional_none_and_fields_of_other_types():
    number_fields(_Record(gain=2, limit_s=None, name="x", weights=("a",)))
    number_fields(_Record(gain=np.float32(0.5), limit_s=math.inf))  # finiteness: not its job


def _self_checking_dataclasses() -> list[type]:
    """Every dataclass of the package with a ``__post_init__`` (its own or inherited) that
    can be built from its defaults (or with "x" in the str fields that have none)."""
    found = {}
    for module in pkgutil.walk_packages(uvms_pin.__path__, "uvms_pin."):
        if any(
            part in module.name
            for part in ("viz", "_meshcat", "foxglove", "sb3", "__main__", "._core")
        ):
            continue
        for value in vars(importlib.import_module(module.name)).values():
            if (
                isinstance(value, type)
                and dataclasses.is_dataclass(value)
                and value.__module__ == module.name
                and hasattr(value, "__post_init__")
                and not inspect.isabstract(value)
            ):
                found[f"{value.__module__}.{value.__qualname__}"] = value
    return [found[name] for name in sorted(found)]


def _required(cls: type) -> dict[str, str] | None:
    required = {}
    for field in dataclasses.fields(cls):
        if not field.init or field.default is not dataclasses.MISSING:
            continue
        if field.default_factory is not dataclasses.MISSING:
            continue
        if field.type not in ("str", str):
            return None
        required[field.name] = "x"
    return required


def test_every_self_checking_dataclass_refuses_a_string_in_each_float_field_by_name():
    """A string where a number belongs (``RK4(step_s="1e-3")``, ``SensorConfig(
    sample_period_s="x")``) is a ParameterError naming the field, in every dataclass of the
    package that checks itself: before `number_fields`, a comparison's TypeError ('>' not
    supported between 'str' and 'float'), or the string kept until the run."""
    checked = 0
    for cls in _self_checking_dataclasses():
        required = _required(cls)
        if required is None:
            continue
        try:
            cls(**required)
        except ParameterError:
            continue  # needs more than its defaults to be valid
        for field in dataclasses.fields(cls):
            if not field.init or field.name in required or field.type not in ("float", float):
                continue
            with pytest.raises(ParameterError, match=field.name):
                cls(**required, **{field.name: "x"})
            checked += 1
    assert checked > 50  # the walk found the package's dataclasses
