"""uvms_pin/checks.py: `finite_parameters`, what a controller's constructor calls with its
``locals()``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.checks import finite_parameters, nonnegative, positive
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
