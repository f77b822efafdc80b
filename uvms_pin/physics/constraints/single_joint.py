"""The implicit step of one joint coordinate with Coulomb friction and position limits, solved
exactly: the same problem `step.constrained_velocity` poses for a `JointCoulombFriction` row
and `JointLimits` rows on one coordinate, when nothing else acts on the joint's body.

Over a period h, with I the joint's inertia (its 1 x 1 block of M, the body having no
other coordinate), v_free the smooth step's rate, c the Coulomb friction and the limits'
gaps r_lo = q - q_min, r_hi = q_max - q, the step's velocity v+ solves

    min_v  1/2 I (v - v_free)^2 + c h |v|      subject to  v_lo <= v <= v_hi,
    v_lo = -phi(r_lo) / h,   v_hi = phi(r_hi) / h

(maximum dissipation: the friction impulse in the box |lambda_f| <= c h opposes the motion,
the limits' impulses >= 0 keep the gaps at the period's end >= 0; phi as in `step`, a
penetration removed by the fraction beta per period). In one dimension the minimiser of a
convex function over an interval is its free minimiser clipped to the interval, and the free
minimiser is the soft threshold of v_free by c h / I:

    v_f = sign(v_free) max(|v_free| - c h / I, 0),       v+ = clip(v_f, v_lo, v_hi),
    lambda_f = I (v_f - v_free)  [N m s or N s],         lambda_limit = I (v+ - v_f).

Exact to rounding: a joint held below its friction has v+ = 0, not the iterative solver's
residual (the ADMM's tolerance is on impulses: it leaves a joint of inverse inertia G a rate
of about G times it, a creep), and a joint held by friction at its limit, where the two rows
act on one coordinate and their impulses are not unique, is no harder than any other.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.step import DEFAULT_CORRECTION

__all__ = ["SingleJointStep", "single_joint_step"]


class SingleJointStep(NamedTuple):
    """v+ [rad/s or m/s], the friction's impulse and the limits' [N m s or N s] (the lower
    limit's positive, the upper's negative: both along the joint's coordinate)."""

    velocity: float
    friction_impulse: float
    limit_impulse: float


def _phi(gap: float, correction: float) -> float:
    return gap if gap >= 0.0 else correction * gap


def single_joint_step(
    v_free: float,
    inertia: float,
    coulomb: float,
    gaps: tuple[float, float],
    period_s: float,
    correction: float = DEFAULT_CORRECTION,
) -> SingleJointStep:
    """The step of the module docstring: ``v_free`` [rad/s or m/s], ``inertia`` I > 0
    [kg m^2 or kg], ``coulomb`` c >= 0 [N m or N], ``gaps`` (r_lo, r_hi) [rad or m]
    (inf: no limit), ``period_s`` h > 0."""
    if not (inertia > 0.0 and math.isfinite(inertia)):
        raise ParameterError(f"a joint's inertia must be > 0 and finite, got {inertia}")
    if not (coulomb >= 0.0 and math.isfinite(coulomb)) or not period_s > 0.0:
        raise ParameterError(f"need c >= 0 and h > 0, got c = {coulomb}, h = {period_s}")
    threshold = coulomb * period_s / inertia
    slid = math.copysign(max(abs(v_free) - threshold, 0.0), v_free)
    low = -_phi(gaps[0], correction) / period_s if np.isfinite(gaps[0]) else -math.inf
    high = _phi(gaps[1], correction) / period_s if np.isfinite(gaps[1]) else math.inf
    velocity = min(max(slid, low), high) if low <= high else 0.5 * (low + high)
    return SingleJointStep(
        velocity, inertia * (slid - v_free), inertia * (velocity - slid)
    )
