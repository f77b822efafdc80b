"""Buoyancy and the Froude-Krylov load: the undisturbed pressure field on the displaced volume.

The pressure of the undisturbed flow pushes a submerged body with -grad p integrated over
its volume: rho V (Du/Dt - g) at the centre of buoyancy. Its -rho V g part is buoyancy
(gravity itself is Pinocchio's); its rho V Du/Dt part is the Froude-Krylov force of an
accelerating flow (waves), zero in still water or a uniform constant current.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.hydro.vector import cross3, mat_t_vec, skew


def buoyancy_wrench(
    volume_m3: float | np.ndarray,
    center_of_buoyancy_body_m: np.ndarray,
    rotation_world_body: np.ndarray,
    water_density_kg_m3: float,
    gravity_world_m_s2: np.ndarray,
) -> np.ndarray:
    """Body-frame wrench of the buoyancy force -rho V g acting at the centre of buoyancy.

    f_b = R^T (-rho V g_world) (up for g pointing down); moment r_b x f_b about the body
    origin. Returns [f_b (N); r_b x f_b (N m)], shape (..., 6) for stacked inputs
    (volume (...), r_b (..., 3), R (..., 3, 3)).
    """
    volume = np.asarray(volume_m3, dtype=float)[..., None]
    force_world = -water_density_kg_m3 * volume * gravity_world_m_s2
    force_body = mat_t_vec(rotation_world_body, force_world)
    return np.concatenate([force_body, cross3(center_of_buoyancy_body_m, force_body)], axis=-1)


def froude_krylov_wrench(
    volume_m3: float | np.ndarray,
    center_of_buoyancy_body_m: np.ndarray,
    rotation_world_body: np.ndarray,
    water_density_kg_m3: float,
    flow_acceleration_world_m_s2: np.ndarray,
) -> np.ndarray:
    """Body-frame wrench of rho V Du/Dt acting at the centre of buoyancy (..., 6) [N; N m].

    Du/Dt (world, (..., 3)) is the flow's material acceleration at the centre of buoyancy.
    """
    volume = np.asarray(volume_m3, dtype=float)[..., None]
    force_body = mat_t_vec(
        rotation_world_body, water_density_kg_m3 * volume * flow_acceleration_world_m_s2
    )
    return np.concatenate([force_body, cross3(center_of_buoyancy_body_m, force_body)], axis=-1)


def point_force_jacobians(
    force_body_N: np.ndarray, center_of_buoyancy_body_m: np.ndarray, rotation_world_body: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Derivatives of a body wrench [f; r x f] of a world force F at a body point r, f = R^T F
    (buoyancy, Froude-Krylov): (d/d theta (..., 6, 3), d/dF (..., 6, 3)).

    theta is the body's rotation perturbation in its own axes, R -> R exp([theta]x), under
    which d(R^T F) = [R^T F]x dtheta:

        d/d theta = [[f]x; [r]x [f]x],   d/dF = [R^T; [r]x R^T].
    """
    f_hat, r_hat = skew(force_body_N), skew(center_of_buoyancy_body_m)
    rotation_t = np.swapaxes(rotation_world_body, -1, -2)
    by_rotation = np.concatenate([f_hat, np.matmul(r_hat, f_hat)], axis=-2)
    by_force = np.concatenate([rotation_t, np.matmul(r_hat, rotation_t)], axis=-2)
    return by_rotation, by_force


def buoyancy_potential_energy(
    volume_m3: float,
    center_of_buoyancy_world_m: np.ndarray,
    water_density_kg_m3: float,
    gravity_world_m_s2: np.ndarray,
) -> float:
    """U_b = rho V g_world . p_b [J]: the potential whose negative gradient is the buoyancy force."""
    return float(water_density_kg_m3 * volume_m3 * gravity_world_m_s2 @ center_of_buoyancy_world_m)
