"""Minimum-norm solutions: the Cholesky route against the SVD definition, and its refusals."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.control.pseudo_inverse import (
    MAX_GRAM_CONDITION_BOUND,
    MinimumNormSolver,
    pseudo_inverse,
)


def matrix_with_condition(rng, condition: float, n: int = 10) -> np.ndarray:
    """A random 6 x n matrix with singular values from 1 down to 1 / condition."""
    u, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    v, _ = np.linalg.qr(rng.normal(size=(n, 6)))
    return (u * np.logspace(0, -np.log10(condition), 6)) @ v.T


@pytest.mark.parametrize("condition", [1.0, 10.0, 100.0, 1000.0])
@pytest.mark.parametrize("weighted", [False, True])
def test_agrees_with_the_svd_definition(condition, weighted):
    """The refined semi-normal equations are within 1e-12 of W^-1/2 (J W^-1/2)^+ b."""
    rng = np.random.default_rng(int(condition) + weighted)
    for _ in range(50):
        weights = rng.uniform(0.5, 2.0, 10) if weighted else None
        scale = 1.0 if weights is None else np.sqrt(weights)
        jacobian = matrix_with_condition(rng, condition) * scale  # cond(J W^-1/2) = condition
        rhs = rng.normal(size=6)
        x = MinimumNormSolver(weights, 1e-12).solve(jacobian, rhs)
        assert x is not None
        reference = pseudo_inverse(jacobian, 1e-12, weights) @ rhs
        assert np.abs(x - reference).max() <= 1e-12 * np.abs(reference).max()
        np.testing.assert_allclose(jacobian @ x, rhs, atol=1e-12 * condition)


def test_the_solution_is_the_minimum_weighted_norm_one():
    """Any other solution x + z (J z = 0) has a larger x^T W x."""
    rng = np.random.default_rng(3)
    weights = rng.uniform(1.0, 100.0, 10)
    jacobian = rng.normal(size=(6, 10))
    x = MinimumNormSolver(weights, 1e-12).solve(jacobian, rng.normal(size=6))
    null_basis = np.linalg.svd(jacobian)[2][6:]
    for z in rng.normal(size=(20, 4)) @ null_basis:
        assert (x + z) @ (weights * (x + z)) > x @ (weights * x)


def test_certified_bound_brackets_the_condition_number():
    """tr G tr G^-1 (the bound the solver tests) lies in [cond(G), 36 cond(G)]."""
    rng = np.random.default_rng(5)
    for condition in (1.0, 30.0, 1e3):
        jacobian = matrix_with_condition(rng, condition)
        gram = jacobian @ jacobian.T
        bound = np.trace(gram) * np.trace(np.linalg.inv(gram))
        assert np.linalg.cond(gram) * (1 - 1e-9) <= bound <= 36.0 * np.linalg.cond(gram)


@pytest.mark.parametrize("condition", [1e4, 1e8, 1e14])
def test_declines_when_ill_conditioned(condition):
    rng = np.random.default_rng(9)
    jacobian = matrix_with_condition(rng, condition)
    assert condition**2 > MAX_GRAM_CONDITION_BOUND
    assert MinimumNormSolver(None, 1e-12).solve(jacobian, np.ones(6)) is None


def test_declines_when_rank_deficient():
    rng = np.random.default_rng(4)
    jacobian = rng.normal(size=(6, 10))
    jacobian[5] = jacobian[0] - 2.0 * jacobian[3]
    assert MinimumNormSolver(None, 1e-12).solve(jacobian, np.ones(6)) is None
    jacobian[5] = 0.0
    assert MinimumNormSolver(None, 1e-12).solve(jacobian, np.ones(6)) is None


def test_declines_when_the_svd_would_cut_a_singular_value():
    """With a user cutoff of 1e-2, a matrix of condition 300 has a singular value the SVD
    route treats as zero: the solver must leave it to the SVD."""
    rng = np.random.default_rng(8)
    jacobian = matrix_with_condition(rng, 300.0)
    assert MinimumNormSolver(None, 1e-12).solve(jacobian, np.ones(6)) is not None
    assert MinimumNormSolver(None, 1e-2).solve(jacobian, np.ones(6)) is None
