"""The navigation filter on a trajectory known in closed form: consistency (NEES over Monte
Carlo seeds), convergence, bias estimation, covariance, dropouts, latency, determinism."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest
from scipy import stats
from trajectory import IMU, NAVIGATION, nees, run, still

from uvms_pin.sim.estimation.eskf import NavState, correct, dvl_model, process_noise, transition
from uvms_pin.sim.estimation.estimator import NavigationEstimator
from uvms_pin.sim.estimation.spec import EstimatorSpec
from uvms_pin.sim.navigation.dvl import DvlSpec
from uvms_pin.sim.navigation.usbl import UsblSpec

SPEC = EstimatorSpec()
SEEDS = range(16)


@pytest.fixture(scope="module")
def monte_carlo():
    return [run(seed, SPEC, duration_s=20.0) for seed in SEEDS]


def test_nees_is_chi_square_over_monte_carlo_seeds(monte_carlo):
    """The mean NEES over N seeds at a tick is chi^2(15 N) / N when the filter is
    consistent: in its two-sided 95 % interval at (nearly) all ticks, and 15 on average."""
    n = len(monte_carlo)
    mean_nees = np.mean([nees(r) for r in monte_carlo], axis=0)
    lower, upper = stats.chi2.ppf([0.025, 0.975], 15 * n) / n
    inside = np.mean((mean_nees >= lower) & (mean_nees <= upper))
    assert inside > 0.9, (inside, mean_nees.min(), mean_nees.max())
    assert 13.5 < mean_nees.mean() < 16.5
    # the pose and velocity alone (9 of 15): the same, not carried by the biases
    mean9 = np.mean([nees(r, slice(0, 9)) for r in monte_carlo], axis=0)
    lo9, up9 = stats.chi2.ppf([0.025, 0.975], 9 * n) / n
    assert np.mean((mean9 >= lo9) & (mean9 <= up9)) > 0.9


def test_errors_are_within_three_sigma_and_position_is_usbl_bounded(monte_carlo):
    sigma = np.sqrt(np.array([np.diagonal(r.covariances, axis1=1, axis2=2) for r in monte_carlo]))
    errors = np.array([r.errors for r in monte_carlo])
    assert np.mean(np.abs(errors) <= 3 * sigma) > 0.99
    # the fixes (0.1 m noise each second) and the DVL keep the position to a few cm
    final_position_rms = np.sqrt(np.mean(errors[:, -1, :3] ** 2))
    assert final_position_rms < 0.06


def test_converges_from_a_wrong_initial_state():
    """Metres off in position, a tenth of a m/s and a few degrees off: the fixes, the DVL
    and the turns bring every error down to the noise (docs/estimation.md: larger heading
    errors strain the linearization)."""
    wrong = replace(SPEC, initial_sigma=(3.0, 0.1, 0.05, 5e-3, 0.05))
    for seed in (3, 4):
        r = run(seed, wrong, duration_s=40.0)
        start, end = r.errors[0], r.errors[-1]
        assert np.linalg.norm(start[:3]) > 2.0 and np.linalg.norm(start[6:9]) > 0.05
        assert np.linalg.norm(end[:3]) < 0.1  # m
        assert np.linalg.norm(end[3:6]) < 0.02  # m/s
        assert np.linalg.norm(end[6:9]) < 0.03  # rad: yaw too (the vehicle turns)
        sigma_end = np.sqrt(np.diag(r.covariances[-1]))
        assert np.all(np.abs(end) < 3.5 * sigma_end)


def test_biases_on_a_still_vehicle():
    """At rest the gyro bias about the world's horizontal axes (it tilts the vehicle, which
    gravity shows) and the accelerometer bias along the world's vertical (against gravity
    and the depth) are observable: they converge to the truth, within the filter's sigma.
    (About the vertical the gyro bias is not observable at rest; docs/estimation.md says
    what the filter does there.)"""
    gyro_bias = np.array([4e-3, -3e-3, 2e-3])
    accel_bias = np.array([0.03, -0.02, 0.05])
    spec = replace(SPEC, initial_sigma=(0.1, 0.05, 0.02, 5e-3, 0.05), draw_initial_error=False)
    r = run(5, spec, path=still, duration_s=120.0, initial_biases=(gyro_bias, accel_bias))
    rotation = pin.Quaternion(still(0.0)[0][3:7]).toRotationMatrix()
    error, P = r.errors[-1], r.covariances[-1]
    checks = [  # (block, world axis, prior sigma, true bias)
        (slice(9, 12), 0, 5e-3, gyro_bias),
        (slice(9, 12), 1, 5e-3, gyro_bias),
        (slice(12, 15), 2, 0.05, accel_bias),
    ]
    for block, axis, prior, truth in checks:
        u = rotation.T[:, axis]  # the world axis in body coordinates
        sigma, e = np.sqrt(u @ P[block, block] @ u), u @ error[block]
        assert abs(e) < 3 * sigma and sigma < 0.05 * prior
        assert abs(e) < 0.05 * abs(u @ truth)  # most of the true bias is found


def test_covariance_stays_symmetric_positive_definite():
    spec = replace(SPEC, initial_sigma=(5.0, 1.0, 0.5, 1e-2, 0.1))
    r = run(11, spec, duration_s=20.0)
    P = r.covariances
    np.testing.assert_array_equal(P, np.transpose(P, (0, 2, 1)))
    assert np.linalg.eigvalsh(P).min() > 0.0


def test_dropouts_grow_the_covariance_and_keep_the_filter_consistent():
    """No DVL lock (the bottom out of range) and nine fixes in ten lost: the position's
    variance grows between fixes and falls at each; the errors stay within their sigmas."""
    sparse = replace(
        NAVIGATION,
        dvl=DvlSpec(noise_m_s=0.01, max_altitude_m=5.0),
        usbl=UsblSpec(noise_m=0.1, period_s=1.0, latency_s=0.5, dropout_probability=0.6),
    )
    runs = [run(seed, SPEC, navigation=sparse, duration_s=20.0) for seed in range(5)]
    r = runs[0]
    variance = r.covariances[:, 0, 0]
    steps = np.diff(variance)
    assert np.sum(steps < 0) < 0.05 * steps.size  # falls only at fixes
    assert variance.max() > 5 * variance[len(variance) // 2 :].min()
    errors = np.array([x.errors for x in runs])
    sigma = np.sqrt(np.array([np.diagonal(x.covariances, axis1=1, axis2=2) for x in runs]))
    assert np.mean(np.abs(errors) <= 3 * sigma) > 0.98


def test_a_late_fix_gives_the_estimate_of_one_without_delay():
    """Fixes applied at the tick they were taken and the ticks after filtered again: once
    no fix is in flight the estimate is the one of the same fixes without latency."""
    delays = {}
    for latency in (0.0, 0.5):
        nav = replace(NAVIGATION, usbl=replace(NAVIGATION.usbl, latency_s=latency))
        delays[latency] = run(2, SPEC, navigation=nav, duration_s=10.0)
    times = delays[0.0].time_s
    settled = (times % 1.0 > 0.55) & (times % 1.0 < 0.95)
    np.testing.assert_allclose(
        delays[0.5].errors[settled], delays[0.0].errors[settled], rtol=0, atol=1e-9
    )
    in_flight = (times % 1.0 > 0.05) & (times % 1.0 < 0.45) & (times > 1.0)
    assert np.abs(delays[0.5].errors[in_flight] - delays[0.0].errors[in_flight]).max() > 1e-6
    assert delays[0.5].estimator.late_fixes == delays[0.0].estimator.late_fixes == 0


def test_same_seed_same_estimate_other_seed_other():
    a, b, c = (
        run(7, SPEC, duration_s=5.0),
        run(7, SPEC, duration_s=5.0),
        run(8, SPEC, duration_s=5.0),
    )
    np.testing.assert_array_equal(a.errors, b.errors)
    np.testing.assert_array_equal(a.covariances, b.covariances)
    assert np.abs(a.errors - c.errors).max() > 1e-6


def _state(rng, biased=True):
    scale = 1.0 if biased else 0.0
    return NavState(
        rng.normal(size=3), rng.normal(size=3), pin.exp3(rng.normal(size=3)),
        0.01 * scale * rng.normal(size=3), 0.05 * scale * rng.normal(size=3),
    )  # fmt: skip


def test_transition_matches_finite_differences():
    """F of `transition`: a small error dx before the period gives F dx after it, to first
    order (central differences; the attitude on the manifold)."""
    rng = np.random.default_rng(0)
    state = _state(rng)
    gyro0, gyro1, accel, dt = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3), 0.01
    nominal, F = transition(state, gyro0, gyro1, accel, dt)
    eps = 1e-6
    for i in range(15):
        dx = np.zeros(15)
        dx[i] = eps
        plus = nominal.error_to(transition(state.injected(dx), gyro0, gyro1, accel, dt)[0])
        minus = nominal.error_to(transition(state.injected(-dx), gyro0, gyro1, accel, dt)[0])
        np.testing.assert_allclose((plus - minus) / (2 * eps), F[:, i], atol=5 * dt**2)


def test_process_noise_is_the_imu_noise_integrated_over_a_period():
    noise = SPEC.imu_noise_of(NAVIGATION)
    dt = 0.02
    Q = process_noise(noise, dt)
    assert Q[3, 3] == pytest.approx(IMU.accel_noise_m_s2_rthz**2 * dt, rel=1e-12)
    assert Q[6, 6] == pytest.approx(IMU.gyro_noise_rad_s_rthz**2 * dt, rel=1e-12)
    assert Q[9, 9] == pytest.approx(IMU.gyro_bias_walk_rad_s2_rthz**2 * dt, rel=1e-12)
    assert Q[12, 12] == pytest.approx(IMU.accel_bias_walk_m_s3_rthz**2 * dt, rel=1e-12)
    assert np.linalg.eigvalsh(Q).min() >= -1e-20  # positive semi-definite (p, v rank one)
    # the velocity's noise n reaches the position by dt/2 (dp+ = dp + dt dv + dt/2 (dv+ - dv)):
    # (dp, dv) noise = [dt/2; 1] n, so its covariance is [dt^2/4, dt/2; dt/2, 1] N_a^2 dt
    spread = np.kron(np.array([[dt * dt / 4.0, dt / 2.0], [dt / 2.0, 1.0]]), np.eye(3))
    np.testing.assert_allclose(
        Q[:6, :6], spread * IMU.accel_noise_m_s2_rthz**2 * dt, rtol=1e-12, atol=0.0
    )
    assert not Q[:6, 6:].any()  # no noise shared with the attitude or the biases


def test_dvl_jacobian_matches_finite_differences():
    rng = np.random.default_rng(1)
    state = _state(rng, biased=False)
    h, H = dvl_model(state)
    eps = 1e-7
    for i in range(15):
        dx = np.zeros(15)
        dx[i] = eps
        np.testing.assert_allclose((dvl_model(state.injected(dx))[0] - h) / eps, H[:, i], atol=1e-6)


def test_a_correction_pulls_toward_the_measurement_by_the_kalman_gain():
    """Scalar check: a velocity prior of variance s^2, a DVL of noise r^2 at rest and level:
    the estimate moves by s^2 / (s^2 + r^2) of the residual, the variance to s^2 r^2 /
    (s^2 + r^2)."""
    state = NavState(np.zeros(3), np.zeros(3), np.eye(3), np.zeros(3), np.zeros(3))
    P = np.eye(15) * 1e-4
    P[3, 3] = 0.04
    h, H = dvl_model(state)
    new, P_new = correct(state, P, np.array([0.1, 0.0, 0.0]) - h, H, np.full(3, 0.01))
    assert new.velocity_world_m_s[0] == pytest.approx(0.1 * 0.04 / 0.05, rel=1e-12)
    assert P_new[3, 3] == pytest.approx(0.04 * 0.01 / 0.05, rel=1e-12)


def test_a_depth_reading_is_weighed_by_the_depth_noise_variance():
    """The first tick's prior is the initial one (sigma_p^2 on z); a depth reading d of
    variance R = depth_m^2 makes the posterior variance sigma_p^2 R / (sigma_p^2 + R) and
    moves z by the gain K = sigma_p^2 / (sigma_p^2 + R) toward the reading (z = -d)."""
    estimator = NavigationEstimator(replace(SPEC, draw_initial_error=False), NAVIGATION, 0)
    q, v = still(0.0)
    estimator.start(0.02, q, v)
    reading_m = -q[2] + 0.2
    estimator.update(
        0.0, {"imu_gyro": np.zeros(3), "imu_accel": np.zeros(3), "depth": np.array([reading_m])}
    )
    prior, noise = SPEC.initial_sigma[0] ** 2, estimator.noise.depth_m**2
    assert noise < 0.1 * prior  # the reading counts
    assert estimator.covariance[2, 2] == pytest.approx(prior * noise / (prior + noise), rel=1e-9)
    gain = prior / (prior + noise)
    z = estimator.state.position_world_m[2]
    assert z == pytest.approx(q[2] - gain * 0.2, rel=1e-9)
