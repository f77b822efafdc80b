"""Every metric of `uvms_pin.results.metrics` on synthetic rollouts with known answers.

The rollouts are built with `Rollout.allocate` (the package's own constructor) and filled
with signals whose metrics follow by hand: sines sampled over whole periods (mean of
sin^2 = 1/2 exactly on a uniform grid of more than two samples per period), joints held past
a limit by a known amount over a known set of samples, funnels of known transient length.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.results.metrics import (
    compute_metrics,
    force_tracking_metrics,
    joint_limit_metrics,
    transient_end_s,
)
from uvms_pin.results.rollout import Rollout

DT = 0.01
N = 1000  # t = 0 .. 9.99 s
N_JOINTS = 4
PER_PERIOD = 100  # a 1 s period: a multiple of 4, so the grid hits every peak
LOWER = [-1.0, -2.0, -1.0, -3.0]
UPPER = [1.0, 2.0, 1.0, 3.0]


def rollout(n: int = N, metadata: dict | None = None) -> Rollout:
    """At rest at the origin, level, no input, zero energy: every metric's neutral value."""
    r = Rollout.allocate(n, 7 + N_JOINTS, 6 + N_JOINTS, metadata)
    r.time_s[:] = DT * np.arange(n)
    for name in Rollout._BASE[1:]:
        getattr(r, name)[...] = 0.0
    r.q[:, 6] = 1.0  # unit quaternion (x, y, z, w)
    return r


def sine(amplitude: float, n: int = N, periods_delay: int = 0) -> np.ndarray:
    k = np.arange(n) - periods_delay * PER_PERIOD
    return amplitude * np.sin(2.0 * np.pi * k / PER_PERIOD)


# ---- compute_metrics: timing, energy, motion, effort --------------------------------------


def test_timing_comes_from_the_metadata_and_an_empty_rollout_has_nothing_else():
    meta = {"simulated_time_s": 9.99, "wall_time_s": 2.5, "real_time_factor": 3.996}
    m = compute_metrics(rollout(metadata=meta))
    assert (m["simulated_time_s"], m["wall_time_s"], m["real_time_factor"]) == (9.99, 2.5, 3.996)
    assert m["n_samples"] == N
    empty = compute_metrics(rollout(0))
    assert set(empty) == {"simulated_time_s", "wall_time_s", "real_time_factor", "n_samples"}
    assert empty["n_samples"] == 0 and math.isnan(empty["wall_time_s"])


def test_effort_rms_and_peak_of_known_sines():
    r = rollout()
    r.tau[:, 0] = sine(3.0)  # |f| = 3 |sin|: RMS 3 / sqrt(2), peak 3
    r.tau[:, 3] = 1.0  # |m| = sqrt(1 + 4 sin^2): RMS sqrt(1 + 2), peak sqrt(5)
    r.tau[:, 5] = sine(2.0)
    r.tau[:, 6] = sine(0.5)  # joints: max_j |tau_j| = 1.5 at every sample
    r.tau[:, 8] = -1.5
    m = compute_metrics(r)
    assert m["vehicle_force_rms_N"] == pytest.approx(3.0 / math.sqrt(2.0), rel=1e-12)
    assert m["vehicle_force_peak_N"] == pytest.approx(3.0, rel=1e-12)
    assert m["vehicle_torque_rms_Nm"] == pytest.approx(math.sqrt(3.0), rel=1e-12)
    assert m["vehicle_torque_peak_Nm"] == pytest.approx(math.sqrt(5.0), rel=1e-12)
    # "joint torques = max over joints of |tau_j|", its peak and RMS over time
    assert m["joint_torque_peak_Nm"] == pytest.approx(1.5, rel=1e-12)
    assert m["joint_torque_rms_Nm"] == pytest.approx(1.5, rel=1e-12)


def test_a_vehicle_without_an_arm_has_no_joint_torque_metrics_and_no_nan():
    """A bare vehicle: the joint metrics do not apply, so they are absent (they were a NaN
    RMS beside a 0 peak in metrics.json); every metric left is a finite number."""
    r = Rollout.allocate(
        N, 7, 6, {"simulated_time_s": 9.99, "wall_time_s": 1.0, "real_time_factor": 9.99}
    )
    r.time_s[:] = DT * np.arange(N)
    for name in Rollout._BASE[1:]:
        getattr(r, name)[...] = 0.0
    r.q[:, 6] = 1.0
    r.tau[:, 2] = sine(1.0)
    m = compute_metrics(r)
    assert "joint_torque_rms_Nm" not in m and "joint_torque_peak_Nm" not in m
    assert all(math.isfinite(value) for value in m.values()), m


