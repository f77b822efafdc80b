"""Linear wave theory: dispersion, continuity, free-surface conditions, limits, decay."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.flow import AiryWave, wavenumber

G = 9.81


def _fd_gradient(flow, t, p, h=1e-6):
    grad = np.empty((3, 3))
    for j in range(3):
        dp = np.zeros(3)
        dp[j] = h
        grad[:, j] = (flow.velocity(t, p + dp)[0] - flow.velocity(t, p - dp)[0]) / (2 * h)
    return grad


@pytest.mark.parametrize("depth", [math.inf, 50.0, 8.0, 2.0])
@pytest.mark.parametrize("period", [2.0, 5.0, 12.0])
def test_dispersion_relation_holds(depth, period):
    w = 2 * math.pi / period
    k = wavenumber(w, depth)
    rhs = G * k * (1.0 if math.isinf(depth) else math.tanh(k * depth))
    assert rhs == pytest.approx(w * w, rel=1e-13)


def test_deep_and_shallow_water_limits():
    w = 2 * math.pi / 5.0
    assert wavenumber(w, 1e4) == pytest.approx(w * w / G, rel=1e-14)
    # shallow water: c = w / k -> sqrt(g d) as k d -> 0
    depth = 0.05
    w_long = 2 * math.pi / 60.0
    k = wavenumber(w_long, depth)
    assert k * depth < 0.02
    assert w_long / k == pytest.approx(math.sqrt(G * depth), rel=1e-4)


@pytest.mark.parametrize("depth", [math.inf, 10.0])
def test_continuity_irrotationality_and_gradient(depth):
    wave = AiryWave(0.4, 6.0, heading_rad=0.7, water_depth_m=depth, phase_rad=0.3)
    rng = np.random.default_rng(1)
    for _ in range(10):
        p = rng.uniform([-20, -20, -5], [20, 20, -0.5])
        t = rng.uniform(0, 20)
        grad = wave.velocity_gradient(t, p)[0]
        np.testing.assert_allclose(grad, _fd_gradient(wave, t, p), atol=1e-8)
        assert abs(np.trace(grad)) < 1e-14  # div u = 0
        np.testing.assert_allclose(grad, grad.T, atol=1e-14)  # curl u = 0


def test_local_acceleration_is_time_derivative():
    wave = AiryWave(0.3, 4.0, heading_rad=-1.0, water_depth_m=6.0)
    p, t, h = np.array([3.0, -2.0, -1.5]), 7.3, 1e-6
    fd = (wave.velocity(t + h, p) - wave.velocity(t - h, p)) / (2 * h)
    np.testing.assert_allclose(wave.local_acceleration(t, p), fd, atol=1e-8)


@pytest.mark.parametrize("depth", [math.inf, 5.0])
def test_linear_free_surface_conditions(depth):
    """Kinematic: d eta/dt = w at z = 0; dynamic (its x gradient): du/dt + g d eta/dx = 0."""
    wave = AiryWave(0.5, 5.0, heading_rad=0.0, water_depth_m=depth)
    h = 1e-6
    for x, t in [(0.0, 0.0), (3.7, 1.1), (-12.0, 8.4)]:
        xy = np.array([[x, 0.0]])
        deta_dt = (wave.surface_elevation(t + h, xy) - wave.surface_elevation(t - h, xy)) / (2 * h)
        w = wave.velocity(t, [x, 0.0, 0.0])[0, 2]
        assert deta_dt[0] == pytest.approx(w, abs=1e-8)
        deta_dx = (
            wave.surface_elevation(t, xy + np.array([h, 0]))
            - wave.surface_elevation(t, xy - np.array([h, 0]))
        ) / (2 * h)
        dudt = wave.local_acceleration(t, [x, 0.0, 0.0])[0, 0]
        assert dudt + G * deta_dx[0] == pytest.approx(0.0, abs=1e-7)


def test_sea_floor_is_impermeable():
    wave = AiryWave(0.5, 5.0, water_depth_m=4.0)
    for t in np.linspace(0, 5, 7):
        assert abs(wave.velocity(t, [1.3, 0.0, -4.0])[0, 2]) < 1e-14


def test_orbital_velocity_decays_as_theory():
    deep = AiryWave(0.5, 5.0)
    k = deep.wavenumber_rad_m
    speed = [np.linalg.norm(deep.velocity(0.0, [0, 0, z])[0]) for z in (0.0, -2.0, -6.0)]
    # deep water: circular orbits, |u| = A w e^{kz} at every phase
    w = 2 * math.pi / 5.0
    np.testing.assert_allclose(speed, [0.5 * w * math.exp(k * z) for z in (0.0, -2.0, -6.0)])
    finite = AiryWave(0.5, 5.0, water_depth_m=6.0)
    kf = finite.wavenumber_rad_m
    u0 = finite.velocity(0.0, [0, 0, 0.0])[0, 0]
    u3 = finite.velocity(0.0, [0, 0, -3.0])[0, 0]
    assert u3 / u0 == pytest.approx(math.cosh(kf * 3.0) / math.cosh(kf * 6.0), rel=1e-12)


def test_material_acceleration_follows_a_fluid_particle():
    """Du/Dt equals d/dt u(t, p(t)) along p_dot = u: the convective term is right."""
    wave = AiryWave(0.8, 4.0, heading_rad=0.4, water_depth_m=7.0)
    p, t, h = np.array([1.0, 2.0, -1.0]), 2.0, 1e-4

    def path(p0, t0, dt):  # RK4 on p_dot = u(t, p)
        f = lambda s, x: wave.velocity(s, x)[0]  # noqa: E731
        k1 = f(t0, p0)
        k2 = f(t0 + dt / 2, p0 + dt / 2 * k1)
        k3 = f(t0 + dt / 2, p0 + dt / 2 * k2)
        k4 = f(t0 + dt, p0 + dt * k3)
        return p0 + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)

    forward, backward = path(p, t, h), path(p, t, -h)
    fd = (wave.velocity(t + h, forward)[0] - wave.velocity(t - h, backward)[0]) / (2 * h)
    np.testing.assert_allclose(wave.acceleration(t, p)[0], fd, atol=1e-7)
    # and it differs from the local derivative by a visible second-order term
    assert np.linalg.norm(wave.acceleration(t, p) - wave.local_acceleration(t, p)) > 1e-2


def test_bad_parameters_are_refused():
    with pytest.raises(ParameterError, match="period_s"):
        AiryWave(0.5, 0.0)
    with pytest.raises(ParameterError, match="amplitude_m"):
        AiryWave(-1.0, 5.0)
    with pytest.raises(ParameterError, match="water_depth_m"):
        AiryWave(0.5, 5.0, water_depth_m=-3.0)
    with pytest.raises(ParameterError, match="points_world"):
        AiryWave(0.5, 5.0).velocity(0.0, np.zeros((2, 2)))
    # gravity 0 was a ZeroDivisionError, a negative or nan one a wave of nan; a string a
    # ValueError of float()
    for name, value in [("amplitude_m", math.nan), ("amplitude_m", math.inf),
                        ("heading_rad", math.inf), ("phase_rad", math.nan),
                        ("period_s", math.inf), ("gravity_m_s2", 0.0),
                        ("gravity_m_s2", -9.81), ("gravity_m_s2", math.nan),
                        ("amplitude_m", "0.5"), ("period_s", None), ("water_depth_m", "deep"),
                        ("heading_rad", [0.0])]:  # fmt: skip
        given = {"amplitude_m": 0.5, "period_s": 5.0, name: value}
        with pytest.raises(ParameterError, match=name):
            AiryWave(**given)


def test_a_wave_of_no_amplitude_is_still_water():
    """A = 0 is accepted (a sea state switched off): the surface stays at 0, the water still."""
    wave = AiryWave(0.0, 5.0)
    points = np.array([[0.0, 0.0, 0.0], [3.0, -1.0, -2.0]])
    assert np.all(wave.surface_elevation(1.3, points[:, :2]) == 0.0)
    assert np.all(wave.velocity(1.3, points) == 0.0)


@pytest.mark.parametrize("period_s", [4.0, 8.0, 12.0])
def test_wavelength_is_the_deep_water_one_and_shortens_in_shallow_water(period_s):
    """lambda = g T^2 / (2 pi) in deep water (1.56 T^2 m); in water of depth h it is
    2 pi / k with k from the dispersion relation, tending to T sqrt(g h) when h << lambda."""
    deep = AiryWave(0.1, period_s)
    assert deep.wavelength_m == pytest.approx(G * period_s**2 / (2.0 * math.pi), rel=1e-12)
    shallow = AiryWave(0.01, period_s, water_depth_m=0.5)
    assert shallow.wavelength_m < deep.wavelength_m
    assert shallow.wavelength_m == pytest.approx(period_s * math.sqrt(G * 0.5), rel=0.03)


def test_a_wave_steeper_than_one_in_seven_is_refused_naming_its_height_and_length():
    """Breaking (Michell's limit): a height 2 a over the wavelength above 1/7 is refused, one
    just below it accepted; the refusal gives the height and the wavelength (deep water at
    8 s: 99.92 m). Still water (depth 0) is no depth for a wave."""
    length_m = G * 8.0**2 / (2.0 * math.pi)
    AiryWave(0.99 * length_m / 14.0, 8.0)  # H / lambda = 0.99 / 7
    with pytest.raises(ParameterError, match=r"height .*14\.4\d* m over its wavelength 99\.9"):
        AiryWave(1.01 * length_m / 14.0, 8.0)
    with pytest.raises(ParameterError, match="water_depth_m"):
        AiryWave(0.5, 5.0, water_depth_m=0.0)


def test_by_default_a_wave_travels_along_x_with_its_crest_at_the_origin():
    """heading 0 and phase 0 unless given: eta = A cos(k x - w t), the orbital velocity in
    the x-z plane (none along y), the crest over the origin at t = 0."""
    wave = AiryWave(0.5, 5.0)
    k = wave.wavenumber_rad_m
    for t in (0.0, 1.3):
        for x, y in ((0.0, 0.0), (2.0, 0.0), (2.0, 7.0), (-3.0, -4.0)):
            eta = wave.surface_elevation(t, np.array([[x, y]]))[0]
            assert eta == pytest.approx(0.5 * math.cos(k * x - 2 * math.pi / 5.0 * t), abs=1e-12)
            assert abs(wave.velocity(t, [x, y, -1.0])[0, 1]) < 1e-15
