"""The shipped scenarios' own controllers (``type = "module:Class"`` next to the scenario):
a parameter that is not a finite number is refused by name before the run starts, as the
built-in controllers' are (a gain of inf ran until its first tick, then stopped the run)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest

import uvms_pin as up
from uvms_pin.errors import ParameterError, ScenarioError

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def _own_controllers() -> list[tuple[str, str, str]]:
    """(scenario file, the controller table's override prefix, a numeric key) of every
    shipped scenario whose controller is its own class."""
    cases = []
    for path in sorted(SCENARIOS.glob("*.toml")):
        raw = tomllib.loads(path.read_text())
        tables = [("controller", raw.get("controller", {}))]
        tables += [(f"robots[{k}].controller", r.get("controller", {}))
                   for k, r in enumerate(raw.get("robots", []))]  # fmt: skip
        for prefix, table in tables:
            if ":" not in str(table.get("type", "")):
                continue
            cases += [(path.name, prefix, key) for key, v in table.items() if _numeric(v)]
    return cases


def _numeric(value) -> bool:
    """A number, or a non-empty (nested) list of numbers (waypoints: lists of points)."""
    if isinstance(value, list):
        return bool(value) and all(_numeric(x) for x in value)
    return isinstance(value, int | float) and not isinstance(value, bool)


CASES = _own_controllers()
#: the parameters whose inf means "never" (the jaw opens at inf: it stays closed)
NEVER = {("object_recovery.toml", "jaw_open_at_s")}


def test_every_scenario_controller_is_found():
    assert {name for name, _, _ in CASES} >= {
        "cooperative_transport.toml", "gripper_close.toml", "hot_stab.toml",
        "object_recovery.toml", "push_object.toml", "seabed_landing.toml", "valve_turn.toml",
        "visual_approach.toml",
    }  # fmt: skip


def _value_with(value, bad: float):
    """``value`` with its first number (the first of the first point's, when nested) bad."""
    return [_value_with(value[0], bad), *value[1:]] if isinstance(value, list) else bad


@pytest.mark.parametrize("bad", [math.inf, -math.inf, math.nan])
@pytest.mark.parametrize("name, prefix, key", CASES)
def test_a_non_finite_parameter_is_refused_by_name_before_the_run(name, prefix, key, bad):
    path = SCENARIOS / name
    raw = tomllib.loads(path.read_text())
    table = raw["controller"] if prefix == "controller" else raw["robots"][
        int(prefix[len("robots[") : prefix.index("]")])
    ]["controller"]  # fmt: skip
    overrides = {f"{prefix}.{key}": _value_with(table[key], bad), "scenario.duration_s": 0.2}
    if bad == math.inf and (name, key) in NEVER:
        rollout = up.simulate(up.load_scenario(path, overrides=overrides), progress=False)
        assert rollout.time_s[-1] == pytest.approx(0.2)  # it means never, and runs
        return
    with pytest.raises((ParameterError, ScenarioError), match=f"{key} must be"):
        up.simulate(up.load_scenario(path, overrides=overrides), progress=False)


def test_a_baselines_table_must_name_another_built_in_baseline_or_give_its_type(tmp_path):
    """[baselines.<name>] tunes a baseline compare-controllers runs beside the scenario's
    controller: a misspelt name (``impedence``) and the scenario's own controller type
    (``ppc``) are refused naming the table, before any run; a table with its own ``type``
    is a named variant of any name."""
    from uvms_pin.scenario.load import load_scenario

    text = (SCENARIOS / "realistic_force_tracking.toml").read_text()
    text = text.replace('"../models/', f'"{SCENARIOS.parent}/models/')
    for name in ("impedence", "ppc"):
        path = tmp_path / f"{name}.toml"
        path.write_text(text + f"\n[baselines.{name}]\ndamping = 3.0\n")
        with pytest.raises(ScenarioError, match=rf"\[baselines\.{name}\]: a baseline is one of"):
            load_scenario(path)
    variant = tmp_path / "variant.toml"
    variant.write_text(text + '\n[baselines.soft_impedance]\ntype = "impedance"\n')
    assert load_scenario(variant).controller_factory is not None
