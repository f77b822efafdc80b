"""Irregular seas, Gauss-Markov and sheared currents, superposition."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import welch

from uvms_pin.errors import ParameterError
from uvms_pin.flow import (
    AiryWave,
    DepthProfileCurrent,
    GaussMarkovCurrent,
    IrregularSea,
    UniformCurrent,
    jonswap_spectrum,
    pierson_moskowitz_spectrum,
)


@pytest.mark.parametrize("gamma", [1.0, 3.3, 7.0])
def test_spectrum_carries_the_requested_significant_height(gamma):
    w = np.linspace(0.01, 30.0, 300001)
    s = jonswap_spectrum(w, 2.0, 8.0, gamma)
    m0 = np.trapezoid(s, w)
    assert 4.0 * math.sqrt(m0) == pytest.approx(2.0, rel=1e-4)
    assert w[np.argmax(s)] == pytest.approx(2 * math.pi / 8.0, rel=1e-3)


def test_jonswap_with_gamma_one_is_pierson_moskowitz():
    w = np.linspace(0.2, 4.0, 50)
    np.testing.assert_array_equal(
        jonswap_spectrum(w, 1.0, 6.0, 1.0), pierson_moskowitz_spectrum(w, 1.0, 6.0)
    )


def test_irregular_sea_reproduces_hs_and_tp_in_a_record():
    """A 3-hour record at one point: Hs = 4 std(eta) and the periodogram's peak period."""
    sea = IrregularSea(0.5, 5.0, peak_enhancement=3.3, n_components=200, seed=4)
    assert sea.components_significant_height_m == pytest.approx(0.5, rel=0.02)
    fs = 4.0
    t = np.arange(0.0, 3 * 3600.0, 1.0 / fs)
    # vectorised over time: one point, many times
    c = sea.components
    eta = np.cos(np.outer(-t, c.angular_frequency_rad_s) + c.phase_rad) @ c.amplitude_m
    assert 4.0 * np.std(eta) == pytest.approx(0.5, rel=0.05)
    f, p = welch(eta, fs=fs, nperseg=8192)
    assert 1.0 / f[np.argmax(p)] == pytest.approx(5.0, rel=0.06)
    # the record from surface_elevation agrees with the vectorised one
    assert sea.surface_elevation(t[123], [[0.0, 0.0]])[0] == pytest.approx(eta[123], abs=1e-12)


def test_irregular_sea_is_seeded_and_spread():
    a = IrregularSea(1.0, 6.0, seed=3, spreading_exponent=4.0)
    b = IrregularSea(1.0, 6.0, seed=3, spreading_exponent=4.0)
    c = IrregularSea(1.0, 6.0, seed=4, spreading_exponent=4.0)
    p = np.array([[1.0, 2.0, -3.0]])
    np.testing.assert_array_equal(a.velocity(1.0, p), b.velocity(1.0, p))
    assert not np.allclose(a.velocity(1.0, p), c.velocity(1.0, p))
    headings = a.components.heading_rad
    assert np.std(headings) > 0.1  # spread
    assert abs(np.mean(headings)) < 0.3  # around the mean heading
    long_crested = IrregularSea(1.0, 6.0, seed=3, heading_rad=0.5)
    assert np.all(long_crested.components.heading_rad == 0.5)


def test_superposition_adds_velocities_and_forms_material_acceleration_from_the_sum():
    wave = AiryWave(0.5, 5.0, water_depth_m=20.0)
    current = UniformCurrent([0.3, -0.1, 0.0])
    flow = wave + current
    p = np.array([[2.0, 1.0, -2.0]])
    np.testing.assert_allclose(
        flow.velocity(1.0, p), wave.velocity(1.0, p) + np.array([0.3, -0.1, 0.0])
    )
    # the current convects the wave's velocity field: (grad u) U is in Du/Dt of the sum
    expected = wave.acceleration(1.0, p) + wave.velocity_gradient(1.0, p)[0] @ [0.3, -0.1, 0.0]
    np.testing.assert_allclose(flow.acceleration(1.0, p), expected, atol=1e-14)


def test_gauss_markov_current_is_seeded_bounded_smooth_and_order_independent():
    gm = GaussMarkovCurrent(
        [0.2, 0.0, 0.0], std_m_s=0.1, time_constant_s=20.0, bound_m_s=0.15, seed=7
    )
    times = np.linspace(0.0, 2000.0, 4001)
    v = np.array([gm.velocity(t, [0, 0, 0])[0] for t in times])
    assert np.all(np.abs(v - [0.2, 0.0, 0.0]) <= 0.15 + 1e-12)
    assert 0.05 < np.std(v[:, 1]) < 0.15
    other = GaussMarkovCurrent(
        [0.2, 0.0, 0.0], std_m_s=0.1, time_constant_s=20.0, bound_m_s=0.15, seed=7
    )
    np.testing.assert_array_equal(other.velocity(1500.0, [0, 0, 0]), gm.velocity(1500.0, [0, 0, 0]))
    h = 1e-5
    for t in (0.3, 17.77, 999.1):
        fd = (gm.velocity(t + h, [0, 0, 0]) - gm.velocity(t - h, [0, 0, 0])) / (2 * h)
        np.testing.assert_allclose(gm.acceleration(t, [0, 0, 0]), fd, atol=1e-8)
    with pytest.raises(ParameterError, match="t >= 0"):
        gm.velocity(-1.0, [0, 0, 0])


def test_depth_profile_current():
    shear = DepthProfileCurrent([0.5, 0.0, 0.0], depths_m=[0.0, 10.0], factors=[1.0, 0.2])
    np.testing.assert_allclose(shear.velocity(0.0, [[0, 0, -5.0]]), [[0.3, 0.0, 0.0]])
    np.testing.assert_allclose(shear.velocity(0.0, [[0, 0, -50.0]]), [[0.1, 0.0, 0.0]])
    grad = shear.velocity_gradient(0.0, [[0, 0, -5.0]])[0]
    assert grad[0, 2] == pytest.approx(0.5 * 0.08)  # du/dz = U * 0.8 / 10
    np.testing.assert_allclose(shear.acceleration(0.0, [[0, 0, -5.0]]), 0.0)  # steady, horizontal
    law = DepthProfileCurrent.power_law([1.0, 0, 0], seabed_depth_m=20.0)
    assert law.velocity(0.0, [[0, 0, 0.0]])[0, 0] == pytest.approx(1.0)
    assert law.velocity(0.0, [[0, 0, -20.0]])[0, 0] == pytest.approx(0.0)
    with pytest.raises(ParameterError, match="increasing"):
        DepthProfileCurrent([1, 0, 0], [0.0, 0.0], [1, 1])


@pytest.mark.parametrize("n", [0, 2001, 10_000_000, 2.5, True])
def test_a_sea_has_a_bounded_number_of_components(n):
    """Refused before anything is drawn: 1e7 components took GBs and minutes (deaf to Ctrl-C)."""
    with pytest.raises(ParameterError, match=r"n_components must be an integer in 1\.\.2000"):
        IrregularSea(0.5, 5.0, n_components=n)
    assert IrregularSea(0.5, 5.0, n_components=2000).components.amplitude_m.size == 2000
