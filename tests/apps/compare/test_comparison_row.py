"""compare-controllers' per-controller numbers (`comparison_row`) on a synthetic rollout
with known answers (built with `Rollout.allocate`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.apps.compare.metrics import Criteria, comparison_row
from uvms_pin.results.rollout import Rollout
from uvms_pin.sim.actuation import Actuation

DT = 0.01
N = 1000  # t = 0 .. 9.99 s
PER_PERIOD = 100
NV = 10


class SurgeLimited(Actuation):
    """Saturated when the commanded surge force exceeds 1 N."""

    def apply(self, tau_commanded):
        return tau_commanded

    def saturated(self, tau_commanded):
        return abs(tau_commanded[0]) > 1.0


def sine(amplitude: float) -> np.ndarray:
    return amplitude * np.sin(2.0 * np.pi * np.arange(N) / PER_PERIOD)


def run(limits=((-1.0,) * 4, (1.0,) * 4)) -> Rollout:
    """x error -0.6 N at t = 0, +0.2 N at 1 s, 0 at 2 s, then a 0.1 N sine (and a y error
    0.04 cos t); orientation
    error 0.3 rad up to 2 s, then a 0.02 rad sine; surge force a 2 N sine."""
    meta = {"arm_position_lower_rad": list(limits[0]), "arm_position_upper_rad": list(limits[1])}
    r = Rollout.allocate(N, 7 + 4, NV, meta)
    for name in Rollout._BASE[1:]:
        getattr(r, name)[...] = 0.0
    r.time_s[:] = DT * np.arange(N)
    r.q[:, 6] = 1.0
    t = r.time_s
    desired = np.zeros((N, 3))
    desired[:, 0] = 0.5
    r.signal("force_desired_world_N", 3)[:] = desired
    error = np.zeros(N)
    rise, fall, after = t <= 1.0, (t > 1.0) & (t < 2.0), t >= 2.0
    error[rise] = -0.6 + 0.8 * t[rise]
    error[fall] = 0.2 * (2.0 - t[fall])
    error[after] = sine(0.1)[after]
    r.wrench_contact_world[:, 0] = desired[:, 0] + error
    r.wrench_contact_world[:, 1] = np.where(after, 0.04 * np.cos(t), 0.0)  # y: from 2 s on
    r.wrench_measured_world[:, :3] = r.wrench_contact_world[:, :3] + 3.0  # a biased sensor
    e_x = r.signal("e_x", 6)
    e_x[:] = 0.0
    e_x[:, 5] = np.where(after, sine(0.02), 0.3)
    r.tau[:, 0] = sine(2.0)
    r.tau[:, 7] = -4.0
    r.signal("tau_commanded", NV)[:] = r.tau
    return r


def test_errors_after_the_transient_settling_and_efforts():
    r = run()
    row = comparison_row("ppc", r, SurgeLimited(), Criteria(after_s=2.0, band_N=0.151))
    after = r.time_s >= 2.0
    y = np.where(after, 0.04 * np.cos(r.time_s), 0.0)
    norm = np.hypot(sine(0.1), y)[after]
    assert row["force_error_rms_N"] == pytest.approx(math.sqrt(np.mean(norm**2)), rel=1e-12)
    # the x ripple alone: RMS 0.1 / sqrt 2, with y adding its mean square
    assert row["force_error_rms_N"] ** 2 == pytest.approx(
        0.01 / 2 + np.mean(y[after] ** 2), rel=1e-12
    )
    assert row["force_error_peak_N"] == pytest.approx(np.max(norm), rel=1e-12)
    assert 0.1 < row["force_error_peak_N"] < math.hypot(0.1, 0.04)
    # x starts below the desired force and reaches +0.2 N above it; y starts at zero
    # error, so any y error counts, but its 0.04 N are less
    assert row["overshoot_N"] == pytest.approx(0.2, rel=1e-12)
    # |e| > 0.151 N last on the fall from 0.2 N: 0.2 (2 - t) > 0.151 for t < 1.245 s
    assert row["settling_time_s"] == pytest.approx(1.24, abs=1e-12)
    assert row["orientation_error_rms_rad"] == pytest.approx(0.02 / math.sqrt(2), rel=1e-12)
    assert row["orientation_error_peak_rad"] == pytest.approx(0.02, rel=1e-12)
    assert row["vehicle_force_peak_N"] == pytest.approx(2.0, rel=1e-12)
    assert row["vehicle_force_rms_N"] == pytest.approx(math.sqrt(2.0), rel=1e-12)
    assert row["joint_torque_peak_Nm"] == 4.0
    # |2 sin| > 1 on (1/12, 5/12) and (7/12, 11/12) of each period: 66 of 100 samples
    assert row["saturated_fraction"] == 0.66
    assert math.isnan(row["funnel_margin_first"]) and math.isnan(row["funnel_margin_second"])
    assert row["success"] and row["reason"] == ""


def test_never_settling_a_large_error_and_a_joint_past_its_limit_are_failures():
    r = run()
    # still outside the band at the end (|e| = 0.034 N at 9.99 s): not settled
    row = comparison_row("ppc", r, SurgeLimited(), Criteria(after_s=2.0, band_N=0.02))
    assert math.isnan(row["settling_time_s"])
    # the peak after t = 1 s is 0.2 N > 0.15 N
    row = comparison_row("ppc", r, SurgeLimited(), Criteria(after_s=1.0, tolerance_N=0.15))
    assert not row["success"] and "0.200 N > 0.15 N" in row["reason"]
    r.q[500:510, 8] = 1.0 + 1e-14  # at its upper limit to rounding (a constraint's): held
    assert comparison_row("ppc", r, SurgeLimited(), Criteria(after_s=2.0))["success"]
    r.q[500:510, 8] = 1.25  # joint 2 a quarter radian past its upper limit
    row = comparison_row("ppc", r, SurgeLimited(), Criteria(after_s=2.0))
    assert not row["success"] and row["reason"] == "an arm joint went 0.250 rad past its limit"
    stopped = comparison_row("ppc", run(), SurgeLimited(), Criteria(2.0), stopped="diverged")
    assert stopped["status"] == "stopped" and stopped["reason"] == "diverged"


def test_funnel_margins_and_a_run_that_never_reached_the_window():
    r = run()
    r.signal("xi_x", 6)[:] = 0.1
    r.signals["xi_x"][50, 2] = -0.8
    r.signal("xi_zeta", NV)[:] = 0.4
    row = comparison_row("ppc", r, SurgeLimited(), Criteria(after_s=2.0))
    assert row["funnel_margin_first"] == pytest.approx(0.2, rel=1e-12)
    assert row["funnel_margin_second"] == pytest.approx(0.6, rel=1e-12)
    late = comparison_row("ppc", r, SurgeLimited(), Criteria(after_s=20.0))
    assert math.isnan(late["force_error_rms_N"]) and math.isnan(late["force_error_peak_N"])
    assert late["reason"] == "no samples after the transient"


def test_overshoot_is_the_runs_metric():
    """One definition of overshoot: the comparison table's equals a run's metrics.json."""
    from uvms_pin.results.metrics import force_tracking_metrics

    rollout = run()
    rollout.wrench_contact_world[3, 1] += 0.3  # a component that started at zero error
    row = comparison_row("ppc", rollout, SurgeLimited(), Criteria(after_s=0.0))
    assert row["overshoot_N"] == force_tracking_metrics(rollout)["force_overshoot_N"]
    assert row["overshoot_N"] >= 0.3 - 1e-12
