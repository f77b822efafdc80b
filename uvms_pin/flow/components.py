"""Linear (Airy) wave components: kinematics of a sum of regular waves, vectorized.

One component j: amplitude A_j [m], angular frequency w_j [rad/s], wavenumber k_j [rad/m]
(from the dispersion relation w^2 = g k tanh(k d)), heading beta_j (direction of travel,
world, from +x towards +y) [rad], phase phi_j [rad], water depth d [m] (inf: deep water).
With e_j = (cos beta_j, sin beta_j, 0) and theta_j = k_j e_j . p - w_j t + phi_j:

    eta     = sum A cos(theta)
    u       = sum A w [ C cos(theta) e + S sin(theta) z ]
    du/dt   = sum A w^2 [ C sin(theta) e - S cos(theta) z ]
    C = cosh(k (z + d)) / sinh(k d),   S = sinh(k (z + d)) / sinh(k d)   (both e^{kz} deep)

(the velocity potential A g / w cosh(k (z + d)) / cosh(k d) sin(theta) differentiated).
C and S are evaluated as (e^{kz} +- e^{-k (z + 2d)}) / (1 - e^{-2kd}), which never
overflows and is exact for d = inf.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvms_pin.checks import number, positive
from uvms_pin.errors import ParameterError
from uvms_pin.flow.base import FlowField, as_points

STANDARD_GRAVITY_M_S2 = 9.81


def wavenumber(
    angular_frequency_rad_s: float,
    water_depth_m: float = math.inf,
    gravity_m_s2: float = STANDARD_GRAVITY_M_S2,
) -> float:
    """k [rad/m] solving the linear dispersion relation w^2 = g k tanh(k d) (Newton).

    Deep water (d = inf): k = w^2 / g. Converges to machine precision from Eckart's
    approximation.
    """
    w = number("angular frequency", angular_frequency_rad_s)
    d, g = number("water_depth_m", water_depth_m), positive("gravity_m_s2", gravity_m_s2)
    if not (w > 0.0 and math.isfinite(w)):
        raise ParameterError(f"angular frequency must be positive and finite, got {w}")
    if not d > 0.0:
        raise ParameterError(f"water_depth_m must be positive (or inf), got {d}")
    k_deep = w * w / g
    if math.isinf(d) or k_deep * d > 20.0:  # tanh(20) = 1 - 8e-18
        return k_deep
    k = k_deep / math.sqrt(math.tanh(k_deep * d))  # Eckart (1952), within ~5 %
    for _ in range(50):
        t = math.tanh(k * d)
        f = g * k * t - w * w
        df = g * t + g * k * d * (1.0 - t * t)
        step = f / df
        k -= step
        if abs(step) <= 1e-15 * k:
            break
    return k


@dataclass(frozen=True)
class WaveComponents:
    """Stacked regular-wave components (arrays of equal length m) in water of depth d."""

    amplitude_m: np.ndarray
    angular_frequency_rad_s: np.ndarray
    wavenumber_rad_m: np.ndarray
    heading_rad: np.ndarray
    phase_rad: np.ndarray
    water_depth_m: float

    def _phase_and_profiles(self, time_s: float, points: np.ndarray):
        direction_x, direction_y = np.cos(self.heading_rad), np.sin(self.heading_rad)
        k = self.wavenumber_rad_m
        theta = (
            np.outer(points[:, 0], k * direction_x)
            + np.outer(points[:, 1], k * direction_y)
            - self.angular_frequency_rad_s * time_s
            + self.phase_rad
        )  # (n, m)
        kz = np.outer(points[:, 2], k)
        below = np.exp(-np.outer(points[:, 2] + 2.0 * self.water_depth_m, k))
        denominator = 1.0 - np.exp(-2.0 * k * self.water_depth_m)
        grow = np.exp(kz)
        cosh_profile = (grow + below) / denominator
        sinh_profile = (grow - below) / denominator
        return theta, cosh_profile, sinh_profile, direction_x, direction_y

    def elevation(self, time_s: float, xy: np.ndarray) -> np.ndarray:
        points = np.column_stack([xy, np.zeros(len(xy))])
        theta, *_ = self._phase_and_profiles(time_s, points)
        return np.cos(theta) @ self.amplitude_m

    def surface_kinematics(
        self, time_s: float, xy: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """eta = sum A cos(theta), d eta / dt = sum A w sin(theta),
        grad eta = -sum A k sin(theta) (cos beta, sin beta)."""
        points = np.column_stack([xy, np.zeros(len(xy))])
        theta, _, _, ex, ey = self._phase_and_profiles(time_s, points)
        sin = np.sin(theta)
        a, w, k = self.amplitude_m, self.angular_frequency_rad_s, self.wavenumber_rad_m
        akx, aky = a * k * ex, a * k * ey
        return np.cos(theta) @ a, sin @ (a * w), -np.column_stack([sin @ akx, sin @ aky])

    def velocity(self, time_s: float, points: np.ndarray) -> np.ndarray:
        theta, ch, sh, ex, ey = self._phase_and_profiles(time_s, points)
        aw = self.amplitude_m * self.angular_frequency_rad_s
        horizontal = ch * np.cos(theta) * aw
        return np.column_stack([horizontal @ ex, horizontal @ ey, (sh * np.sin(theta)) @ aw])

    def local_acceleration(self, time_s: float, points: np.ndarray) -> np.ndarray:
        theta, ch, sh, ex, ey = self._phase_and_profiles(time_s, points)
        aww = self.amplitude_m * self.angular_frequency_rad_s**2
        horizontal = ch * np.sin(theta) * aww
        return np.column_stack([horizontal @ ex, horizontal @ ey, -(sh * np.cos(theta)) @ aww])

    def kinematics(
        self, time_s: float, points: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(u, du/dt, grad u) from one evaluation of the phases and depth profiles."""
        theta, ch, sh, ex, ey = self._phase_and_profiles(time_s, points)
        cos, sin = np.cos(theta), np.sin(theta)
        a, w, k = self.amplitude_m, self.angular_frequency_rad_s, self.wavenumber_rad_m
        c_cos, c_sin, s_cos, s_sin = ch * cos, ch * sin, sh * cos, sh * sin
        aw, aww = a * w, a * w * w
        velocity = np.column_stack([c_cos @ (aw * ex), c_cos @ (aw * ey), s_sin @ aw])
        local = np.column_stack([c_sin @ (aww * ex), c_sin @ (aww * ey), -(s_cos @ aww)])
        return velocity, local, self._gradient(c_sin, s_cos, ex, ey, aw * k)

    def velocity_gradient(self, time_s: float, points: np.ndarray) -> np.ndarray:
        theta, ch, sh, ex, ey = self._phase_and_profiles(time_s, points)
        awk = self.amplitude_m * self.angular_frequency_rad_s * self.wavenumber_rad_m
        return self._gradient(ch * np.sin(theta), sh * np.cos(theta), ex, ey, awk)

    def gradient_kinematics(
        self, time_s: float, points: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(grad du/dt (n, 3, 3), Hessian of u (n, 3, 3, 3), [k, i, j, l] = d2 u_i/dx_j dx_l).

        One component's velocity gradient is A w k (C sin(theta) P + S cos(theta) Q) with
        P = z z^T - e e^T and Q = e z^T + z e^T; with grad theta = k e, dC/dz = k S and
        dS/dz = k C, its time and space derivatives are

            d/dt    = A w^2 k (-C cos(theta) P + S sin(theta) Q)
            d/dx_l  = A w k^2 [(S sin(theta) z_l + C cos(theta) e_l) P
                               + (C cos(theta) z_l - S sin(theta) e_l) Q].
        """
        theta, ch, sh, ex, ey = self._phase_and_profiles(time_s, points)
        cos, sin = np.cos(theta), np.sin(theta)
        a, w, k = self.amplitude_m, self.angular_frequency_rad_s, self.wavenumber_rad_m
        e = np.column_stack([ex, ey, np.zeros_like(ex)])  # (m, 3)
        up = np.array([0.0, 0.0, 1.0])
        p = up[None, :, None] * up[None, None, :] - e[:, :, None] * e[:, None, :]
        q = e[:, :, None] * up[None, None, :] + up[None, :, None] * e[:, None, :]
        awwk, awkk = a * w * w * k, a * w * k * k
        grad_rate = np.einsum("nm,mij->nij", -ch * cos * awwk, p) + np.einsum(
            "nm,mij->nij", sh * sin * awwk, q
        )
        s_sin, c_cos = sh * sin * awkk, ch * cos * awkk  # (n, m)
        hessian = (
            np.einsum("nm,mij,l->nijl", s_sin, p, up)
            + np.einsum("nm,mij,ml->nijl", c_cos, p, e)
            + np.einsum("nm,mij,l->nijl", c_cos, q, up)
            - np.einsum("nm,mij,ml->nijl", s_sin, q, e)
        )
        return grad_rate, hessian

    @staticmethod
    def _gradient(c_sin, s_cos, ex, ey, awk) -> np.ndarray:
        """grad u from C sin(theta), S cos(theta) (n, m) and A w k (m,)."""
        c_sin, s_cos = c_sin * awk, s_cos * awk  # (n, m)
        grad = np.empty((len(c_sin), 3, 3))
        e = (ex, ey)
        for i in range(2):
            for j in range(2):
                grad[:, i, j] = -c_sin @ (e[i] * e[j])
            grad[:, i, 2] = s_cos @ e[i]
            grad[:, 2, i] = grad[:, i, 2]  # irrotational: grad u is symmetric
        grad[:, 2, 2] = c_sin.sum(axis=1)
        return grad


class WaveField(FlowField):
    """A flow made of linear wave components (``self.components``, set by the subclass):
    it has a moving free surface, and its kinematics are those of `WaveComponents`."""

    components: WaveComponents

    def velocity(self, time_s, points_world):
        return self.components.velocity(time_s, as_points(points_world))

    def local_acceleration(self, time_s, points_world):
        return self.components.local_acceleration(time_s, as_points(points_world))

    def velocity_gradient(self, time_s, points_world):
        return self.components.velocity_gradient(time_s, as_points(points_world))

    def kinematics(self, time_s, points_world):
        return self.components.kinematics(time_s, as_points(points_world))

    def gradient_kinematics(self, time_s, points_world):
        return self.components.gradient_kinematics(time_s, as_points(points_world))

    @property
    def has_free_surface(self) -> bool:
        return True

    def surface_elevation(self, time_s, xy_world):
        return self.components.elevation(time_s, np.asarray(xy_world, dtype=float).reshape(-1, 2))

    def surface_kinematics(self, time_s, xy_world):
        xy = np.asarray(xy_world, dtype=float).reshape(-1, 2)
        return self.components.surface_kinematics(time_s, xy)

    @property
    def elevation_bound_m(self) -> float:
        """sum |A|: no point of the surface is farther from z = 0."""
        return float(np.sum(np.abs(self.components.amplitude_m)))

    def record(self) -> dict:
        """Its components, exactly (a sea state is not drawn again)."""
        c = self.components
        return {
            "type": "waves",
            "repr": repr(self),
            "amplitude_m": c.amplitude_m.tolist(),
            "angular_frequency_rad_s": c.angular_frequency_rad_s.tolist(),
            "wavenumber_rad_m": c.wavenumber_rad_m.tolist(),
            "heading_rad": c.heading_rad.tolist(),
            "phase_rad": c.phase_rad.tolist(),
            "water_depth_m": float(c.water_depth_m),
        }


class Waves(WaveField):
    """Linear waves given by their components (a recorded `AiryWave` or `IrregularSea`)."""

    def __init__(self, components: WaveComponents, label: str = "Waves"):
        self.components = components
        self._label = label

    def __repr__(self) -> str:
        return self._label
