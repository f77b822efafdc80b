"""Sensors: bounded, seeded noise on the F/T sensor and the state.

Noise is drawn on a fixed sample grid (period T) and smoothstep-blended between draws
(uvms_pin.sim.sensors docstring): at the grid points it equals the draws, in between it is a
convex combination of the two neighbouring draws, so it never leaves the bound.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.sim.sensors import NoiseSpec, SampledNoise, SensorConfig, SensorSuite

PERIOD = 1e-3
DURATION = 0.5


def _times(n: int = 400) -> np.ndarray:
    """Times strictly inside sample periods (30 % into each), all within the duration."""
    return (np.arange(n) + 0.3) * PERIOD


def _state(uvms):
    q = uvms.neutral_configuration()
    q[:3] = [0.5, -1.0, -2.0]
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.3, -0.2, 1.0)).coeffs()
    q[7:] = [0.1, 0.5, -0.4, 0.2]
    v = np.linspace(-0.5, 0.5, uvms.nv)
    wrench = np.array([0.4, -0.1, 0.2, 0.01, 0.02, -0.03])
    return q, v, wrench


@pytest.mark.parametrize("distribution", ["uniform", "gaussian"])
def test_noise_is_bounded_and_uses_its_range(distribution):
    """|n| <= bound always; uniform fills the range (max > 0.99 bound in 1e5 draws), the
    gaussian (sigma = bound / 3) is clipped: ~0.27 % of draws sit exactly on the bound."""
    spec = NoiseSpec(0.02, distribution)
    draws = spec.draw(np.random.default_rng(0), (100_000, 3))
    assert np.abs(draws).max() <= 0.02
    assert np.abs(draws).max() > 0.99 * 0.02
    assert abs(draws.mean()) < 1e-3 * 0.02 * 10  # zero mean: 10 standard errors of the mean
    if distribution == "gaussian":
        clipped = np.mean(np.abs(draws) == 0.02)
        assert 0.001 < clipped < 0.005
        assert draws.std() == pytest.approx(0.02 / 3, rel=0.02)


def test_zero_bound_draws_zeros_without_consuming_the_generator():
    rng = np.random.default_rng(1)
    np.testing.assert_array_equal(NoiseSpec(0.0).draw(rng, (5, 3)), np.zeros((5, 3)))
    assert rng.uniform() == np.random.default_rng(1).uniform()


@pytest.mark.parametrize(
    "kwargs", [{"bound": -0.1}, {"bound": np.nan}, {"bound": np.inf}, {"distribution": "laplace"}]
)
def test_bad_noise_spec_raises(kwargs):
    with pytest.raises(up.ParameterError):
        NoiseSpec(**kwargs)


def test_a_sensor_config_noise_given_as_a_number_is_refused_with_the_spec_to_give():
    """A bound given where a NoiseSpec goes was accepted and failed at the run's start
    with an AttributeError."""
    with pytest.raises(
        up.ParameterError, match=r"force_noise must be a NoiseSpec \(NoiseSpec\(0.5\)"
    ):
        SensorConfig(force_noise=0.5)
    with pytest.raises(up.ParameterError, match="velocity_noise must be a NoiseSpec, got dict"):
        SensorConfig(velocity_noise={"bound": 0.1})


def test_sampled_noise_rejects_bad_period():
    for period in (0.0, -1e-3, np.nan):
        with pytest.raises(up.ParameterError, match="period"):
            SampledNoise(NoiseSpec(0.1), 3, period, 1.0, np.random.default_rng(0))


@pytest.mark.parametrize("distribution", ["uniform", "gaussian"])
@pytest.mark.parametrize("chunk_rows", [2, 7, 4096])
def test_lazy_noise_equals_one_draw_of_the_whole_table(distribution, chunk_rows):
    """Drawn chunk by chunk as time advances, the noise is bitwise the noise of one draw of
    the whole table, the same generator state, at the grid points and between them; going
    back in time (replayed from the seed) gives the same values again."""
    spec = NoiseSpec(0.02, distribution)
    duration, period = 0.2, 1e-3
    table = spec.draw(np.random.default_rng(3), (round(duration / period) + 2, 3))
    noise = SampledNoise(spec, 3, period, duration, np.random.default_rng(3), chunk_rows=chunk_rows)
    grid = np.arange(round(duration / period) + 1)
    for k in grid:
        np.testing.assert_array_equal(noise(k * period), table[k])
    s = 0.3
    blend = s * s * (3.0 - 2.0 * s)
    for k in grid[::-1][1:]:  # backwards: replays the stream from the seed
        expected = table[k] + blend * (table[k + 1] - table[k])
        np.testing.assert_allclose(noise((k + s) * period), expected, rtol=0, atol=1e-15)


@pytest.mark.parametrize("bound", [0.02, 1.0, 0.0])
@pytest.mark.parametrize("chunk_rows", [2, 5, 4096])
def test_noise_values_at_many_times_are_the_signal_at_each_time(bound, chunk_rows):
    """``values(times)`` (what the compiled loop takes as its noise table) is, row for row
    and bit for bit, the signal at each time: the draw on the grid, the smoothstep blend
    s^2 (3 - 2 s) between two draws, times before 0 and past the duration clamped to the
    table's ends; a zero bound gives zeros. Checked on a second generator of the same seed
    (the signal is a function of time only)."""
    period, duration = 1e-2, 0.3
    spec = NoiseSpec(bound, "uniform")

    def noise():
        return SampledNoise(
            spec, 4, period, duration, np.random.default_rng(11), chunk_rows=chunk_rows
        )

    rng = np.random.default_rng(4)
    times = np.sort(
        np.r_[-0.05, 0.0, np.arange(1, 30) * period, rng.uniform(0.0, duration, 40), 0.31, 0.5]
    )
    batch = noise().values(times)
    one_by_one = noise()
    expected = np.array([one_by_one(float(t)) for t in times])
    np.testing.assert_array_equal(batch, expected)
    if bound == 0.0:
        np.testing.assert_array_equal(batch, np.zeros_like(batch))
        return
    table = spec.draw(np.random.default_rng(11), (round(duration / period) + 2, 4))
    on_grid = (
        np.isclose(times / period, np.round(times / period)) & (times >= 0) & (times <= duration)
    )
    np.testing.assert_array_equal(
        batch[on_grid], table[np.round(times[on_grid] / period).astype(int)]
    )
    k = int(0.123 / period)
    s = 0.123 / period - k
    blend = s * s * (3.0 - 2.0 * s)
    np.testing.assert_allclose(
        noise().values(np.array([0.123]))[0],
        table[k] + blend * (table[k + 1] - table[k]),
        atol=1e-15,
    )
    assert np.abs(batch).max() > 0.5 * bound  # not silent


def test_lazy_noise_memory_does_not_grow_with_the_duration():
    """A 1e6 s run at 1 kHz would be a 24 GB table; lazily, only two chunks are held."""
    noise = SampledNoise(NoiseSpec(0.1), 3, 1e-3, 1e6, np.random.default_rng(0), chunk_rows=64)
    for t in np.linspace(0.0, 2.0, 50):
        noise(float(t))
    assert noise._window.nbytes <= 2 * 64 * 3 * 8
    assert np.all(np.abs(noise(1.999)) <= 0.1)


def _config(bound: float = 0.02, distribution: str = "uniform") -> SensorConfig:
    spec = NoiseSpec(bound, distribution)
    return SensorConfig(
        force_noise=spec,
        torque_noise=NoiseSpec(bound / 10, distribution),
        position_noise=spec,
        orientation_noise=NoiseSpec(0.1, distribution),
        joint_noise=spec,
        velocity_noise=spec,
        sample_period_s=PERIOD,
    )


@pytest.mark.parametrize("distribution", ["uniform", "gaussian"])
def test_measurement_noise_is_bounded_per_channel(reference_uvms, distribution):
    """Force, torque, position (a world offset), orientation (a body rotation vector),
    joints and velocity each stay within their own bound, with orientation noise on at the
    same time (1e-12 slack for round-off of the composition)."""
    uvms = reference_uvms
    sensors = SensorSuite(uvms.model, _config(0.02, distribution), DURATION, seed=7)
    q, v, wrench = _state(uvms)
    rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
    worst = np.zeros(6)
    for t in _times():
        m = sensors.measure(t, q, v, wrench)
        noise_rotation = pin.log3(rotation.T @ pin.Quaternion(m.q[3:7]).toRotationMatrix())
        worst = np.maximum(
            worst,
            [
                np.abs(m.wrench_world[:3] - wrench[:3]).max() / 0.02,
                np.abs(m.wrench_world[3:] - wrench[3:]).max() / 0.002,
                np.abs(m.q[:3] - q[:3]).max() / 0.02,
                np.abs(noise_rotation).max() / 0.1,
                np.abs(m.q[7:] - q[7:]).max() / 0.02,
                np.abs(m.v - v).max() / 0.02,
            ],
        )
    assert np.all(worst <= 1.0 + 1e-9), worst
    assert np.all(worst > 0.5), worst  # every channel is really noisy


def test_noise_is_deterministic_for_a_seed_and_differs_between_seeds(reference_uvms):
    uvms = reference_uvms
    q, v, wrench = _state(uvms)
    a = SensorSuite(uvms.model, _config(), DURATION, seed=3)
    b = SensorSuite(uvms.model, _config(), DURATION, seed=3)
    c = SensorSuite(uvms.model, _config(), DURATION, seed=4)
    differs = 0
    for t in _times(50):
        ma, mb, mc = (s.measure(t, q, v, wrench) for s in (a, b, c))
        np.testing.assert_array_equal(ma.wrench_world, mb.wrench_world)
        np.testing.assert_array_equal(ma.q, mb.q)
        np.testing.assert_array_equal(ma.v, mb.v)
        differs += not np.array_equal(ma.wrench_world, mc.wrench_world)
    assert differs == 50


def test_noise_is_a_function_of_time_only(reference_uvms):
    """Querying out of order (as an adaptive integrator's trial stages do) changes nothing."""
    uvms = reference_uvms
    q, v, wrench = _state(uvms)
    sensors = SensorSuite(uvms.model, _config(), DURATION, seed=5)
    first = sensors.measure(0.2503, q, v, wrench)
    for t in (0.4, 0.0, 0.1, 0.2503, 0.3):
        sensors.measure(t, q, v, wrench)
    again = sensors.measure(0.2503, q, v, wrench)
    np.testing.assert_array_equal(first.wrench_world, again.wrench_world)
    np.testing.assert_array_equal(first.q, again.q)
    np.testing.assert_array_equal(first.v, again.v)


def test_noise_equals_the_draws_on_the_grid_and_blends_between(reference_uvms):
    """At t = k T the force noise is the k-th draw (what a sampled controller reads); inside
    a period it lies between the k-th and (k+1)-th draws component-wise (smoothstep weight
    3 s^2 - 2 s^3 in [0, 1]), moves monotonically from one to the other, and reaches the
    next draw at (k + 1) T. The draws are recovered on the grid; 1e-15 slack for round-off."""
    uvms = reference_uvms
    q, v, wrench = _state(uvms)
    sensors = SensorSuite(uvms.model, _config(), DURATION, seed=9)

    def noise(t):
        return sensors.measure(t, q, v, wrench).wrench_world - wrench

    draws = np.array([noise(k * PERIOD) for k in range(101)])
    assert len({tuple(d) for d in draws}) == 101  # a new value every sample period
    for k in range(100):
        lo, hi = np.minimum(draws[k], draws[k + 1]), np.maximum(draws[k], draws[k + 1])
        inside = np.array([noise((k + f) * PERIOD) for f in (0.1, 0.3, 0.5, 0.7, 0.9)])
        assert np.all(inside >= lo - 1e-15) and np.all(inside <= hi + 1e-15)
        steps = np.diff(np.vstack([draws[k], inside, draws[k + 1]]), axis=0)
        direction = np.sign(draws[k + 1] - draws[k])
        assert np.all(steps * direction >= -1e-15)  # monotone from draw k to draw k + 1
        # smoothstep at s = 0.5 is exactly the midpoint
        np.testing.assert_allclose(inside[2], 0.5 * (draws[k] + draws[k + 1]), atol=1e-15)
    # continuity at the grid points: just before and after k T both tend to draw k
    for k in range(1, 50):
        for t in (k * PERIOD - 1e-9, k * PERIOD + 1e-9):
            np.testing.assert_allclose(noise(t), draws[k], atol=1e-6 * 0.02)
    # after the duration the last draw is held (no IndexError), still within the bound
    late = noise(10 * DURATION)
    np.testing.assert_array_equal(late, noise(20 * DURATION))
    assert np.all(np.abs(late[:3]) <= 0.02)


def test_zero_noise_gives_exact_measurements(reference_uvms):
    uvms = reference_uvms
    q, v, wrench = _state(uvms)
    sensors = SensorSuite(uvms.model, SensorConfig(sample_period_s=PERIOD), DURATION, seed=0)
    for t in _times(20):
        m = sensors.measure(t, q, v, wrench)
        assert m.time_s == t
        np.testing.assert_array_equal(m.q, q)
        np.testing.assert_array_equal(m.v, v)
        np.testing.assert_array_equal(m.wrench_world, wrench)
        np.testing.assert_array_equal(m.force_world_N, wrench[:3])


def test_force_noise_only_leaves_the_state_exact(reference_uvms):
    uvms = reference_uvms
    q, v, wrench = _state(uvms)
    config = SensorConfig(force_noise=NoiseSpec(0.05), sample_period_s=PERIOD)
    sensors = SensorSuite(uvms.model, config, DURATION, seed=0)
    m = sensors.measure(0.1, q, v, wrench)
    np.testing.assert_array_equal(m.q, q)
    np.testing.assert_array_equal(m.v, v)
    np.testing.assert_array_equal(m.wrench_world[3:], wrench[3:])  # no torque noise asked
    assert np.any(m.wrench_world[:3] != wrench[:3])


def test_state_noise_keeps_the_quaternion_unit(reference_uvms):
    """Large orientation noise (0.5 rad per component): |quaternion| = 1 to 1e-12."""
    uvms = reference_uvms
    q, v, wrench = _state(uvms)
    config = SensorConfig(
        orientation_noise=NoiseSpec(0.5),
        position_noise=NoiseSpec(0.1),
        joint_noise=NoiseSpec(0.1),
        sample_period_s=PERIOD,
    )
    sensors = SensorSuite(uvms.model, config, DURATION, seed=11)
    for t in _times(200):
        m = sensors.measure(t, q, v, wrench)
        assert abs(np.linalg.norm(m.q[3:7]) - 1.0) < 1e-12
        assert not np.allclose(m.q[3:7], q[3:7])


def test_noise_table_is_the_noise_measure_adds(reference_uvms):
    """`noise_table` (the compiled loop's noise input) is, column block by block, what
    `measure` adds at the same times: force and torque to the wrench, the position offset to
    q[:3], the joint noise to the arm's q, the velocity noise to v (v_meas = v + n_v), and
    the orientation noise as the body-frame rotation R_meas = R exp([n_o]x)."""
    uvms = reference_uvms
    q, v, wrench = _state(uvms)
    sensors = SensorSuite(uvms.model, _config(), DURATION, seed=21)
    times = np.r_[0.0, _times(60)[::7], 2 * PERIOD]
    times.sort()
    table = sensors.noise_table(times)
    nv, n_arm = uvms.nv, uvms.nv - 6
    assert table.shape == (len(times), 12 + n_arm + nv)
    for t, row in zip(times, table, strict=True):
        measured = sensors.measure(float(t), q, v, wrench)
        np.testing.assert_allclose(measured.wrench_world - wrench, row[:6], rtol=0, atol=1e-15)
        rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
        rotation_meas = pin.Quaternion(measured.q[3:7]).toRotationMatrix()
        np.testing.assert_allclose(pin.log3(rotation.T @ rotation_meas), row[6:9], atol=1e-12)
        np.testing.assert_allclose(measured.q[:3] - q[:3], row[9:12], rtol=0, atol=1e-15)
        np.testing.assert_allclose(measured.q[7:] - q[7:], row[12 : 12 + n_arm], atol=1e-15)
        np.testing.assert_allclose(measured.v - v, row[12 + n_arm :], rtol=0, atol=1e-15)
    assert np.abs(table[:, 12 + n_arm :]).max() > 0.0  # the velocity noise is not silent


def test_each_channel_draws_from_its_own_stream(reference_uvms):
    """A channel's noise is the same whether the other channels are noisy or not (each has
    its own generator spawned from the seed): with every channel on, and with that one
    alone, its draws are equal, for force, torque, position, orientation, joints and
    velocity."""
    uvms = reference_uvms
    q, v, wrench = _state(uvms)
    rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
    channels = {
        "force_noise": lambda m: m.wrench_world[:3] - wrench[:3],
        "torque_noise": lambda m: m.wrench_world[3:] - wrench[3:],
        "position_noise": lambda m: m.q[:3] - q[:3],
        "orientation_noise": lambda m: pin.log3(
            rotation.T @ pin.Quaternion(m.q[3:7]).toRotationMatrix()
        ),
        "joint_noise": lambda m: m.q[7:] - q[7:],
        "velocity_noise": lambda m: m.v - v,
    }
    config = _config()
    every = SensorSuite(uvms.model, config, DURATION, seed=9)
    for name, noise in channels.items():
        alone_config = SensorConfig(**{name: getattr(config, name)}, sample_period_s=PERIOD)
        alone = SensorSuite(uvms.model, alone_config, DURATION, seed=9)
        for t in _times(20):
            drawn = noise(alone.measure(t, q, v, wrench))
            assert np.max(np.abs(drawn)) > 0.0, name
            np.testing.assert_allclose(
                noise(every.measure(t, q, v, wrench)), drawn, rtol=0, atol=1e-12, err_msg=name
            )
