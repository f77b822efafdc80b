"""The derivatives of linear wave components (`uvms_pin.flow.components.WaveComponents`) that
the dynamics' derivatives use: the gradient of the local acceleration, the Hessian of the
velocity and the free surface's rate and slope, each against central differences of the
quantity it differentiates (step h, error O(h^2); tolerances 1e-6 of the term's scale).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.flow import AiryWave, IrregularSea

SEAS = {
    "deep airy": AiryWave(0.4, 6.0, heading_rad=0.7, phase_rad=0.3),
    "shallow airy": AiryWave(0.2, 7.0, heading_rad=-1.1, water_depth_m=6.0),
    "irregular": IrregularSea(0.8, 7.0, n_components=9, seed=4, water_depth_m=30.0),
}
TIME_S = 3.3
POINTS = np.array([[0.3, -1.2, -0.5], [4.0, 2.5, -2.0], [-3.0, 1.0, -4.5]])


def _central(f, x, h):
    """d f / d x_l by central differences: (..., len(x)) stacked on the last axis."""
    return np.stack([(f(x + h * e) - f(x - h * e)) / (2.0 * h) for e in np.eye(len(x))], axis=-1)


@pytest.mark.parametrize("name", SEAS)
def test_gradient_kinematics_are_the_space_derivatives_of_acceleration_and_gradient(name):
    """grad du/dt [i, j] = d (du_i/dt) / d x_j and Hessian [i, j, l] = d (grad u)_ij / d x_l
    (h = 1e-4 m); the Hessian is symmetric in its last two indices, grad du/dt symmetric
    (the flow is irrotational)."""
    components = SEAS[name].components
    grad_rate, hessian = components.gradient_kinematics(TIME_S, POINTS)
    h = 1e-4
    for n, point in enumerate(POINTS):
        fd_rate = _central(lambda p: components.local_acceleration(TIME_S, p[None])[0], point, h)
        fd_hessian = _central(lambda p: components.velocity_gradient(TIME_S, p[None])[0], point, h)
        np.testing.assert_allclose(grad_rate[n], fd_rate, atol=1e-6 * np.abs(fd_rate).max())
        np.testing.assert_allclose(hessian[n], fd_hessian, atol=1e-6 * np.abs(fd_hessian).max())
        np.testing.assert_allclose(grad_rate[n], grad_rate[n].T, atol=1e-14)
        np.testing.assert_allclose(hessian[n], hessian[n].transpose(0, 2, 1), atol=1e-14)


@pytest.mark.parametrize("name", SEAS)
def test_surface_kinematics_are_the_rate_and_slope_of_the_elevation(name):
    """(eta, d eta/dt, grad eta) at horizontal points: eta is the surface elevation, d eta/dt
    its central difference in time (h = 1e-5 s), grad eta in x and y (h = 1e-5 m); the
    elevation never exceeds the bound sum |A|."""
    sea = SEAS[name]
    xy = POINTS[:, :2]
    eta, rate, slope = sea.surface_kinematics(TIME_S, xy)
    np.testing.assert_allclose(eta, sea.surface_elevation(TIME_S, xy), rtol=1e-14, atol=1e-15)
    h = 1e-5
    fd_rate = (sea.surface_elevation(TIME_S + h, xy) - sea.surface_elevation(TIME_S - h, xy)) / (
        2 * h
    )
    np.testing.assert_allclose(rate, fd_rate, atol=1e-7 * np.abs(fd_rate).max())
    for n, point in enumerate(xy):
        fd_slope = _central(lambda p: sea.surface_elevation(TIME_S, p[None])[0], point, h)
        np.testing.assert_allclose(slope[n], fd_slope, atol=1e-7 * np.abs(fd_slope).max())
    amplitudes = sea.components.amplitude_m
    assert sea.elevation_bound_m == pytest.approx(float(np.sum(np.abs(amplitudes))), rel=1e-15)
    grid = np.stack(np.meshgrid(np.linspace(-20, 20, 41), np.linspace(-20, 20, 41)), -1)
    times = np.linspace(0.0, 20.0, 9)
    worst = max(np.abs(sea.surface_elevation(t, grid.reshape(-1, 2))).max() for t in times)
    assert worst <= sea.elevation_bound_m
    if len(amplitudes) == 1:  # one wave reaches its amplitude somewhere
        assert worst == pytest.approx(amplitudes[0], rel=0.05)
    assert math.isfinite(worst)
