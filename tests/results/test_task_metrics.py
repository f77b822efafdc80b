"""Tracking metrics on rollouts whose errors are known in closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.results.rollout_data import RolloutData
from uvms_pin.results.task_metrics import settling_time, task_metrics


def _rollout(error_m: np.ndarray, rotation_rad: np.ndarray, transient_s: float) -> RolloutData:
    n = len(error_m)
    r = RolloutData.allocate(
        n, 11, 10, {"task": {"transient_s": transient_s, "settle_tolerance_m": 0.01}}
    )
    r.time_s[:] = np.arange(n) * 0.1
    r.q[:] = 0.0
    r.v[:] = 1.0
    r.tau[:] = 2.0
    angle = np.linspace(0.0, np.pi, n)
    reference = np.column_stack([np.cos(angle), np.sin(angle), np.zeros(n)])  # half circle
    r.signals["task_reference_position"] = reference
    r.signals["task_position"] = reference + np.column_stack([error_m, np.zeros((n, 2))])
    r.signals["task_rotation_error"] = np.column_stack([np.zeros(n), rotation_rad, np.zeros(n)])
    return r


def test_errors_path_length_and_energy():
    n = 101
    error = np.where(np.arange(n) < 20, 0.05, 0.003)  # 5 cm until t = 2 s, then 3 mm
    rotation = np.full(n, 0.02)
    metrics = task_metrics(_rollout(error, rotation, transient_s=2.0))
    assert metrics["task_position_error_rms_m"] == pytest.approx(0.003)
    assert metrics["task_position_error_max_m"] == pytest.approx(0.003)
    assert metrics["task_orientation_error_rms_rad"] == pytest.approx(0.02)
    assert metrics["task_settling_time_s"] == pytest.approx(2.0)
    assert metrics["task_settled"] == 1.0
    chord = 2 * np.sin(np.pi / (n - 1) / 2)
    assert metrics["task_reference_path_length_m"] == pytest.approx((n - 1) * chord)
    # |tau_i v_i| = 2 on 10 velocities, 101 samples of 0.1 s
    assert metrics["task_actuation_energy_J"] == pytest.approx(20.0 * n * 0.1)


def test_settling_time_never_and_always():
    t = np.arange(5.0)
    assert math.isnan(settling_time(t, np.array([0, 0, 0, 0, 1.0]), 0.5))
    assert settling_time(t, np.zeros(5), 0.5) == 0.0
    assert settling_time(t, np.array([1.0, 0, 1.0, 0, 0]), 0.5) == 3.0
    no_task = RolloutData.allocate(3, 11, 10)
    assert task_metrics(no_task) == {}
