"""The one reader of TOML tables (scenarios and studies): types, ranges, names in messages."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.errors import ScenarioError, StudyError
from uvms_pin.scenario.schema import Table


def test_values_are_read_checked_and_defaulted():
    t = Table({"k": 2, "v": [1, 2.5, 3], "s": "rk4", "b": False, "n": 4}, "integrator", "s.toml")
    assert t.number("k", positive=True) == 2.0 and isinstance(t.number("missing", 1.5), float)
    np.testing.assert_array_equal(t.vector("v", 3), [1.0, 2.5, 3.0])
    assert t.string("s", choices=("rk4", "lsoda")) == "rk4"
    assert t.boolean("b", True) is False and t.integer("n", minimum=1) == 4
    t.finish()  # everything read


@pytest.mark.parametrize(
    ("data", "read", "message"),
    [
        (
            {"k": -1.0},
            lambda t: t.number("k", positive=True),
            "s.toml: water.k: must be positive, got -1.0",
        ),
        ({"k": True}, lambda t: t.number("k"), "water.k: must be a finite number, got True"),
        ({"k": float("nan")}, lambda t: t.number("k"), "water.k: must be a finite number"),
        ({"v": [1, 2]}, lambda t: t.vector("v", 3), "water.v: needs 3 numbers, got 2"),
        ({"v": [1, "a", 3]}, lambda t: t.vector("v", 3), "water.v: must be a list of numbers"),
        (
            {"s": "x"},
            lambda t: t.string("s", choices=("a", "b")),
            "water.s: must be one of a, b, got 'x'",
        ),
        ({"b": 1}, lambda t: t.boolean("b", True), "water.b: must be true or false, got 1"),
        ({"n": 0}, lambda t: t.integer("n", minimum=1), "water.n: must be >= 1, got 0"),
        ({}, lambda t: t.number("k"), "water.k: is required"),
        (
            {"seed": -5},
            lambda t: t.seed("seed", 0),
            "water.seed: must be an integer in [0, 2^63 - 1], got -5",
        ),
        (
            {"seed": 2**63},
            lambda t: t.seed("seed", 0),
            "water.seed: must be an integer in [0, 2^63 - 1]",
        ),
        ({"seed": 1.0}, lambda t: t.seed("seed", 0), "water.seed: must be an integer, got 1.0"),
        ({"e": 3}, lambda t: t.tables("e"), "water.e: must be an array of tables"),
    ],
)
def test_a_bad_value_names_the_file_and_the_key(data, read, message):
    with pytest.raises(ScenarioError) as info:
        read(Table(data, "water", "s.toml"))
    assert message in str(info.value)


def test_unknown_keys_are_named_with_the_closest_known_one():
    t = Table({"densty_kg_m3": 1000.0}, "water", "s.toml")
    t.number("density_kg_m3", 1025.0)
    with pytest.raises(ScenarioError, match=r"\[water\] has unknown key\(s\): densty_kg_m3 "
                       r"\(did you mean 'densty_kg_m3' -> 'density_kg_m3'\?\)"):  # fmt: skip
        t.finish()


def test_an_override_is_named_instead_of_the_file():
    overridden = {"water.waves.period_s": "water.waves.period_s=-4"}
    top = Table({"water": {"waves": {"period_s": -4}}}, "", "s.toml", overridden)
    waves = top.table("water").table("waves")
    with pytest.raises(
        ScenarioError, match=r"override 'water\.waves\.period_s=-4': must be positive"
    ):
        waves.number("period_s", positive=True)


def test_a_study_entry_is_named_by_its_label_and_its_error_type():
    t = Table({"apply": "twice"}, "parameter[2]", "st.toml", error=StudyError)
    t.label = "parameter[2] 'controller.k_x'"
    with pytest.raises(
        StudyError, match=r"st.toml: parameter\[2\] 'controller.k_x': apply: must be"
    ):
        t.string("apply", "set", ("set", "scale", "add"))
    with pytest.raises(StudyError, match=r"parameter\[2\] 'controller.k_x' has unknown key\(s\)"):
        Table({"x": 1}, "parameter[2]", "st.toml", error=StudyError, label=t.label).finish()
