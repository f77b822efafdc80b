"""`uvms_pin.results.estimate_metrics` on a synthetic rollout with known errors and variances."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.results.estimate_metrics import estimate_metrics
from uvms_pin.results.rollout import Rollout

N = 200


def _rollout() -> Rollout:
    """A vehicle at rest at the origin, level; its estimate off by (0.2, 0.5, 0) m over the
    first half of the samples, by nothing after; its velocity off by (0.1, 0, 0.2) m/s
    throughout; sigma 0.1 m, 0.05 m/s, 1 mrad."""
    r = Rollout.allocate(N, 7 + 4, 6 + 4)
    r.time_s[:] = 0.01 * np.arange(N)
    for name in Rollout._BASE[1:]:
        getattr(r, name)[...] = 0.0
    r.q[:, 6] = 1.0
    estimate = r.signal("estimate", 16)
    estimate[:] = 0.0
    estimate[:, 6] = 1.0  # the true attitude
    estimate[: N // 2, :3] = [0.2, 0.5, 0.0]
    estimate[:, 7:10] = [0.1, 0.0, 0.2]  # x within 3 sigma, z not
    variance = r.signal("estimate_variance", 15)
    variance[:] = 1e-6
    variance[:, :3] = 0.1**2
    variance[:, 3:6] = 0.05**2
    return r


def test_errors_and_the_three_sigma_fraction_of_known_offsets():
    m = estimate_metrics(_rollout())
    half_norm = math.hypot(0.2, 0.5)
    assert m["estimate_position_error_rms_m"] == pytest.approx(half_norm / math.sqrt(2), rel=1e-12)
    assert m["estimate_position_error_max_m"] == pytest.approx(half_norm, rel=1e-12)
    assert m["estimate_position_error_final_m"] == 0.0
    assert m["estimate_velocity_error_rms_m_s"] == pytest.approx(math.hypot(0.1, 0.2), rel=1e-12)
    assert m["estimate_attitude_error_max_rad"] == pytest.approx(0.0, abs=1e-12)
    # per sample, 9 components: first half 7 within 3 sigma (y off by 0.5 > 0.3 m, vz off by
    # 0.2 > 0.15 m/s), second half 8 (vz)
    assert m["estimate_within_3_sigma_fraction"] == pytest.approx((7 + 8) / 18, rel=1e-12)


def test_no_estimate_no_metrics():
    r = _rollout()
    del r.signals["estimate_variance"]
    assert estimate_metrics(r) == {}
