"""A flow field saved with a rollout (its record, as JSON) is rebuilt as the same field."""

from __future__ import annotations

import json

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.flow import (
    AiryWave,
    DepthProfileCurrent,
    FlowField,
    GaussMarkovCurrent,
    IrregularSea,
    UniformCurrent,
    flow_from_record,
)

FIELDS = {
    "uniform": UniformCurrent([0.2, -0.1, 0.05]),
    "airy": AiryWave(0.4, 6.0, heading_rad=0.3, water_depth_m=25.0, phase_rad=1.0),
    "sea": IrregularSea(1.2, 7.0, n_components=40, seed=11, spreading_exponent=4.0),
    "gauss_markov": GaussMarkovCurrent([0.1, 0.2, 0.0], 0.05, 8.0, 0.1, seed=4),
    "profile": DepthProfileCurrent.power_law([0.5, 0.0, 0.0], 30.0),
    "sum": UniformCurrent([0.1, 0, 0])
    + AiryWave(0.2, 5.0)
    + GaussMarkovCurrent([0, 0, 0], 0.02, 3.0, 0.05),
}


@pytest.mark.parametrize("name", FIELDS)
def test_a_record_rebuilds_the_same_field(name):
    field = FIELDS[name]
    rebuilt = flow_from_record(json.loads(json.dumps(field.record())))
    points = np.array([[0.0, 0.0, -1.0], [3.0, -2.0, -6.5], [10.0, 4.0, -20.0]])
    for t in (0.0, 2.3, 17.0):
        np.testing.assert_allclose(
            rebuilt.velocity(t, points), field.velocity(t, points), rtol=1e-14, atol=1e-15
        )
        np.testing.assert_allclose(
            rebuilt.acceleration(t, points), field.acceleration(t, points), rtol=1e-13, atol=1e-15
        )
        np.testing.assert_allclose(
            rebuilt.surface_elevation(t, points[:, :2]),
            field.surface_elevation(t, points[:, :2]),
            rtol=1e-14,
            atol=1e-15,
        )
    assert rebuilt.has_free_surface == field.has_free_surface


class Vortex(FlowField):
    """A flow defined outside uvms-pin."""

    def velocity(self, time_s, points_world):
        return np.zeros((len(points_world), 3))

    def local_acceleration(self, time_s, points_world):
        return np.zeros((len(points_world), 3))

    def velocity_gradient(self, time_s, points_world):
        return np.zeros((len(points_world), 3, 3))


def test_a_field_from_elsewhere_records_what_it_is_and_cannot_be_rebuilt():
    record = Vortex().record()
    assert record["type"] == "Vortex" and "Vortex" in record["repr"]
    with pytest.raises(ParameterError, match="cannot rebuild the flow"):
        flow_from_record(record)
    with pytest.raises(ParameterError, match="malformed flow record of type 'uniform_current'"):
        flow_from_record({"type": "uniform_current"})
    assert flow_from_record(None) is None
