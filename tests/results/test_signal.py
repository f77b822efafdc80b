"""A signal's component names: identifiers, and the labels model names become."""

from __future__ import annotations

import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.results.signal import Signal, component_label


@pytest.mark.parametrize(
    ("name", "label"),
    [
        ("alpha_axis_e", "alpha_axis_e"),
        ("oberon7/finger_left_joint", "oberon7_finger_left_joint"),
        ("arm.joint-2", "arm_joint_2"),
        ("2nd_finger", "_2nd_finger"),
        ("_x", "_x"),
        ("fingér", "fing_r"),
    ],
)
def test_a_model_name_becomes_a_component_name_a_signal_takes(name, label):
    assert component_label(name) == label
    assert Signal([1.0], [component_label(name)]).components == (label,)


@pytest.mark.parametrize("names", [["a/b"], ["1a"], ["a", "a"], [""]])
def test_a_signal_refuses_what_is_no_identifier_or_repeated(names):
    with pytest.raises(ParameterError, match="distinct identifiers"):
        Signal([0.0] * len(names), names)


@pytest.mark.parametrize(
    ("values", "names", "unit"),
    [
        ([1.0, 2.0], ["a"], "N"),  # more values than names
        ([1.0], ["a", "b"], "N"),  # more names than values
        ([1.0, 2.0], ["a", "b"], ["N"]),  # one unit for two components
        ([[1.0, 2.0]], ["a", "b"], "N"),  # values not a vector
    ],
)
def test_a_signal_refuses_values_names_and_units_that_do_not_agree(values, names, unit):
    with pytest.raises(ParameterError, match="must agree"):
        Signal(values, names, unit)


def test_a_signal_keeps_one_unit_per_component():
    signal = Signal([1.0, 2.0], ["force", "torque"], ["N", "N m"])
    assert signal.units == ("N", "N m") and Signal([1.0, 2.0], ["a", "b"], "m").units == ("m", "m")
