"""Depth from pressure, DVL bottom lock, USBL latency and dropouts."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.sim.navigation.depth import DepthSensor
from uvms_pin.sim.navigation.dvl import Dvl, DvlSpec
from uvms_pin.sim.navigation.seabed import FlatSeabed
from uvms_pin.sim.navigation.usbl import Usbl, UsblSpec


def test_depth_from_pressure_is_unbiased_with_the_pressure_noise_in_metres():
    sensor = DepthSensor(100.0, 1025.0, np.random.default_rng(0))
    readings = np.array([sensor.measure(np.array([0.0, 0.0, -12.0])) for _ in range(20_000)])
    sigma = 100.0 / (1025.0 * 9.81)
    assert abs(readings.mean() - 12.0) < 4 * sigma / np.sqrt(readings.size)
    assert readings.std() == pytest.approx(sigma, rel=0.03)
    assert DepthSensor(0.0, 1025.0, np.random.default_rng(0)).measure(
        np.array([0, 0, -3.5])
    ) == pytest.approx(3.5, rel=1e-14)


def test_dvl_locks_only_within_its_altitudes_and_measures_the_body_velocity():
    dvl = Dvl(
        DvlSpec(noise_m_s=0.01, min_altitude_m=0.5, max_altitude_m=30.0),
        FlatSeabed(40.0),
        np.random.default_rng(1),
    )
    velocity = np.array([0.3, -0.1, 0.05])
    for depth, locked in ((39.8, 0.0), (35.0, 1.0), (5.0, 0.0)):
        out = dvl.measure(np.array([0.0, 0.0, -depth]), velocity)
        assert out[4] == locked
        assert out[3] == pytest.approx(40.0 - depth, rel=1e-14)
    samples = np.array(
        [dvl.measure(np.array([0.0, 0.0, -20.0]), velocity)[:3] for _ in range(5000)]
    )
    np.testing.assert_allclose(samples.mean(axis=0), velocity, atol=4 * 0.01 / np.sqrt(5000))
    np.testing.assert_allclose(samples.std(axis=0), 0.01, rtol=0.05)


def test_dvl_dropouts_happen_at_their_rate():
    dvl = Dvl(DvlSpec(dropout_probability=0.2), FlatSeabed(40.0), np.random.default_rng(2))
    locks = np.array(
        [dvl.measure(np.array([0.0, 0.0, -20.0]), np.zeros(3))[4] for _ in range(10_000)]
    )
    lost = 1.0 - locks.mean()
    assert abs(lost - 0.2) < 4 * np.sqrt(0.2 * 0.8 / locks.size)


def test_usbl_fix_arrives_after_its_latency_with_the_position_when_taken():
    usbl = Usbl(UsblSpec(period_s=1.0, latency_s=0.3), np.random.default_rng(3))
    dt, out = 0.01, []
    for k in range(300):
        t = k * dt
        out.append(usbl.measure(t, np.array([t, 0.0, -5.0])))  # moving at 1 m/s along x
    out = np.array(out)
    arrivals = np.flatnonzero(out[:, 4])
    np.testing.assert_allclose(arrivals * dt, [0.3, 1.3, 2.3], atol=1e-12)
    for k in arrivals:
        assert out[k, 0] == pytest.approx(k * dt - 0.3, abs=1e-12)  # where it was when pinged
        assert out[k, 3] == pytest.approx(0.3, abs=1e-12)
    assert np.all(out[: arrivals[0], 3] == -1.0)  # no fix yet
    # between arrivals the newest fix is held and ages
    assert out[arrivals[0] + 10, 3] == pytest.approx(0.4, abs=1e-12)


def test_usbl_dropouts_lose_their_share_of_pings():
    usbl = Usbl(UsblSpec(period_s=0.1, dropout_probability=0.3), np.random.default_rng(4))
    arrivals = sum(usbl.measure(k * 0.1, np.zeros(3))[4] for k in range(20_000))
    kept = arrivals / 20_000
    assert abs(kept - 0.7) < 4 * np.sqrt(0.3 * 0.7 / 20_000)


@pytest.mark.parametrize(
    ("factory", "match"),
    [
        (lambda: DvlSpec(min_altitude_m=5.0, max_altitude_m=1.0), "min_altitude_m"),
        (lambda: DvlSpec(dropout_probability=1.0), "dropout_probability"),
        (lambda: UsblSpec(period_s=0.0), "period_s"),
        (lambda: FlatSeabed(-1.0), "sea-bottom depth"),
    ],
)
def test_bad_parameters_are_refused(factory, match):
    with pytest.raises(ParameterError, match=match):
        factory()


def test_usbl_fixes_scatter_about_the_truth_with_their_sigma_and_read_zero_before_the_first():
    """Each fix is the position when pinged plus white noise of sigma noise_m per world
    component (unbiased; 10 % on the sigma over 4000 fixes); before the first fix arrives
    the reading is [0, 0, 0, age -1, new 0]."""
    sigma = 0.25
    usbl = Usbl(UsblSpec(noise_m=sigma, period_s=0.1, latency_s=0.05), np.random.default_rng(6))
    truth = np.array([10.0, -4.0, -30.0])
    out = np.array([usbl.measure(k * 0.05, truth) for k in range(8002)])
    np.testing.assert_array_equal(out[0], [0.0, 0.0, 0.0, -1.0, 0.0])
    fixes = out[out[:, 4] == 1.0, :3]
    assert len(fixes) == 4000
    error = fixes - truth
    assert np.std(error) == pytest.approx(sigma, rel=0.1)
    assert np.all(np.abs(error.mean(axis=0)) < 5 * sigma / np.sqrt(len(fixes)))


def test_usbl_pings_once_per_period_on_its_grid_after_a_gap_in_the_ticks():
    """A ping is taken at the first tick at or after each multiple of the period; ticks that
    skip several periods give one ping, and the next is at the next multiple of the period
    after it (not a burst of the missed ones): ticks at 0, 2.6 s then every 0.1 s, period
    0.5 s, no latency: fixes at 0, 2.6, 3.0, 3.5, 4.0 s."""
    usbl = Usbl(UsblSpec(period_s=0.5), np.random.default_rng(1))
    times = [0.0, 2.6, *(2.6 + 0.1 * k for k in range(1, 15))]
    new = [usbl.measure(t, np.zeros(3))[4] for t in times]
    pinged = [t for t, n in zip(times, new, strict=True) if n == 1.0]
    np.testing.assert_allclose(pinged, [0.0, 2.6, 3.0, 3.5, 4.0], atol=1e-9)
