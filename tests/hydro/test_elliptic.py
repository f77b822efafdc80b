"""Carlson's R_D (uvms_pin/hydro/elliptic.py) against scipy's implementation, its special
values and identity, and the prolate spheroid's shape integral in closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import elliprd

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.elliptic import carlson_rd
from uvms_pin.hydro.geometry import ellipsoid_shape_integrals


def test_rd_is_scipys_over_twelve_decades_and_with_one_argument_zero():
    rng = np.random.default_rng(0)
    args = 10.0 ** rng.uniform(-8.0, 4.0, (3000, 3))
    args[::10, 0] = 0.0  # x = 0: the complete integral
    args[5::10, 1] = 0.0
    ours = np.array([carlson_rd(*row) for row in args])
    np.testing.assert_allclose(ours, elliprd(*args.T), rtol=2e-15, atol=0.0)


def test_rd_of_equal_arguments_and_the_cyclic_sum():
    for x in (1e-6, 0.3, 1.0, 7.0, 1e5):
        assert carlson_rd(x, x, x) == pytest.approx(x**-1.5, rel=1e-15)
    x, y, z = 0.3, 1.7, 2.9  # R_D(y, z, x) + R_D(z, x, y) + R_D(x, y, z) = 3 / sqrt(x y z)
    total = carlson_rd(y, z, x) + carlson_rd(z, x, y) + carlson_rd(x, y, z)
    assert total == pytest.approx(3.0 / math.sqrt(x * y * z), rel=1e-15)


@pytest.mark.parametrize("ratio", [1.5, 3.0, 10.0, 100.0])
def test_a_prolate_spheroids_axial_integral_is_lambs_closed_form(ratio):
    """alpha0 = 2 (1 - e^2) / e^3 (artanh(e) - e) along the long axis (Lamb 1932, sec. 114)."""
    e = math.sqrt(1.0 - 1.0 / ratio**2)
    alpha0, beta0, gamma0 = ellipsoid_shape_integrals(ratio, 1.0, 1.0)
    expected = 2.0 * (1.0 - e * e) / e**3 * (math.atanh(e) - e)
    assert alpha0 == pytest.approx(expected, rel=1e-12)
    assert beta0 == pytest.approx(gamma0, rel=1e-15)  # the two short axes
    assert beta0 == pytest.approx(1.0 - 0.5 * expected, rel=1e-12)


@pytest.mark.parametrize(
    "args",
    [
        (-1.0, 1.0, 1.0),
        (0.0, 0.0, 1.0),
        (1.0, 1.0, 0.0),
        (math.nan, 1.0, 1.0),
        (1.0, math.inf, 1.0),
    ],
)
def test_rd_refuses_arguments_outside_its_domain(args):
    with pytest.raises(ParameterError, match="R_D needs finite"):
        carlson_rd(*args)
