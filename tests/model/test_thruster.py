"""A thruster (`uvms_pin.model.thruster.Thruster`): its direction made a unit vector, its
wrench column [d; r x d], its limits finite and non-negative."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.model.thruster import Thruster


def test_a_direction_is_normalised_and_the_wrench_column_is_d_and_r_cross_d():
    thruster = Thruster("t", [0.2, -0.1, 0.05], [0.0, 3.0, 4.0], 40.0, 30.0)
    np.testing.assert_allclose(thruster.direction_body, [0.0, 0.6, 0.8], rtol=0, atol=1e-16)
    np.testing.assert_allclose(
        thruster.wrench_column,
        [0.0, 0.6, 0.8, -0.1 * 0.8 - 0.05 * 0.6, -0.2 * 0.8, 0.2 * 0.6],
        rtol=0,
        atol=1e-16,
    )


@pytest.mark.parametrize(
    "given, match",
    [
        ({"direction_body": [0.0, 0.0, 0.0]}, "direction must be non-zero"),
        ({"direction_body": [1.0, math.nan, 0.0]}, "position and direction need 3 finite numbers"),
        ({"position_body_m": [1.0, 2.0]}, "position and direction need 3 finite numbers"),
        ({"max_forward_N": -1.0}, "max_forward_N must be finite and >= 0, got -1.0"),
        ({"max_forward_N": math.inf}, "max_forward_N must be finite and >= 0, got inf"),
        ({"max_reverse_N": math.nan}, "max_reverse_N must be finite and >= 0, got nan"),
    ],
)
def test_a_bad_thruster_is_refused_by_name(given, match):
    values = {"position_body_m": [0.0, 0.0, 0.0], "direction_body": [1.0, 0.0, 0.0],
              "max_forward_N": 40.0, "max_reverse_N": 30.0, **given}  # fmt: skip
    with pytest.raises(ParameterError, match=rf"thruster 't': {match}"):
        Thruster("t", **values)