def test_joint_torque_rms_follows_the_largest_joint_sample_by_sample():
    """|tau_1| = |2 sin|, |tau_2| = 1: the largest is 2 |sin| where |sin| > 1/2 (two
    thirds of the period), so mean(max^2) = 5/3 + 3^0.5 / pi (integrating 4 sin^2 there)."""
    r = rollout()
    r.tau[:, 6] = sine(2.0)
    r.tau[:, 7] = 1.0
    expected = math.sqrt(5.0 / 3.0 + math.sqrt(3.0) / math.pi)
    # the grid's 100 samples per period sum the kinked square to ~1e-4
    assert compute_metrics(r)["joint_torque_rms_Nm"] == pytest.approx(expected, rel=1e-3)


def test_energy_drift_and_largest_increase():
    r = rollout()
    r.kinetic_energy_J[:] = 4.0 * np.exp(-np.arange(N) / 200.0)  # decays from 4 J
    r.potential_energy_J[:] = -10.0
    r.potential_energy_J[500] += 0.5  # one step up of 0.5 J (minus the decay's step)
    m = compute_metrics(r)
    total = r.kinetic_energy_J + r.potential_energy_J
    assert m["kinetic_energy_initial_J"] == 4.0
    assert m["kinetic_energy_final_J"] == pytest.approx(4.0 * math.exp(-999 / 200.0))
    # |E(0)| = 6 J > K(0) = 4 J; the largest |E - E(0)| is at the end: 4 (1 - e^-4.995)
    assert m["energy_relative_drift_max"] == pytest.approx(
        4.0 * (1.0 - math.exp(-999 / 200.0)) / 6.0, rel=1e-12
    )
    assert m["energy_max_increase_J"] == pytest.approx(total[500] - total[499], rel=1e-12)
    assert m["energy_max_increase_J"] == pytest.approx(
        0.5 - 4.0 * (math.exp(-499 / 200) - math.exp(-500 / 200)), rel=1e-12
    )
    r.potential_energy_J[500] -= 0.5  # decaying everywhere: no increase
    assert compute_metrics(r)["energy_max_increase_J"] < 0.0
    # E(0) = 0: the drift is relative to K(0)
    r.potential_energy_J[:] = -4.0
    r.kinetic_energy_J[:] = 4.0
    r.kinetic_energy_J[-1] = 5.0
    assert compute_metrics(r)["energy_relative_drift_max"] == pytest.approx(0.25)


def test_displacement_and_final_speeds():
    r = rollout()
    start = np.array([1.0, 2.0, 3.0])
    r.q[:, :3] = start + np.outer(np.arange(N) / (N - 1), [3.0, 0.0, -4.0])
    r.v[-1, :6] = [0.0, 0.6, 0.8, 0.1, -0.2, 0.2]
    m = compute_metrics(r)
    assert m["vehicle_displacement_m"] == pytest.approx(5.0, rel=1e-12)
    assert m["vehicle_speed_final_m_s"] == pytest.approx(1.0, rel=1e-12)
    assert m["vehicle_angular_speed_final_rad_s"] == pytest.approx(0.3, rel=1e-12)


# ---- joint limits ----------------------------------------------------------------------


def limited(n: int = N) -> Rollout:
    return rollout(n, {"arm_position_lower_rad": LOWER, "arm_position_upper_rad": UPPER})


