"""Minimum-norm solutions of J x = b: the paper's (weighted) pseudo-inverse, eq. (9) and remark.

Two ways to the same J^# b, for an m x n matrix J (m <= n) and weights W = diag(w) > 0:

- :func:`pseudo_inverse`: the exact definition through the SVD, J^# = W^-1/2 (J W^-1/2)^+,
  singular values below ``relative_cutoff * s_max`` treated as zero (numerical rank). It
  works at any rank; it is the reference.
- :class:`MinimumNormSolver`: when J has full row rank (the UVMS case: the vehicle's six
  columns alone span the task space), J^# = W^-1 J^T (J W^-1 J^T)^-1, solved with a
  Cholesky factor of the m x m Gram matrix G = J W^-1 J^T and one step of iterative
  refinement (the corrected semi-normal equations). It returns None whenever it cannot
  vouch for the SVD's answer to ~1e-13: G not positive definite, or a certified bound of
  cond(J W^-1/2) too large (see :meth:`MinimumNormSolver.solve`). The caller then uses the
  SVD.

If J has full row rank and T is invertible, (T J)^# = J^# T^-1 (both are the minimum
W-norm x with J x = T^-1 b), which lets a caller factor out well-known invertible row
operations (e.g. the Euler-rate matrix of the analytical Jacobian) before solving.
"""

from __future__ import annotations

import numpy as np

#: Above this certified bound of cond(J W^-1/2)^2 the solution is refined once: below it the
#: normal equations' error ~cond^2 * 1e-16 is already ~1e-13 or less.
REFINE_ABOVE_CONDITION_BOUND = 1e3
#: Largest certified bound of cond(J W^-1/2)^2 for which the Cholesky route is used. The
#: bound lies between cond(G) and m^2 cond(G) = 36 cond(G) (G = J W^-1 J^T): this admits every
#: cond(J W^-1/2) below ~530 and none above ~3200. The refined solution's error grows like
#: cond * 1e-16 (measured against the SVD: <= 2e-13 relative at cond = 1e3).
MAX_GRAM_CONDITION_BOUND = 1e7


def pseudo_inverse(
    matrix: np.ndarray, relative_cutoff: float, weights: np.ndarray | None = None
) -> np.ndarray:
    """Moore-Penrose pseudo-inverse through the SVD, or its weighted form.

    Singular values ``s_i <= relative_cutoff * s_max`` are treated as zero (numerical
    rank); the others are inverted exactly (no damping), as in the paper's eq. (9).
    With ``weights`` w (columns), J^# = W^-1/2 (J W^-1/2)^+, i.e. the minimum of
    x^T W x among the least-squares solutions of J x = b.
    """
    if weights is not None:
        scale = 1.0 / np.sqrt(weights)
        return scale[:, None] * pseudo_inverse(matrix * scale[None, :], relative_cutoff)
    u, s, vt = np.linalg.svd(matrix, full_matrices=False)
    if s.size == 0 or s[0] == 0.0:
        return np.zeros(matrix.shape[::-1])
    keep = s > relative_cutoff * s[0]
    s_inv = np.zeros_like(s)
    s_inv[keep] = 1.0 / s[keep]
    return (vt.T * s_inv) @ u.T


class MinimumNormSolver:
    """x = J^# b = W^-1 J^T (J W^-1 J^T)^-1 b for full-row-rank J, or None.

    Args:
        weights: W's diagonal (n,), > 0, or None for W = I (the Moore-Penrose inverse).
        relative_cutoff: the SVD route's numerical-rank cutoff; the Cholesky route is only
            taken when the certified condition bound shows that the SVD keeps every
            singular value (cond(J W^-1/2) < 1 / relative_cutoff).
    """

    def __init__(self, weights: np.ndarray | None, relative_cutoff: float):
        self._weights = None if weights is None else np.asarray(weights, float)
        self._inverse_weights = None if weights is None else 1.0 / self._weights
        # the SVD keeps every singular value iff cond < 1 / cutoff, i.e. cond^2 < cutoff^-2
        cutoff_squared = float(relative_cutoff) ** 2
        self._max_bound = (
            MAX_GRAM_CONDITION_BOUND
            if cutoff_squared == 0.0
            else min(MAX_GRAM_CONDITION_BOUND, 1.0 / cutoff_squared)
        )

    @property
    def max_condition_bound(self) -> float:
        """The largest certified bound of cond(J W^-1/2)^2 for which :meth:`solve` answers."""
        return self._max_bound

    def solve(self, jacobian: np.ndarray, rhs: np.ndarray) -> np.ndarray | None:
        """The minimum W-norm solution x (n,) of J x = b, or None (use the SVD instead).

        With G = J W^-1 J^T = L L^T (Cholesky) and Y = G^-1 J W^-1 (two triangular solves
        with n right-hand sides), J^# = Y^T:

            x1 = W^-1 J^T G^-1 b;  r = b - J x1,  x = x1 + W^-1 J^T G^-1 r.

        The refinement step (taken when the condition bound is above
        :data:`REFINE_ABOVE_CONDITION_BOUND`) turns the normal equations' error ~cond^2 eps
        into ~cond eps.
        The rank and accuracy check is certified, not estimated: lambda_max(G) <= tr G and
        1 / lambda_min(G) <= tr G^-1 = tr(Y W Y^T), so cond(G) <= tr G tr G^-1 <= m^2 cond(G);
        None when that bound exceeds :data:`MAX_GRAM_CONDITION_BOUND` (or 1 / cutoff^2),
        or when G is not numerically positive definite.
        """
        # scipy.linalg is imported where it is used (0.24 us a call once loaded), not by every
        # start-up (a sixth of a second)
        from scipy.linalg import lapack

        weighted = jacobian if self._inverse_weights is None else jacobian * self._inverse_weights
        # G is symmetric: hand LAPACK its Fortran-ordered transpose (no copy)
        gram = np.dot(weighted, jacobian.T).T
        factor, info = lapack.dpotrf(gram, lower=1, overwrite_a=1)
        if info != 0:
            return None
        # Y = G^-1 J W^-1 (6 x n), so J^# = W^-1 J^T G^-1 = Y^T and G^-1 = Y W Y^T
        solved, info = lapack.dpotrs(factor, weighted, lower=1)
        inverse_trace = np.vdot(solved if self._weights is None else solved * self._weights, solved)
        bound = np.vdot(weighted, jacobian) * inverse_trace
        if info != 0 or not bound <= self._max_bound:
            return None
        pseudo = solved.T
        x = np.dot(pseudo, rhs)
        if bound > REFINE_ABOVE_CONDITION_BOUND:
            x += np.dot(pseudo, rhs - np.dot(jacobian, x))
        return x
