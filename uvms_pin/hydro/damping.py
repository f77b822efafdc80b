"""Viscous damping: linear plus quadratic in the current-relative velocity."""

from __future__ import annotations

import numpy as np

from uvms_pin.hydro.vector import mat_vec


def damping_wrench(
    linear_damping: np.ndarray, quadratic_damping: np.ndarray, relative_velocity_body: np.ndarray
) -> np.ndarray:
    """Wrench of the fluid on the body: -(D_lin nu_r + diag(D_quad) |nu_r| nu_r).

    Args:
        linear_damping: D_lin (..., 6, 6) [N/(m/s), N m/(rad/s)].
        quadratic_damping: diagonal of D_quad (..., 6) [N/(m/s)^2, N m/(rad/s)^2].
        relative_velocity_body: nu_r = nu - nu_c (..., 6), body frame [m/s; rad/s].

    Returns:
        Body-frame wrench (..., 6) [N; N m]. Its power nu_r . w <= 0 (dissipative) for
        positive semi-definite D_lin and non-negative D_quad.
    """
    nu_r = relative_velocity_body
    return -mat_vec(linear_damping, nu_r) - quadratic_damping * np.abs(nu_r) * nu_r


def damping_jacobian(
    linear_damping: np.ndarray, quadratic_damping: np.ndarray, relative_velocity_body: np.ndarray
) -> np.ndarray:
    """d(damping wrench)/d nu_r (..., 6, 6) = -(D_lin + diag(2 D_quad |nu_r|)).

    d(|x| x)/dx = 2 |x|: the quadratic law is continuously differentiable (its second
    derivative jumps at x = 0).
    """
    diagonal = 2.0 * quadratic_damping * np.abs(relative_velocity_body)
    return -(linear_damping + diagonal[..., :, None] * np.eye(6))
