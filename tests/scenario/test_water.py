"""``[water]``'s flows come from one registry (`uvms_pin.scenario.water.FLOWS`): each table
builds the field of its kind, the fields summed in the registry's order."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.errors import ScenarioError
from uvms_pin.flow import (
    AiryWave,
    DepthProfileCurrent,
    GaussMarkovCurrent,
    IrregularSea,
    SumFlow,
    UniformCurrent,
)
from uvms_pin.scenario.schema import Table
from uvms_pin.scenario.water import FLOWS, build_water


def _water(data: dict):
    return build_water(Table(data, "water", "s.toml"), seed=5)


def test_every_table_of_the_registry_is_read_and_summed_in_its_order():
    assert list(FLOWS) == ["current", "waves", "sea"]
    water = _water(
        {
            "current": {"type": "gauss_markov", "mean_velocity_world_m_s": [0.2, 0, 0],
                        "std_m_s": 0.05, "time_constant_s": 20.0, "bound_m_s": 0.3},
            "waves": {"amplitude_m": 0.1, "period_s": 8.0},
            "sea": {"significant_height_m": 0.5, "peak_period_s": 7.0, "n_components": 8},
        }
    )  # fmt: skip
    assert isinstance(water.flow, SumFlow)
    kinds = [type(f) for f in water.flow.fields]
    assert kinds == [GaussMarkovCurrent, AiryWave, IrregularSea]
    assert isinstance(_water({"current": {"velocity_world_m_s": [0.1, 0, 0]}}).flow, UniformCurrent)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"current": {"type": "vortex"}}, r"water\.current\.type.*one of uniform, gauss_markov"),
        ({"waves": {"type": "airy", "amplitude_m": 0.1, "period_s": 8.0}}, r"unknown key.*type"),
        ({"waves": {"amplitude_m": 0.1}}, r"water\.waves\.period_s.*required"),
    ],
)
def test_a_flow_table_is_checked_naming_its_key(data, message):
    with pytest.raises(ScenarioError, match=message):
        _water(data)


def test_a_sea_of_one_component_is_read_and_none_refused_naming_the_key():
    sea = {"significant_height_m": 0.5, "peak_period_s": 7.0}
    one = _water({"sea": {**sea, "n_components": 1}}).flow
    assert isinstance(one, IrregularSea) and one.components.amplitude_m.size == 1
    with pytest.raises(ScenarioError, match=r"water\.sea\.n_components"):
        _water({"sea": {**sea, "n_components": 0}})


def test_a_depth_profile_current_is_read_from_its_table():
    """`type = "profile"`: the velocity where the factor is 1, scaled by the factor at each
    depth (linear between the depths, constant beyond)."""
    table = {"type": "profile", "velocity_world_m_s": [0.4, 0.1, 0.0],
             "depths_m": [0.0, 10.0, 30.0], "factors": [1.0, 0.5, 0.0]}  # fmt: skip
    flow = _water({"current": table}).flow
    assert isinstance(flow, DepthProfileCurrent)
    points = np.array([[0.0, 0.0, 0.0], [3.0, 1.0, -5.0], [0.0, 0.0, -20.0], [0.0, 0.0, -50.0]])
    expected = np.outer([1.0, 0.75, 0.25, 0.0], [0.4, 0.1, 0.0])
    np.testing.assert_allclose(flow.velocity(0.0, points), expected, atol=1e-15)
    with pytest.raises(ScenarioError, match=r"water\.current.*velocity_world_m_s"):
        _water({"current": {**table, "velocity_world_m_s": [0.4, 0.1]}})
