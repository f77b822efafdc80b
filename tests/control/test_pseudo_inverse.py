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


# ---- the SVD reference itself, against numpy's pinv ------------------------------------------


def matrix_with_singular_values(rng, singular_values, shape=(6, 10)) -> np.ndarray:
    m, n = shape
    u, _ = np.linalg.qr(rng.normal(size=(m, m)))
    v, _ = np.linalg.qr(rng.normal(size=(n, m)))
    return (u * np.asarray(singular_values, dtype=float)) @ v.T


@pytest.mark.parametrize("shape", [(6, 10), (6, 6), (3, 7), (8, 5)])
def test_the_reference_is_numpys_pinv_at_full_rank(shape):
    rng = np.random.default_rng(shape[0] * 10 + shape[1])
    for _ in range(20):
        matrix = rng.normal(size=shape)
        expected = np.linalg.pinv(matrix, rcond=1e-12)
        np.testing.assert_allclose(
            pseudo_inverse(matrix, 1e-12), expected, rtol=0, atol=1e-12 * np.abs(expected).max()
        )


def test_the_cutoff_drops_the_same_singular_values_as_numpys_rcond():
    """Singular values 40 x (1, 0.5, 1e-3, 1e-7, 1e-13, 0): a cutoff (relative to the largest)
    between two of them keeps those above it; numpy's rcond (s > rcond s_max) draws the same
    line."""
    rng = np.random.default_rng(21)
    sigma = 40.0 * np.array([1.0, 0.5, 1e-3, 1e-7, 1e-13, 0.0])
    matrix = matrix_with_singular_values(rng, sigma)
    for cutoff, kept in ((0.7, 1), (1e-2, 2), (1e-5, 3), (1e-10, 4)):
        mine = pseudo_inverse(matrix, cutoff)
        expected = np.linalg.pinv(matrix, rcond=cutoff)
        np.testing.assert_allclose(mine, expected, rtol=0, atol=1e-9 * np.abs(expected).max())
        # the kept rank: J^# J projects onto a space of that dimension
        assert np.trace(mine @ matrix) == pytest.approx(kept, abs=1e-6)
        # what a dropped direction would have given: its 1/s dwarfs everything kept
        assert np.abs(mine).max() < 2.0 / sigma[kept - 1]


def test_a_singular_value_at_the_cutoff_is_dropped():
    """s_i = cutoff x s_max exactly (a diagonal matrix: its SVD is exact) is not above the
    cutoff: dropped, as numpy's pinv drops it."""
    matrix = np.zeros((3, 4))
    matrix[range(3), range(3)] = [4.0, 2.0, 1.0]
    mine = pseudo_inverse(matrix, 0.5)
    np.testing.assert_array_equal(mine, np.linalg.pinv(matrix, rcond=0.5))
    np.testing.assert_array_equal(np.diag(mine), [0.25, 0.0, 0.0])


def test_the_weighted_reference_is_the_minimum_weighted_norm_least_squares_solution():
    """J^# = W^-1/2 (J W^-1/2)^+: for a rank-deficient J, x = J^# b minimises |J x - b|, and
    among the minimisers x^T W x (checked against numpy's pinv of J W^-1/2)."""
    rng = np.random.default_rng(22)
    weights = rng.uniform(0.2, 5.0, 10)
    matrix = matrix_with_singular_values(rng, [3.0, 1.0, 0.2, 0.05, 0.0, 0.0])  # rank 4
    half = 1.0 / np.sqrt(weights)
    expected = half[:, None] * np.linalg.pinv(matrix * half, rcond=1e-12)
    mine = pseudo_inverse(matrix, 1e-12, weights)
    np.testing.assert_allclose(mine, expected, rtol=0, atol=1e-11 * np.abs(expected).max())
    rhs = rng.normal(size=6)
    x = mine @ rhs
    residual = matrix @ x - rhs
    np.testing.assert_allclose(matrix.T @ residual, 0.0, atol=1e-12)  # least squares
    null_basis = np.linalg.svd(matrix)[2][4:]  # J z = 0
    for z in rng.normal(size=(20, 6)) @ null_basis:
        assert (x + z) @ (weights * (x + z)) > x @ (weights * x)


def test_the_zero_matrix_has_a_zero_pseudo_inverse():
    np.testing.assert_array_equal(pseudo_inverse(np.zeros((6, 10)), 1e-12), np.zeros((10, 6)))


def test_a_single_row_or_column_has_its_pseudo_inverse():
    """One singular value: J = (3, 4) gives J^+ = J^T / |J|^2, a column the same way; the
    zero row gives zeros."""
    np.testing.assert_allclose(
        pseudo_inverse(np.array([[3.0, 4.0]]), 1e-12), [[0.12], [0.16]], rtol=1e-15
    )
    np.testing.assert_allclose(
        pseudo_inverse(np.array([[3.0], [4.0]]), 1e-12), [[0.12, 0.16]], rtol=1e-15
    )
    np.testing.assert_array_equal(pseudo_inverse(np.zeros((1, 2)), 1e-12), np.zeros((2, 1)))
