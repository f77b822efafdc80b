"""Added mass: constant-frame transformation and the Kirchhoff (Coriolis) wrench.

A body moving with body velocity nu = [v; w] through an ideal fluid carries the fluid
kinetic energy T_A = 1/2 nu^T M_A nu. Its reaction on the body is

    w_A = -(M_A nu_dot + C_A(nu) nu),   C_A(nu) nu = nu x* (M_A nu)

so M_A enters the mass matrix and C_A(nu) nu is a velocity-product wrench that does no work
(nu^T (nu x* p) = 0). Functions take single bodies or stacks (leading axes broadcast).
"""

from __future__ import annotations

import numpy as np

from uvms_pin.hydro.vector import cross3, mat_vec, skew


def kirchhoff_wrench(added_mass: np.ndarray, velocity_body: np.ndarray) -> np.ndarray:
    """C_A(nu) nu = [w x p1; w x p2 + v x p1] with p = M_A nu (Pinocchio order).

    Args:
        added_mass: M_A (..., 6, 6) in the body frame [kg, kg m, kg m^2].
        velocity_body: nu = [v (m/s); w (rad/s)] (..., 6) in the body frame.

    Returns:
        The wrench C_A(nu) nu (..., 6) [N; N m] (the fluid exerts its negative on the body).
    """
    p = mat_vec(added_mass, velocity_body)
    v = velocity_body[..., :3]
    w = velocity_body[..., 3:]
    return np.concatenate(
        [cross3(w, p[..., :3]), cross3(w, p[..., 3:]) + cross3(v, p[..., :3])], axis=-1
    )


def kirchhoff_jacobian(added_mass: np.ndarray, velocity_body: np.ndarray) -> np.ndarray:
    """d(C_A(nu) nu)/d nu (..., 6, 6): the Kirchhoff wrench linearised about nu.

    C_A(nu) nu = nu x* p with p = M_A nu is bilinear in (nu, p):
    d(nu x* p) = (nu x*) M_A dnu + (dnu x* p), and dnu x* p = -(p xbar) dnu with
    (p xbar) = [0, [p1]x; [p1]x, [p2]x] (columns: linear, angular), so

        d(C_A nu)/d nu = (nu x*) M_A - (p xbar),   (nu x*) = [[w]x, 0; [v]x, [w]x].
    """
    p = mat_vec(added_mass, velocity_body)
    cross_star = np.zeros((*velocity_body.shape[:-1], 6, 6))
    w_hat, v_hat = skew(velocity_body[..., 3:]), skew(velocity_body[..., :3])
    cross_star[..., :3, :3] = w_hat
    cross_star[..., 3:, :3] = v_hat
    cross_star[..., 3:, 3:] = w_hat
    bar = np.zeros_like(cross_star)
    p1_hat = skew(p[..., :3])
    bar[..., :3, 3:] = p1_hat
    bar[..., 3:, :3] = p1_hat
    bar[..., 3:, 3:] = skew(p[..., 3:])
    return np.matmul(cross_star, added_mass) - bar


def added_mass_in_parent(
    added_mass_child: np.ndarray, action_parent_to_child: np.ndarray
) -> np.ndarray:
    """Express a rigidly attached body's added mass in its parent frame: X^T M_A X.

    Args:
        added_mass_child: M_A (6x6) at the child origin, in child axes.
        action_parent_to_child: X (6x6) with nu_child = X nu_parent, i.e.
            ``placement_parent_child.inverse().action``.

    Exact: the fluid energy 1/2 nu_c^T M_A nu_c equals 1/2 nu_p^T (X^T M_A X) nu_p, and the
    Kirchhoff term is frame-covariant, so added masses of rigidly joined bodies add up.
    """
    return action_parent_to_child.T @ added_mass_child @ action_parent_to_child