def test_joints_past_their_limits_by_known_amounts_for_known_times():
    r = limited()
    r.q[300:400, 7] = UPPER[0] + 0.1  # joint 1 above its upper limit for samples 300-399
    r.q[350:450, 9] = LOWER[2] - 0.25  # joint 3 below its lower limit for 350-449
    m = joint_limit_metrics(r)
    assert m["joint_limit_excess_max_rad"] == pytest.approx(0.25, rel=1e-12)
    assert m["joint_limit_excess_time_fraction"] == 150 / N  # samples 300-449
    assert m["time_at_joint_stop_s"] == pytest.approx(150 * DT, rel=1e-12)  # each held DT
    # joint 4 exactly at its limit (as a limit solved as a constraint holds it), samples
    # 500-599: not past it, but at its stop
    r.q[500:600, 10] = UPPER[3]
    m = joint_limit_metrics(r)
    assert m["joint_limit_excess_time_fraction"] == 150 / N
    assert m["time_at_joint_stop_s"] == pytest.approx(250 * DT, rel=1e-12)
    assert compute_metrics(r)["joint_limit_excess_max_rad"] == m["joint_limit_excess_max_rad"]
    # ... or past it by a rounding (a constraint's 1e-15): at its stop, not past it, though
    # the largest excess stays exact
    r.q[:, 7:] = 0.0
    r.q[500:600, 10] = UPPER[3] + 4e-15
    m = joint_limit_metrics(r)
    assert m["joint_limit_excess_time_fraction"] == 0.0
    assert 0.0 < m["joint_limit_excess_max_rad"] < 1e-14
    assert m["time_at_joint_stop_s"] == pytest.approx(100 * DT, rel=1e-12)
    r.q[500:600, 10] = UPPER[3] + 2e-9
    assert joint_limit_metrics(r)["joint_limit_excess_time_fraction"] == 100 / N


def test_a_joint_swinging_across_its_limit():
    """q = 1.95 + 0.1 sin(2 pi t): 0.05 rad past the 2 rad limit, a third of the time
    (sin > 1/2 on (1/12, 5/12) of each period), to one sample at each crossing."""
    r = limited()
    r.q[:, 8] = 1.95 + sine(0.1)
    m = joint_limit_metrics(r)
    assert m["joint_limit_excess_max_rad"] == pytest.approx(0.05, rel=1e-9)
    assert m["joint_limit_excess_time_fraction"] == pytest.approx(1.0 / 3.0, abs=2.0 / PER_PERIOD)


def test_joints_inside_their_limits_give_exactly_zero():
    r = limited()
    r.q[:, 7:] = 0.999 * np.sin(np.arange(N) / 50.0)[:, None] * np.array(UPPER)
    assert joint_limit_metrics(r) == {
        "joint_limit_excess_max_rad": 0.0,
        "joint_limit_excess_time_fraction": 0.0,
        "time_at_joint_stop_s": 0.0,
    }


def test_no_limits_no_arm_or_no_samples_give_no_joint_limit_metrics():
    assert joint_limit_metrics(rollout()) == {}
    assert joint_limit_metrics(limited(0)) == {}
    vehicle = Rollout.allocate(
        5, 7, 6, {"arm_position_lower_rad": [], "arm_position_upper_rad": []}
    )
    assert joint_limit_metrics(vehicle) == {}
    assert "joint_limit_excess_max_rad" not in compute_metrics(rollout())


# ---- the force funnel's transient --------------------------------------------------------


def with_funnel(rate_per_s: float, rho0: float = 1.0, rho_inf: float = 0.1) -> Rollout:
    r = rollout()
    rho = (rho0 - rho_inf) * np.exp(-rate_per_s * r.time_s) + rho_inf
    r.signal("rho_x", 6)[:] = rho[:, None]
    return r


@pytest.mark.parametrize("fraction", [0.05, 0.3])
@pytest.mark.parametrize("rate_per_s", [1.5, 3.0])
def test_transient_ends_where_the_funnel_is_within_the_fraction_of_its_span(rate_per_s, fraction):
    """rho - rho(T) <= f (rho(0) - rho(T)) from t* = -ln(f + (1 - f) e^{-l T}) / l on: the
    first sample at or after t*."""
    r = with_funnel(rate_per_s)
    last = r.time_s[-1]
    t_star = -math.log(fraction + (1.0 - fraction) * math.exp(-rate_per_s * last)) / rate_per_s
    expected = math.ceil(t_star / DT - 1e-9) * DT
    assert transient_end_s(r, fraction) == pytest.approx(expected, abs=1e-12)
    assert transient_end_s(r, fraction) >= t_star


def test_transient_of_a_constant_or_missing_funnel():
    r = with_funnel(0.0)  # never shrinks: no transient
    assert transient_end_s(r) == 0.0
    assert math.isnan(transient_end_s(rollout()))
    short = rollout(1)
    short.signal("rho_x", 6)[:] = 1.0
    assert math.isnan(transient_end_s(short))


