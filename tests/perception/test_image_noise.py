"""The images' Gaussian noise: a standard normal in 65,536 equiprobable levels, seeded."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import ndtr

from uvms_pin.errors import ParameterError
from uvms_pin.perception.image_noise import (
    LEVELS,
    normal_codes,
    normal_levels,
    standard_normal_f32,
)


def test_the_levels_are_the_normal_quantiles_at_unit_variance():
    z = normal_levels().astype(float)
    assert z.shape == (LEVELS,) and z.dtype == float
    assert np.all(np.diff(z) > 0.0)
    np.testing.assert_allclose(z, -z[::-1], atol=1e-6)  # symmetric about 0
    assert np.mean(z * z) == pytest.approx(1.0, abs=1e-6)
    # level k stands for the probability (k + 1/2) / 65536 of N(0, 1): to 5e-6, the scaling
    # to unit variance (z times 1.000005) moving it by at most 2.5e-6
    np.testing.assert_allclose(ndtr(z), (np.arange(LEVELS) + 0.5) / LEVELS, rtol=0, atol=5e-6)
    assert 4.3 < z.max() < 4.35
    assert not normal_levels().flags.writeable


def test_the_draws_are_standard_normal():
    draws = standard_normal_f32(np.random.default_rng(7), (1000, 1000)).astype(float).ravel()
    n = draws.size
    assert abs(draws.mean()) < 5.0 / np.sqrt(n)
    assert draws.std() == pytest.approx(1.0, abs=5e-3)
    for k, inside in ((1.0, 0.682689), (2.0, 0.954500), (3.0, 0.997300)):
        assert np.mean(np.abs(draws) < k) == pytest.approx(inside, abs=2e-3)
    excess = np.mean(draws**4) - 3.0  # kurtosis: a normal's fourth moment is 3
    assert abs(excess) < 0.03
    # no correlation between neighbours
    assert abs(np.mean(draws[1:] * draws[:-1])) < 5.0 / np.sqrt(n)


def test_the_same_seed_gives_the_same_draws_written_in_place():
    first = standard_normal_f32(np.random.default_rng(3), (31, 41, 3))
    out = np.empty((31, 41, 3), dtype=np.float32)
    second = standard_normal_f32(np.random.default_rng(3), (31, 41, 3), out=out)
    assert second is out
    np.testing.assert_array_equal(first, second)
    assert not np.array_equal(first, standard_normal_f32(np.random.default_rng(4), (31, 41, 3)))


@pytest.mark.parametrize(
    "out",
    [
        np.empty((4, 3), np.float64),
        np.empty((3, 4), np.float32),
        np.empty((3, 8), np.float32)[:, ::2],
    ],
)
def test_an_output_of_the_wrong_kind_is_refused(out):
    with pytest.raises(ParameterError, match="C-contiguous float32"):
        standard_normal_f32(np.random.default_rng(0), (4, 3), out=out)


@pytest.mark.parametrize("sizes", [(230400, 8, 12), (6, 8, 7, 12), (3, 5, 230400)])
def test_the_codes_are_numpys_integers_and_leave_the_generator_as_they_do(sizes):
    """`normal_codes` reads PCG64's raw outputs when that gives numpy's own 16-bit integers
    (a multiple of 4, no 32-bit half kept): the same codes in any sequence of sizes, the
    generator left in the same state."""
    ours, numpys = np.random.default_rng(11), np.random.default_rng(11)
    for size in sizes:
        codes = normal_codes(ours, size)
        assert codes.dtype == np.uint16 and codes.shape == (size,)
        np.testing.assert_array_equal(codes, numpys.integers(0, LEVELS, size, np.uint16))
        # the same state (a 32-bit half numpy keeps but will not use aside)
        state, expected = ours.bit_generator.state, numpys.bit_generator.state
        assert state["has_uint32"] == expected["has_uint32"]
        if not state["has_uint32"]:
            state["uinteger"] = expected["uinteger"]
        assert state == expected
    for draw in (lambda g: g.random(3), lambda g: g.integers(0, 7, 5, np.uint32)):
        np.testing.assert_array_equal(draw(ours), draw(numpys))
    other = np.random.Generator(np.random.MT19937(5))  # not PCG64: numpy's integers
    np.testing.assert_array_equal(
        normal_codes(other, 8),
        np.random.Generator(np.random.MT19937(5)).integers(0, LEVELS, 8, np.uint16),
    )
