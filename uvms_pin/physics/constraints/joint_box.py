"""The implicit step of one body's joints with Coulomb friction and position limits, solved
exactly: the problem `step.constrained_velocity` poses for `JointCoulombFriction` rows and
`JointLimits` rows on those joints, when nothing else acts on the body (its block of M has
no coupling to the other bodies' coordinates, and no other row acts on it).

Over a period h, with M the body's mass matrix (n x n, its joints), v_free the smooth step's
rates, c the joints' Coulomb friction and r_lo = q - q_min, r_hi = q_max - q their limits'
gaps, the step's velocity v+ solves the maximum-dissipation problem

    min_v  1/2 (v - v_free)^T M (v - v_free) + h sum_j c_j |v_j|
    subject to  v_lo <= v <= v_hi,    v_lo = -phi(r_lo) / h,   v_hi = phi(r_hi) / h

(its optimality conditions are the step's: the friction impulse lambda_f in the box
|lambda_f,j| <= c_j h opposes the motion, the limits' impulses >= 0 keep the gaps at the
period's end >= 0; phi as in `step`, a penetration removed by the fraction beta per period).
The objective is strictly convex (M positive definite): coordinate descent converges to its
one minimiser (Tseng 2001, a separable nonsmooth term), each update exact,

    b_j = v_free,j - sum_{k != j} M_jk (v_k - v_free,k) / M_jj
    v_j = clip(sign(b_j) max(|b_j| - c_j h / M_jj, 0), v_lo,j, v_hi,j),

and the joints it leaves moving freely are then solved exactly (the others held where they
are: at 0 when stuck, at a bound when stopped). One joint is one update: its v+ is its
rate soft-thresholded by c h / M and clipped to the limits. A joint held below its friction
has v+ = 0 exactly, not an iterative solver's residual (the ADMM's tolerance is on impulses:
it leaves a joint of inverse inertia G a rate of about G times it, a creep), and a joint
held by friction at its limit, where two rows act on one coordinate and their impulses are
not unique, is no harder than any other.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.step import DEFAULT_CORRECTION

__all__ = ["JointBoxStep", "joint_box_step"]

#: coordinate descent stops when no rate changes by more than this [rad/s or m/s]
_SETTLED = 1.0e-15
_MAX_SWEEPS = 10_000


class JointBoxStep(NamedTuple):
    """v+ (n,) [rad/s or m/s], and the impulses (n,) [N m s or N s] along each joint: the
    friction's and the limits' (the lower limit's positive, the upper's negative)."""

    velocity: np.ndarray
    friction_impulse: np.ndarray
    limit_impulse: np.ndarray


def joint_box_step(
    v_free: np.ndarray,
    mass_matrix: np.ndarray,
    coulomb: np.ndarray,
    gaps: tuple[np.ndarray, np.ndarray],
    period_s: float,
    correction: float = DEFAULT_CORRECTION,
) -> JointBoxStep:
    """The step of the module docstring: ``v_free`` (n,), ``mass_matrix`` M (n, n) positive
    definite, ``coulomb`` c (n,) >= 0 [N m or N], ``gaps`` (r_lo, r_hi) (n,) each [rad or m]
    (inf: no limit), ``period_s`` h > 0."""
    v_free = finite_vector("v_free", v_free, np.size(v_free))
    n = v_free.size
    mass = np.asarray(mass_matrix, dtype=float).reshape(n, n)
    coulomb = np.asarray(coulomb, dtype=float).reshape(n)
    if not (period_s > 0.0 and np.all(coulomb >= 0.0) and np.all(np.diag(mass) > 0.0)):
        raise ParameterError(f"need h > 0, c >= 0 and M_jj > 0, got h = {period_s}, c = {coulomb}")
    h = float(period_s)
    low = -_phi(np.asarray(gaps[0], dtype=float), correction) / h
    high = _phi(np.asarray(gaps[1], dtype=float), correction) / h
    crossed = low > high  # both limits past (a start outside them): their middle
    low[crossed] = high[crossed] = 0.5 * (low[crossed] + high[crossed])
    v = np.clip(np.zeros(n), low, high)
    for _ in range(_MAX_SWEEPS):
        moved = 0.0
        for j in range(n):
            b = v_free[j] - (mass[j] @ (v - v_free) - mass[j, j] * (v[j] - v_free[j])) / mass[j, j]
            new = min(max(_soft(b, coulomb[j] * h / mass[j, j]), low[j]), high[j])
            moved, v[j] = max(moved, abs(new - v[j])), new
        if moved <= _SETTLED:
            break
    v = _polished(v, v_free, mass, coulomb * h, (low, high))
    total = mass @ (v - v_free)
    friction = _friction_share(v, total, coulomb * h)
    return JointBoxStep(v, friction, total - friction)


def _phi(gap: np.ndarray, correction: float) -> np.ndarray:
    return np.where(gap >= 0.0, gap, correction * gap)


def _soft(b: float, threshold: float) -> float:
    return float(np.sign(b)) * max(abs(b) - threshold, 0.0)


def _polished(v, v_free, mass, bound, limits) -> np.ndarray:
    """The joints left moving freely (strictly inside their limits, not stuck) solved
    exactly with the others held: M_FF (v_F - v_free,F) + M_FB (v_B - v_free,B) +
    c_F h sign(v_F) = 0; the descent's own ``v`` when that moves a joint across 0 or past a
    limit (it was not yet settled)."""
    low, high = limits
    free = (v != 0.0) & (v > low) & (v < high)
    if not np.any(free):
        return v
    held = ~free
    rhs = mass[np.ix_(free, held)] @ (v[held] - v_free[held]) + bound[free] * np.sign(v[free])
    out = v.copy()
    out[free] = v_free[free] - np.linalg.solve(mass[np.ix_(free, free)], rhs)
    same = np.all(np.sign(out[free]) == np.sign(v[free]))
    inside = np.all((out[free] >= low[free]) & (out[free] <= high[free]))
    return out if same and inside else v


def _friction_share(v: np.ndarray, total: np.ndarray, bound: np.ndarray) -> np.ndarray:
    """The friction's part of each joint's impulse: -c h sign(v) while it moves, else as
    much of the total as its box holds (the limit takes the rest)."""
    return np.where(v != 0.0, -bound * np.sign(v), np.clip(total, -bound, bound))