# ---- force tracking ------------------------------------------------------------------------


def tracking_run() -> tuple[Rollout, float, float]:
    """A force task with a known history (x error: -0.4 N at t = 0, up to +0.15 N at t = 1 s,
    back to 0 at t = 2 s; then a 0.05 N sine), the transient ending at t = 2 s exactly;
    the sensor reads the true force plus a large noise (that the metrics must ignore)."""
    r = rollout()
    t = r.time_s
    transient_s, ripple_N = 2.0, 0.05
    # l with t* just under 2 s (the first sample after it is t = 2.00)
    rate = math.log(20.0) / 1.995
    rho = 0.9 * np.exp(-rate * t) + 0.1
    r.signal("rho_x", 6)[:] = rho[:, None]
    desired = np.zeros((N, 3))
    desired[:, 0] = 0.4 + 0.1 * np.sin(t)
    r.signal("force_desired_world_N", 3)[:] = desired
    error = np.zeros((N, 3))
    rise, fall, after = t <= 1.0, (t > 1.0) & (t < transient_s), t >= transient_s
    error[rise, 0] = -0.4 + 0.55 * t[rise]
    error[fall, 0] = 0.15 * (transient_s - t[fall])
    error[after, 0] = sine(ripple_N, periods_delay=2)[after]
    r.wrench_contact_world[:, :3] = desired + error
    r.wrench_measured_world[:, :3] = r.wrench_contact_world[:, :3] + np.random.default_rng(
        1
    ).normal(scale=2.0, size=(N, 3))
    return r, transient_s, ripple_N


def test_force_error_after_the_transient_is_the_ripple():
    r, transient_s, ripple_N = tracking_run()
    m = force_tracking_metrics(r)
    assert m["transient_end_s"] == pytest.approx(transient_s, abs=1e-12)
    assert m["force_error_rms_after_transient_N"] == pytest.approx(ripple_N / math.sqrt(2), 1e-12)
    assert m["force_error_max_after_transient_N"] == pytest.approx(ripple_N, rel=1e-12)
    assert m["force_error_max_N"] == pytest.approx(0.4, rel=1e-12)
    # whole run: the ramps' squares (sum_k e_k^2 on the grid) and the ripple's 800 samples
    t = r.time_s
    ramps = np.r_[-0.4 + 0.55 * t[t <= 1.0], 0.15 * (2.0 - t[(t > 1.0) & (t < 2.0)])]
    rms = math.sqrt((np.sum(ramps**2) + 800 * ripple_N**2 / 2) / N)
    assert m["force_error_rms_N"] == pytest.approx(rms, rel=1e-12)
    assert (
        compute_metrics(r)["force_error_rms_after_transient_N"]
        == m["force_error_rms_after_transient_N"]
    )


def test_without_a_force_funnel_the_after_transient_errors_are_left_out_not_null():
    """The MPC and the baselines have no funnel to end a transient: no NaN (null in
    metrics.json) for them, the keys are absent; the whole run's errors stay."""
    r, _, _ = tracking_run()
    del r.signals["rho_x"]
    m = force_tracking_metrics(r)
    for key in (
        "transient_end_s",
        "force_error_rms_after_transient_N",
        "force_error_max_after_transient_N",
    ):
        assert key not in m and key not in compute_metrics(r)
    assert m["force_error_max_N"] == pytest.approx(0.4, rel=1e-12)
    assert all(math.isfinite(value) for value in m.values())


def test_overshoot_is_the_largest_error_past_the_desired_force():
    r, _, _ = tracking_run()
    # the x error starts negative (-0.4 N) and goes up to +0.15 N
    assert force_tracking_metrics(r)["force_overshoot_N"] == pytest.approx(0.15, rel=1e-12)
    # the same history mirrored (starting above the desired force): the same overshoot
    mirrored = 2.0 * r.signals["force_desired_world_N"] - r.wrench_contact_world[:, :3]
    r.wrench_contact_world[:, :3] = mirrored
    assert force_tracking_metrics(r)["force_overshoot_N"] == pytest.approx(0.15, rel=1e-12)
    # a component starting at zero error: any error of it counts, of either sign
    r.wrench_contact_world[400, 1] = -0.2
    assert force_tracking_metrics(r)["force_overshoot_N"] == pytest.approx(0.2, rel=1e-12)


