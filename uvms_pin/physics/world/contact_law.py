"""The contact law at one point: a Hunt-Crossley normal force that never pulls, and Coulomb
friction with static and kinetic coefficients held by a tangential spring (pure functions).

Normal (depth delta > 0 into the object, rate delta_dot = -n . v_rel, n out of the object):

    f_n = k delta max(0, 1 + d delta_dot)                                       [N]

k [N/m] per contact point, d [s/m] the Hunt-Crossley dissipation: the force is zero at
first touch (no jump), grows with the depth, and the max(0, .) keeps it from pulling when
the bodies separate fast (then it is zero, never negative).

Friction: each contact point keeps an anchor a, where it stuck (`FrictionMemory`). With
s the tangential part of x - a and v_t the tangential velocity, the trial force

    f_trial = -k_t s - c_t v_t

is applied while it is within the friction cone (stick: no creep, the spring holds the
load); outside, the point slips with the kinetic friction along f_trial. The cone bounds a
patch, the points of one piece on one object: |sum f_trial| <= mu_s sum f_n. A slipping
patch slips on while |sum f_trial| > mu_k sum f_n (it sticks again below: Coulomb's
static-kinetic hysteresis). After each control period
(`uvms_pin.physics.world.world.FrictionMemory`) a slipping point's anchor moves to where
the spring gives its share of the kinetic force. This is the regularization: Coulomb's law with its set-valued stick replaced
by a stiff tangential spring (k_t, c_t), the only smoothing an explicit integrator needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvms_pin.checks import nonnegative, number_fields, positive
from uvms_pin.errors import ParameterError

__all__ = ["ContactLaw", "friction_force_N", "normal_force_N"]


@dataclass(frozen=True)
class ContactLaw:
    """The parameters of the contact law (``[world.contact]``).

    Attributes:
        stiffness_N_m: k, normal stiffness per contact point [N/m] (> 0).
        dissipation_s_m: d, Hunt-Crossley dissipation [s/m] (>= 0).
        friction_static, friction_kinetic: mu_s >= mu_k >= 0 (defaults for each object).
        tangential_stiffness_N_m: k_t, the stick spring per point [N/m] (> 0).
        tangential_damping_N_s_m: c_t [N s/m] (>= 0).
    """

    stiffness_N_m: float = 2.0e4
    dissipation_s_m: float = 1.0
    friction_static: float = 0.6
    friction_kinetic: float = 0.5
    tangential_stiffness_N_m: float = 2.0e4
    tangential_damping_N_s_m: float = 200.0

    def __post_init__(self) -> None:
        number_fields(self)
        for name in ("stiffness_N_m", "tangential_stiffness_N_m"):
            positive(f"contact {name}", getattr(self, name))
        for name in ("dissipation_s_m", "tangential_damping_N_s_m"):
            nonnegative(f"contact {name}", getattr(self, name))
        check_friction(self.friction_static, self.friction_kinetic, "[world.contact]")

    def record(self) -> dict[str, float]:
        return {k: float(v) for k, v in self.__dict__.items()}


def check_friction(static: float, kinetic: float, where: str) -> None:
    """ParameterError unless mu_s >= mu_k >= 0, both finite."""
    if not (math.isfinite(static) and math.isfinite(kinetic) and static >= kinetic >= 0.0):
        raise ParameterError(
            f"{where}: friction needs friction_static >= friction_kinetic >= 0, got "
            f"friction_static = {static}, friction_kinetic = {kinetic}"
        )


def normal_force_N(law: ContactLaw, depth_m: np.ndarray, rate_m_s: np.ndarray) -> np.ndarray:
    """f_n = k delta max(0, 1 + d delta_dot) (n,) [N]: >= 0, zero at zero depth."""
    return law.stiffness_N_m * depth_m * np.maximum(0.0, 1.0 + law.dissipation_s_m * rate_m_s)


def friction_force_N(
    law: ContactLaw,
    normal_N: np.ndarray,
    slip_m: np.ndarray,
    tangential_velocity_m_s: np.ndarray,
    patch: np.ndarray,
    mu_stick: np.ndarray,
    mu_kinetic: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(f_t (n, 3) [N], sticking (n,) bool) at points with tangential spring stretch s and
    tangential velocity v_t (n, 3), grouped in patches (``patch`` (n,): the points of one
    piece on one object).

    A patch sticks while |sum f_trial| <= mu sum f_n (``mu_stick`` per point, the same
    within a patch: mu_s, or mu_k for a patch already slipping), each point then getting
    its f_trial = -k_t s - c_t v_t; else it slips, every f_trial scaled so that the patch's
    friction is mu_k sum f_n along sum f_trial. Coulomb's law bounds the friction of a
    rigid patch, not of each of its points (how a load spreads over the corners of a box
    is statically indeterminate): a box on a slope holds while tan(theta) < mu_s, whatever
    the tipping moment does to its corners' loads."""
    trial = -law.tangential_stiffness_N_m * slip_m - law.tangential_damping_N_s_m * (
        tangential_velocity_m_s
    )
    groups, member = np.unique(patch, return_inverse=True)
    width = len(groups)
    total = np.column_stack([np.bincount(member, trial[:, k], width) for k in range(3)])
    load = np.bincount(member, normal_N, width)
    size = np.linalg.norm(total, axis=1)
    limit = np.zeros(width)
    limit[member] = mu_stick
    kinetic = np.zeros(width)
    kinetic[member] = mu_kinetic
    stick = size <= limit * load
    scale = np.where(stick, 1.0, kinetic * load / np.where(size > 0.0, size, 1.0))
    return trial * scale[member][:, None], stick[member]
