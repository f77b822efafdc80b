"""The IMU's noise: its Allan deviation is the configured one; gravity in the accelerometer."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.sim.navigation.imu import Imu, ImuSpec, NoisyChannel, allan_deviation

N, K = 0.004, 2e-4  # rad/s/sqrt(Hz), rad/s^2/sqrt(Hz)


def test_a_record_is_the_same_numbers_as_sample_by_sample():
    one = NoisyChannel(N, K, np.random.default_rng(5))
    other = NoisyChannel(N, K, np.random.default_rng(5))
    truth = np.arange(30.0).reshape(10, 3)
    step = np.array([one.sample(row, 0.01) for row in truth])
    np.testing.assert_allclose(other.record(truth, 0.01), step, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(one.bias, other.bias, rtol=1e-13)


@pytest.mark.parametrize("tau_s", [1.0, 100.0])
def test_allan_deviation_is_the_configured_one(tau_s):
    """sigma(tau)^2 = N^2 / tau + K^2 tau / 3, over a 20 h record at 10 Hz, every axis."""
    dt = 0.1
    channel = NoisyChannel(N, K, np.random.default_rng(2017))
    record = channel.record(np.zeros((720_000, 3)), dt)
    expected = math.sqrt(N**2 / tau_s + K**2 * tau_s / 3.0)
    for axis in range(3):
        got = allan_deviation(record[:, axis], dt, tau_s)
        assert got == pytest.approx(expected, rel=0.10)


def test_allan_deviation_of_white_noise_alone_falls_as_one_over_sqrt_tau():
    channel = NoisyChannel(N, 0.0, np.random.default_rng(3))
    record = channel.record(np.zeros((200_000, 3)), 0.01)[:, 0]
    ratio = allan_deviation(record, 0.01, 0.1) / allan_deviation(record, 0.01, 10.0)
    assert ratio == pytest.approx(10.0, rel=0.1)


def test_accelerometer_reads_gravity_at_rest_in_body_axes():
    imu = Imu(ImuSpec(), np.random.default_rng(0), np.random.default_rng(1))
    # rolled by 90 degrees about x: the body's y axis points up
    rotation = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    gyro, accel = imu.measure(np.array([0.1, 0.2, 0.3]), np.zeros(3), rotation, 0.01)
    np.testing.assert_allclose(accel, [0.0, 9.81, 0.0], atol=1e-15)
    np.testing.assert_array_equal(gyro, [0.1, 0.2, 0.3])
    # in free fall it reads nothing
    _, falling = imu.measure(np.zeros(3), np.array([0.0, 0.0, -9.81]), rotation, 0.01)
    np.testing.assert_allclose(falling, 0.0, atol=1e-15)


def test_bad_specs_are_refused():
    with pytest.raises(ParameterError, match="gyro_noise"):
        ImuSpec(gyro_noise_rad_s_rthz=-1.0)
    with pytest.raises(ParameterError, match="tau"):
        allan_deviation(np.zeros(10), 0.1, 1.0)


def test_each_spec_entry_drives_its_own_channel_and_term():
    """ImuSpec's four numbers reach the right channel and term: a gyroscope with white noise
    only scatters about the truth with sigma = N / sqrt(dt) and no drift, an accelerometer
    with a bias walk only reads the truth exactly at its first sample and then drifts by
    steps of sigma = K sqrt(dt) (its consecutive differences), 10 % on 4000 samples."""
    dt, n = 0.01, 4000
    imu = Imu(
        ImuSpec(gyro_noise_rad_s_rthz=N, accel_bias_walk_m_s3_rthz=K * 10),
        np.random.default_rng(8),
        np.random.default_rng(9),
    )
    rate, acceleration, rotation = np.array([0.1, -0.2, 0.3]), np.zeros(3), np.eye(3)
    specific_force = np.array([0.0, 0.0, 9.81])
    readings = [imu.measure(rate, acceleration, rotation, dt) for _ in range(n)]
    gyro = np.array([g for g, _ in readings]) - rate
    accel = np.array([a for _, a in readings]) - specific_force
    assert np.std(gyro) == pytest.approx(N / math.sqrt(dt), rel=0.1)
    assert abs(np.mean(gyro)) < 5 * N / math.sqrt(dt) / math.sqrt(n)  # no bias walk
    np.testing.assert_array_equal(accel[0], np.zeros(3))  # no white noise, bias 0 at first
    steps = np.diff(accel, axis=0)
    assert np.std(steps) == pytest.approx(K * 10 * math.sqrt(dt), rel=0.1)
    assert np.abs(accel[-1]).max() > 0.0


def test_allan_deviation_takes_every_cluster_time_from_one_sample_to_half_the_record():
    """tau from dt (clusters of one sample: white noise of density N reads N / sqrt(dt), 5 %)
    to the longest with two whole clusters and one more sample (2 tau/dt < n); outside that
    range, refused naming tau."""
    dt = 0.01
    channel = NoisyChannel(N, 0.0, np.random.default_rng(11))
    record = channel.record(np.zeros((20_000, 3)), dt)[:, 0]
    assert allan_deviation(record, dt, dt) == pytest.approx(N / math.sqrt(dt), rel=0.05)
    assert allan_deviation(record[:7], dt, 3 * dt) > 0.0  # 2 * 3 < 7: one difference
    for short, tau_s in ((record[:6], 3 * dt), (record, 0.4 * dt)):  # 2 * 3 = 6; tau/dt -> 0
        with pytest.raises(ParameterError, match="tau"):
            allan_deviation(short, dt, tau_s)