def test_an_error_that_never_changes_sign_has_no_overshoot():
    r, _, _ = tracking_run()
    desired = r.signals["force_desired_world_N"]
    r.wrench_contact_world[:, :3] = desired
    r.wrench_contact_world[:, 0] -= 0.4 * np.exp(-r.time_s)  # approaches from below
    assert force_tracking_metrics(r)["force_overshoot_N"] == 0.0


def test_funnel_margins_orientation_and_commanded_peaks():
    r, _, _ = tracking_run()
    xi_x = r.signal("xi_x", 6)
    xi_x[:] = 0.2
    xi_x[123, 4] = -0.7  # closest to a funnel edge: margin 0.3
    xi_zeta = r.signal("xi_zeta", 10)
    xi_zeta[:] = -0.1
    xi_zeta[456, 8] = 0.9  # margin 0.1
    e_x = r.signal("e_x", 6)
    e_x[:] = 1.0
    e_x[-1, 3:] = [0.03, -0.04, 0.0]  # the final orientation error: 0.05 rad
    commanded = r.signal("tau_commanded", 6 + N_JOINTS)
    commanded[:] = 0.0
    commanded[10, :3] = [3.0, 4.0, 0.0]
    commanded[10, 3] = 1.5  # a torque beside it: not part of the force
    commanded[20, 3:6] = [0.0, 0.0, -2.0]
    commanded[20, 6] = 1.5  # a joint torque beside it: not part of the vehicle's torque
    commanded[30, 9] = -7.0
    m = force_tracking_metrics(r)
    assert m["funnel_margin_min_first"] == pytest.approx(0.3, rel=1e-12)
    assert m["funnel_margin_min_second"] == pytest.approx(0.1, rel=1e-12)
    assert m["orientation_error_final_rad"] == pytest.approx(0.05, rel=1e-12)
    assert m["commanded_vehicle_force_peak_N"] == pytest.approx(5.0, rel=1e-12)
    assert m["commanded_vehicle_torque_peak_Nm"] == pytest.approx(2.0, rel=1e-12)
    assert m["commanded_joint_torque_peak_Nm"] == pytest.approx(7.0, rel=1e-12)


def test_a_funnel_reached_has_a_zero_margin_and_no_force_task_has_no_force_metrics():
    r, _, _ = tracking_run()
    r.signal("xi_x", 6)[:] = 0.0
    r.signals["xi_x"][77, 0] = 1.0
    assert force_tracking_metrics(r)["funnel_margin_min_first"] == 0.0
    assert "funnel_margin_min_second" not in force_tracking_metrics(r)
    assert force_tracking_metrics(rollout()) == {}
    assert "force_error_rms_N" not in compute_metrics(rollout())


# ---- world contacts --------------------------------------------------------------------


def test_world_contact_time_and_peak_force_from_the_logged_pairs():
    r = rollout(metadata={"world_contact_pairs": ["hull|seabed", "tool|rock"]})
    contacts = np.zeros((N, 2, 9))
    contacts[200:500, 0, :3] = [0.0, 3.0, 4.0]  # 5 N on the hull from t = 2 s to 5 s
    contacts[400:450, 1, :3] = [0.0, -3.0, 8.0]  # and the tool on the rock from 4 to 4.5 s
    contacts[400:450, 1, 3:6] = [1.0, 2.0, 3.0]  # (a point: not a force)
    r.signal("world_contact", 18)[:] = contacts.reshape(N, 18)
    m = compute_metrics(r)
    assert m["time_in_world_contact_s"] == pytest.approx(300 * DT, rel=1e-12)
    assert m["world_contact_force_peak_N"] == pytest.approx(12.0, rel=1e-12)  # |(0, 0, 12)|
    # touching at the last sample too: that sample holds for no time (a run ends there)
    contacts[-1, 0, :3] = [0.0, 0.0, 1.0]
    r.signal("world_contact", 18)[:] = contacts.reshape(N, 18)
    assert compute_metrics(r)["time_in_world_contact_s"] == pytest.approx(300 * DT, rel=1e-12)
