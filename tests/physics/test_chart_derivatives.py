"""The local chart's rate Jint(delta)^-1 w and its derivative in delta
(`uvms_pin.physics.derivatives.chart`): the inverse against the series of the right
Jacobian, sum (-ad)^k / (k+1)!, and Pinocchio's Jexp3 / Jexp6 and dIntegrate, the derivative
against central differences of the closed form, on both sides of the series' threshold
(theta = 1 rad) and from 1e-6 rad to 3 rad."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import central_difference, with_spherical_joint

from uvms_pin.errors import ParameterError
from uvms_pin.physics.derivatives import chart
from uvms_pin.physics.derivatives.chart import (
    ChartBlocks,
    exp_inverse_and_derivative,
    se3_ad,
    so3_ad,
)

ANGLES_RAD = (1e-6, 1e-3, 0.05, 0.5, 0.999, 1.001, 2.0, 3.0)


def _rate(delta: np.ndarray, w: np.ndarray) -> np.ndarray:
    return exp_inverse_and_derivative(delta, w, se3=delta.size == 6)[0] @ w


@pytest.mark.parametrize("size", [3, 6], ids=["SO3", "SE3"])
@pytest.mark.parametrize("theta", ANGLES_RAD)
def test_exp_inverse_and_its_derivative(size, theta):
    rng = np.random.default_rng(int(theta * 1e6) + size)
    delta = rng.normal(size=size)
    delta *= theta / np.linalg.norm(delta[-3:])  # the rotation angle |phi| = theta
    w = rng.normal(size=size)
    inverse, derivative = exp_inverse_and_derivative(delta, w, se3=size == 6)
    ad = se3_ad(delta) if size == 6 else so3_ad(delta)
    right_jacobian = sum(np.linalg.matrix_power(-ad, k) / math.factorial(k + 1) for k in range(40))
    np.testing.assert_allclose(inverse @ right_jacobian, np.eye(size), rtol=0, atol=1e-14)
    # Pinocchio's Jexp6 is the same to 2e-11 near theta = 1e-3 (its small-angle branch)
    jexp = pin.Jexp6(pin.Motion(delta)) if size == 6 else pin.Jexp3(delta)
    np.testing.assert_allclose(inverse @ jexp, np.eye(size), rtol=0, atol=1e-10)
    fd = central_difference(lambda d: _rate(d, w), delta, size, 1e-4)
    error = np.max(np.abs(derivative - fd)) / np.max(np.abs(fd))
    assert error < 1e-8, error


@pytest.mark.parametrize("theta", [0.3, 0.7, 1.0])
def test_the_series_and_the_closed_forms_agree(theta, monkeypatch):
    """Either branch of the coefficients at the same angle, near the threshold (1 rad)."""
    rng = np.random.default_rng(3)
    for size in (3, 6):
        delta, w = rng.normal(size=size), rng.normal(size=size)
        delta *= theta / np.linalg.norm(delta[-3:])
        monkeypatch.setattr(chart, "_SERIES_BELOW_RAD", 10.0)
        series = exp_inverse_and_derivative(delta, w, se3=size == 6)
        monkeypatch.setattr(chart, "_SERIES_BELOW_RAD", 0.0)
        closed = exp_inverse_and_derivative(delta, w, se3=size == 6)
        for s, c in zip(series, closed, strict=True):
            np.testing.assert_allclose(s, c, rtol=0, atol=1e-13)


def test_a_model_chart_is_its_joints_blocks(reference_uvms):
    """Free flyer (SE(3)), ball (SO(3)) and revolute joints: the model's inverse chart
    Jacobian is Pinocchio's dIntegrate ARG1 inverted, at any q0."""
    uvms = with_spherical_joint(reference_uvms, 3)
    model, rng = uvms.model, np.random.default_rng(5)
    chart = ChartBlocks.of(model)
    assert chart.se3 == (0,) and chart.so3 == (model.joints[3].idx_v,)
    delta, w = rng.normal(scale=0.8, size=model.nv), rng.normal(size=model.nv)
    inverse, derivative = chart.rate(delta, w)
    q0 = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    jint = pin.dIntegrate(model, q0, delta, pin.ARG1)
    np.testing.assert_allclose(inverse @ jint, np.eye(model.nv), rtol=0, atol=1e-12)
    fd = central_difference(lambda d: chart.rate(d, w)[0] @ w, delta, model.nv, 1e-4)
    assert np.max(np.abs(derivative - fd)) < 1e-8 * np.max(np.abs(fd))


def test_a_joint_without_a_known_chart_is_refused():
    model = pin.Model()
    model.addJoint(0, pin.JointModelPlanar(), pin.SE3.Identity(), "sled")
    with pytest.raises(ParameterError, match="'sled' is JointModelPlanar"):
        ChartBlocks.of(model)


def _bernoulli_even(count: int) -> list:
    """B_2, B_4, ..., B_2count as exact fractions, from the Akiyama-Tanigawa algorithm (an
    independent derivation of the numbers the chart's series is written in)."""
    from fractions import Fraction

    row, numbers = [], []
    for m in range(2 * count + 1):
        row.append(Fraction(1, m + 1))
        for j in range(m, 0, -1):
            row[j - 1] = j * (row[j - 1] - row[j])
        numbers.append(row[0])
    return [numbers[2 * k] for k in range(1, count + 1)]


def test_the_series_coefficients_are_the_bernoulli_numbers():
    """Each b_k of the series below 1 rad is |B_2k| / (2k)! (its last terms are far below
    any rounding at 1 rad: only the table itself can show a wrong one)."""
    expected = [abs(b) / math.factorial(2 * k) for k, b in enumerate(_bernoulli_even(10), 1)]
    assert [abs(b) for b in chart._BERNOULLI_2K] == [abs(b) for b in _bernoulli_even(10)]
    assert chart._B == tuple(float(b) for b in expected)


@pytest.mark.parametrize("theta", [0.3, 0.999])
def test_the_series_meets_the_closed_form_at_its_threshold(theta):
    """beta = (1 - gamma) / theta^2 from the series (below 1 rad) and from the closed form
    agree to rounding just below the threshold."""
    (_, _, series), _ = chart.so3_coefficients(theta)
    closed = chart._gamma_derivatives(theta)[0] / theta**2
    assert series == pytest.approx(closed, rel=1e-14)
