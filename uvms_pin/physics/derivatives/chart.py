"""The local chart's rate and its derivative: what a Runge-Kutta step in the chart at q0
(`uvms_pin.sim.integrators.RK4`) differentiates.

In the chart q = q0 (+) delta ((+): pin.integrate) a body velocity v reads as the chart rate

    delta_dot = Jint(delta)^-1 v,        Jint = d(q0 (+) delta)/d delta   (pin.dIntegrate ARG1)

and the RK4 step's Jacobian needs its derivative in delta, G(delta, v) = d/d delta
[Jint(delta)^-1 v] (v held). Jint is block-diagonal over the joints and does not depend on
q0 for the joints handled here: the identity for revolute, prismatic and continuous (SO(2))
joints, the right Jacobian of the exponential for a spherical joint (SO(3), pin.Jexp3) and
for the free flyer (SE(3), pin.Jexp6; the twist delta = (rho, phi), linear first).

Derivation (SO(3) and SE(3) alike). The right Jacobian of exp is Jr(delta) =
(I - exp(-ad))/ad with ad = ad_delta (ad_delta y = [delta, y]: phi^ on so(3);
[[phi^, rho^], [0, phi^]] on se(3)), so Jr^-1 = f(ad) with

    f(x) = x / (1 - e^-x) = 1 + x/2 + (g(x) - 1),    g(x) = (x/2) coth(x/2) even.

A function of a matrix is the polynomial interpolating f on the matrix's minimal
polynomial. On so(3), ad^3 = -theta^2 ad (theta = |phi|), eigenvalues 0, +-i theta:

    Jr^-1 = I + ad/2 + beta ad^2,         beta = (1 - gamma) / theta^2

with gamma(theta) = g(i theta) = (theta/2) cot(theta/2). On se(3), ad (ad^2 + theta^2)^2 = 0:
+-i theta are double roots, so f is matched in value and slope there (Hermite):
-c2 theta^2 + c4 theta^4 = gamma - 1 and 2 c2 theta - 4 c4 theta^3 = -gamma', i.e.

    Jr^-1 = I + ad/2 + c2 ad^2 + c4 ad^4,
    c2 = 2 (1 - gamma)/theta^2 + gamma'/(2 theta),   c4 = (1 - gamma)/theta^4 + gamma'/(2 theta^3)

(c2 - theta^2 c4 = beta: the diagonal blocks are the SO(3) inverse). Both are
Jr^-1 = sum_k c_k(theta) ad^k. Its derivative applied to w, with d theta/d delta =
phi_bar^T / theta (phi_bar: delta's angular part, zero linear part) and d(ad_delta y)/d delta
= -ad_y (the bracket is antisymmetric):

    G(delta, w) = sum_k (c_k'/theta) (ad^k w) phi_bar^T
                  - sum_k c_k sum_{j<k} ad^j ad_(ad^(k-1-j) w).

Near theta = 0 the closed forms cancel: below theta = 1 the coefficients are their series
in the Bernoulli numbers, 1 - gamma = sum_{k>=1} b_k theta^2k with b_k = |B_2k| / (2k)!,
which give beta = sum b_k theta^(2k-2), c2 = sum (2 - k) b_k theta^(2k-2),
c4 = sum (1 - k) b_k theta^(2k-4) and their derivatives term by term (the series converge
for theta < 2 pi; of the ten terms kept, the first left out is b_11 = 6e-18 at theta = 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError

#: b_k = |B_2k| / (2k)!, k = 1..10 (B_2k the Bernoulli numbers): 1 - gamma = sum b_k theta^2k
_BERNOULLI_2K = (
    Fraction(1, 6),
    Fraction(1, 30),
    Fraction(1, 42),
    Fraction(1, 30),
    Fraction(5, 66),
    Fraction(691, 2730),
    Fraction(7, 6),
    Fraction(3617, 510),
    Fraction(43867, 798),
    Fraction(174611, 330),
)
_B = tuple(float(b / math.factorial(2 * k)) for k, b in enumerate(_BERNOULLI_2K, start=1))

#: below this rotation angle [rad] the coefficients are summed from their series
_SERIES_BELOW_RAD = 1.0

#: joints that hold other joints: refused (their chart is their parts')
_NESTED_JOINTS = ("JointModelComposite", "JointModelMimic")


def _gamma_derivatives(theta: float) -> tuple[float, float, float]:
    """(1 - gamma, gamma', gamma'') for gamma(theta) = (theta/2) cot(theta/2), theta >= 1."""
    s, c = math.sin(0.5 * theta), math.cos(0.5 * theta)
    one_minus_gamma = 1.0 - 0.5 * theta * c / s
    gamma_1 = 0.5 * c / s - 0.25 * theta / s**2
    gamma_2 = -0.5 / s**2 + 0.25 * theta * c / s**3
    return one_minus_gamma, gamma_1, gamma_2


def _series(theta: float, weight, first_k: int, power_shift: int) -> float:
    """sum_{k >= first_k} weight(k) b_k theta^(2k - power_shift)."""
    return sum(
        weight(k) * b * theta ** (2 * k - power_shift)
        for k, b in enumerate(_B, start=1)
        if k >= first_k
    )


def so3_coefficients(theta: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """((c_0, c_1, c_2), (c_0'/theta, c_1'/theta, c_2'/theta)) of Jr^-1 = sum c_k ad^k on
    so(3): c = (1, 1/2, beta)."""
    if theta < _SERIES_BELOW_RAD:
        beta = _series(theta, lambda k: 1.0, 1, 2)
        beta_1 = _series(theta, lambda k: 2.0 * (k - 1), 2, 4)
    else:
        u, g1, _ = _gamma_derivatives(theta)
        beta = u / theta**2
        beta_1 = -g1 / theta**3 - 2.0 * u / theta**4
    return (1.0, 0.5, beta), (0.0, 0.0, beta_1)


def se3_coefficients(theta: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """((c_0, .., c_4), (c_0'/theta, .., c_4'/theta)) of Jr^-1 = sum c_k ad^k on se(3):
    c = (1, 1/2, c2, 0, c4)."""
    if theta < _SERIES_BELOW_RAD:
        c2 = _series(theta, lambda k: 2.0 - k, 1, 2)
        c2_1 = _series(theta, lambda k: 2.0 * (k - 1) * (2.0 - k), 2, 4)
        c4 = _series(theta, lambda k: 1.0 - k, 2, 4)
        c4_1 = _series(theta, lambda k: 2.0 * (k - 2) * (1.0 - k), 3, 6)
    else:
        u, g1, g2 = _gamma_derivatives(theta)
        c2 = 2.0 * u / theta**2 + 0.5 * g1 / theta
        c2_1 = -4.0 * u / theta**4 - 2.5 * g1 / theta**3 + 0.5 * g2 / theta**2
        c4 = u / theta**4 + 0.5 * g1 / theta**3
        c4_1 = -4.0 * u / theta**6 - 2.5 * g1 / theta**5 + 0.5 * g2 / theta**4
    return (1.0, 0.5, c2, 0.0, c4), (0.0, 0.0, c2_1, 0.0, c4_1)


def so3_ad(phi: np.ndarray) -> np.ndarray:
    """ad_phi = phi^ (3, 3) on so(3)."""
    return pin.skew(phi)


def se3_ad(twist: np.ndarray) -> np.ndarray:
    """ad_delta (6, 6) on se(3) for delta = (rho, phi), linear first (Pinocchio's Motion)."""
    out = np.zeros((6, 6))
    out[:3, :3] = out[3:, 3:] = pin.skew(twist[3:])
    out[:3, 3:] = pin.skew(twist[:3])
    return out


def exp_inverse_and_derivative(
    delta: np.ndarray, w: np.ndarray, se3: bool
) -> tuple[np.ndarray, np.ndarray]:
    """(Jr(delta)^-1, G(delta, w) = d/d delta [Jr(delta)^-1 w]) on SO(3) (delta = phi, 3)
    or SE(3) (delta = (rho, phi), 6): see the module docstring."""
    ad_of = se3_ad if se3 else so3_ad
    phi = delta[-3:]
    theta = float(np.linalg.norm(phi))
    coefficients, slopes = se3_coefficients(theta) if se3 else so3_coefficients(theta)
    n = delta.size
    ad = ad_of(delta)
    powers = [np.eye(n)]  # ad^k
    for _ in range(len(coefficients) - 1):
        powers.append(ad @ powers[-1])
    images = [p @ w for p in powers]  # ad^k w
    phi_bar = np.zeros(n)
    phi_bar[-3:] = phi
    inverse = sum(c * p for c, p in zip(coefficients, powers, strict=True))
    derivative = np.zeros((n, n))
    for k, (c, slope) in enumerate(zip(coefficients, slopes, strict=True)):
        if slope != 0.0:
            derivative += slope * np.outer(images[k], phi_bar)
        if c != 0.0:
            for j in range(k):
                derivative -= c * powers[j] @ ad_of(images[k - 1 - j])
    return inverse, derivative


@dataclass(frozen=True)
class ChartBlocks:
    """Where a model's chart Jacobian is not the identity: the velocity offsets of its
    free flyers (SE(3), 6) and spherical joints (SO(3), 3)."""

    se3: tuple[int, ...]
    so3: tuple[int, ...]

    @classmethod
    def of(cls, model: pin.Model) -> ChartBlocks:
        """The blocks of ``model``; the other joints must have an identity chart Jacobian
        (a vector space, or SO(2)): another kind (planar, composite, mimic) is refused with a
        ParameterError."""
        se3, so3 = [], []
        for j in range(1, model.njoints):
            joint, kind = model.joints[j], model.joints[j].shortname()
            if kind == "JointModelFreeFlyer":
                se3.append(joint.idx_v)
            elif kind == "JointModelSpherical":
                so3.append(joint.idx_v)
            elif kind.startswith(_NESTED_JOINTS) or (joint.nq, joint.nv) not in {
                (joint.nv, joint.nv),  # a vector space
                (2, 1),  # SO(2) in (cos, sin): a continuous joint
            }:
                raise ParameterError(
                    f"the chart derivatives know free-flyer, spherical, revolute, prismatic "
                    f"and continuous joints; joint '{model.names[j]}' is {kind}"
                )
        return cls(tuple(se3), tuple(so3))

    def rate(self, delta: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(Jint(delta)^-1 (nv, nv), G(delta, v) = d/d delta [Jint(delta)^-1 v] (nv, nv))."""
        nv = delta.size
        inverse, derivative = np.eye(nv), np.zeros((nv, nv))
        for offsets, size in ((self.se3, 6), (self.so3, 3)):
            for i in offsets:
                block = slice(i, i + size)
                inverse[block, block], derivative[block, block] = exp_inverse_and_derivative(
                    delta[block], v[block], se3=size == 6
                )
        return inverse, derivative
