"""scenarios/seabed_survey.toml: the multibeam's soundings where the geometry is, the DVL's
beam-cast lock lost over the crate alone, and the estimator running on without it."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import uvms_pin as up
from uvms_pin.results.estimate_metrics import estimate_errors

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts" / "results"))
from seabed_survey import CRATE_TOP_Z_M, SEABED_Z_M, lock_intervals, soundings  # noqa: E402


@pytest.fixture(scope="module")
def survey():
    return up.simulate(up.load_scenario(ROOT / "scenarios" / "seabed_survey.toml"))


def test_the_multibeam_soundings_lie_on_the_seabed_and_on_the_crate(survey):
    points = soundings(survey)
    assert len(points) > 5000
    off = np.hypot(points[:, 0] - 6.0, points[:, 1]) > 2.5
    seabed = off & (np.abs(points[:, 2] - SEABED_Z_M) < 0.5)
    assert seabed.sum() > 0.8 * off.sum()  # besides the rock, everything off the crate
    assert abs(points[seabed, 2].mean() - SEABED_Z_M) < 0.005
    assert points[seabed, 2].std() == pytest.approx(0.02, rel=0.3)  # the range noise
    top = np.abs(points[:, 2] - CRATE_TOP_Z_M) < 0.1
    assert top.sum() > 100
    assert abs(points[top, 2].mean() - CRATE_TOP_Z_M) < 0.01
    x, y = points[top, 0] - 6.0, points[top, 1]  # within the crate's footprint (yaw 0.3)
    assert np.all(np.hypot(x, y) < np.hypot(0.75, 1.0) + 0.1)


def test_the_dvl_loses_its_lock_over_the_crate_only_and_the_estimate_goes_on(survey):
    dvl = survey.signals["dvl"]
    lost = dvl[:, 4] == 0.0
    (start, stop), *others = lock_intervals(survey.time_s, dvl[:, 4])
    assert not others
    x = survey.q[lost, 0]
    # a beam within 1 m (its least altitude) of the crate: the crate's half-length along x
    # (1.01 m, its yaw 0.3) and the reach of a beam 1 m down along x (tan 30 deg cos 45 deg)
    reach = 0.75 * np.cos(0.3) + 1.0 * np.sin(0.3) + np.tan(np.pi / 6) * np.cos(np.pi / 4)
    assert 6.0 - reach - 0.05 < x.min() < 6.0 - 1.0 and 6.0 + 1.0 < x.max() < 6.0 + reach + 0.05
    np.testing.assert_array_equal(dvl[lost, :3], 0.0)
    assert np.all(dvl[lost, 3] < 3.0 - 0.5)  # some of its beams on the crate, 0.8 m down
    sigma = estimate_errors(survey)["velocity_sigma"][:, 0]
    before = sigma[np.searchsorted(survey.time_s, start) - 1]
    assert sigma[np.searchsorted(survey.time_s, stop)] > 3.0 * before
    assert np.all(np.isfinite(sigma))
    fls, front = survey.sonar("fls"), survey.camera("front")
    assert fls.intensity.shape[1:] == (256, 128) and front.rgb.shape[1:] == (240, 320, 3)
