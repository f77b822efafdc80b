"""One implicit velocity-level step of the constraints over a period h (Moreau-Jean).

The smooth dynamics alone bring the velocity to v_free at the period's end. The constraints
(joint limits, joint Coulomb friction, contacts) add the impulse lambda (m,) through their
Jacobian J (m x nv) at the configuration q of the period's start:

    v+ = v_free + M^-1 J^T lambda                                    [rad/s, m/s]
    sigma = J v+ + phi(r) / h  in K*,   lambda in K,   lambda . sigma = 0

with M the mass matrix INCLUDING the added mass (the entrained water is accelerated by
the impulse too), K each block's cone (the positive orthant of a limit or a contact normal,
the box |lambda| <= c h of a joint's Coulomb friction, the Coulomb cone
mu |lambda_t| <= lambda_n of a contact; K* its dual, with De Saxce's correction for the
non-associated Coulomb law) and r the rows' gaps (`ConstraintRows`).
In terms of the Delassus operator G = J M^-1 J^T the solver (Pinocchio's
`ADMMConstraintSolver`) finds lambda with sigma = G lambda + g, g = J v_free + phi(r) / h.

Position: the configuration advances with the constrained velocity, q+ = q (+) h v+
(semi-implicit Euler, `constrained_configuration`), so a row's gap at the period's end is
r + h J v+ = h sigma >= 0.

    phi(r) = r                    for r >= 0  (a limit or a surface is reached exactly at the
                                               period's end, never crossed: predictive)
    phi(r) = correction * r       for r < 0   (a penetration, e.g. an initial state past a
                                               limit, is removed by this fraction per period)
    phi(e) = correction * e       on a bilateral row (an attachment's pose error e, held at
                                  zero both ways: sigma = 0, the impulse of any sign)

``correction`` (0 < beta <= 1) is the discrete Baumgarte gain: beta = Kp h^2 of the
continuous stabilisation r_ddot + Kd r_dot + Kp r = 0 sampled once per period. 1 removes a
penetration in one period (stiff), the default 0.2 in about 5 periods with less impulse.

Energy: within the limits (r >= 0) the impulse never adds kinetic energy,
v+^T M v+ - v_free^T M v_free = -lambda^T G lambda - 2 lambda^T phi(r) / h <= 0; only
the correction of a penetration (r < 0) may add some, 2 beta |lambda^T r| / h at most.

A solve that stalls: with friction the problem is not a convex program (the Coulomb law is
non-associated) and its solution need not be unique; with more contacts than the bodies have
freedoms (a box's four corners on a plane) G is singular and the impulses can drift along its
null space. A box rocking on its corners while it slides, or landing flat, is such a case:
the iterates stall with a residual between 1e-10 and about 2e-5 m/s whatever the number of
iterations (measured on boxes dropped on 0 to 40 degree slopes; more iterations, relaxation
and exact per-contact solves did not help). A solve that ends above its tolerance is still
accepted when its residual is at most `ACCEPTABLE_RELATIVE_RESIDUAL` (1e-4) of the largest
speed its rows must absorb, |g|_inf = |J v_free + phi(r) / h|_inf, and at least
`ACCEPTABLE_RESIDUAL_M_S` (1e-5 m/s: a gap wrong by 1e-8 m over a 1 ms period); the run
counts those periods (`StalledSolves`) and its metadata says how many and the largest
residual. A solve that stalls above it is solved once more with the ADMM's Anderson
acceleration, which breaks such cycles where plain iterations do not (a stab held in its
receptacle's bore: 5.1e-5 m/s after 5,000 plain iterations, 1.6e-8 after 461 accelerated);
only if that one too ends above the bound does the run stop, naming the period.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.rows import ConstraintRows, ConstraintSet

__all__ = [
    "ACCEPTABLE_RELATIVE_RESIDUAL",
    "ACCEPTABLE_RESIDUAL_M_S",
    "DEFAULT_CORRECTION",
    "ConstrainedVelocity",
    "StalledSolves",
    "constrained_configuration",
    "constrained_velocity",
    "default_settings",
    "free_body_configuration",
]

#: beta, the fraction of a penetration removed per period (the module docstring)
DEFAULT_CORRECTION = 0.2

#: A solve that stalled above its tolerance is still accepted with a residual of at most
#: this fraction of its rows' largest speed |g|_inf, and at least `ACCEPTABLE_RESIDUAL_M_S`
#: [m/s] (the module docstring)
ACCEPTABLE_RELATIVE_RESIDUAL = 1.0e-4
ACCEPTABLE_RESIDUAL_M_S = 1.0e-5
#: the iterates the ADMM's Anderson acceleration combines when a plain solve stalled
#: (`_solve_or_accelerate`)
ANDERSON_CAPACITY = 5

#: How often the selection of rows is widened (see `constrained_velocity`)
_MAX_ROUNDS = 4


@dataclass(frozen=True)
class ConstrainedVelocity:
    """The result of one constraint step.

    Attributes:
        velocity: v+ (nv,) [m/s, rad/s], the constrained velocity at the period's end.
        impulses: per constraint set (its ``name``), lambda of its rows [N m s or N s]
            (a contact's rows: two tangential then the normal, in the contact frame).
        units: per constraint set, the unit of its impulses.
        generalized_impulse: J^T lambda (nv,) [N s on the vehicle's translations, N m s on
            rotations and revolute joints]: the impulse in the generalized coordinates.
        rows: the blocks solved (Jacobians, gaps, labels), empty when nothing could touch.
        iterations: the solver's iterations (0 without rows).
        residual: the largest of the solver's primal and dual feasibility and
            complementarity errors at its end [m/s, rad/s].
        converged: whether the solver met its tolerances.
        speed: |g|_inf = |J v_free + phi(r) / h|_inf [m/s], the largest speed the rows
            must absorb (0 without rows).
    """

    velocity: np.ndarray
    impulses: dict[str, np.ndarray]
    units: dict[str, str]
    generalized_impulse: np.ndarray
    rows: tuple[ConstraintRows, ...]
    iterations: int
    residual: float
    converged: bool
    speed: float = 0.0

    @property
    def acceptable_residual(self) -> float:
        """The largest residual [m/s] a stalled solve of these rows may keep."""
        return max(ACCEPTABLE_RESIDUAL_M_S, ACCEPTABLE_RELATIVE_RESIDUAL * self.speed)

    @property
    def accepted(self) -> bool:
        """Converged, or stalled with a residual of at most `acceptable_residual`."""
        return self.converged or self.residual <= self.acceptable_residual


@dataclass
class StalledSolves:
    """The constraint solves of a run that stalled above their tolerance and were accepted
    (`ConstrainedVelocity.accepted`): how many and the largest residual [m/s]."""

    count: int = 0
    worst_residual_m_s: float = 0.0

    def add(self, residual_m_s: float) -> None:
        self.count += 1
        self.worst_residual_m_s = max(self.worst_residual_m_s, float(residual_m_s))

    def merged(self, count: int, worst_residual_m_s: float) -> StalledSolves:
        """These and ``count`` more (the compiled system's), worst of both."""
        return StalledSolves(
            self.count + count, max(self.worst_residual_m_s, float(worst_residual_m_s))
        )

    def record(self) -> dict[str, float | int]:
        """As a run's metadata records it."""
        return {
            "stalled": self.count,
            "worst_stalled_residual_m_s": self.worst_residual_m_s,
            "acceptable_residual": (
                f"{ACCEPTABLE_RELATIVE_RESIDUAL:g} of the rows' largest speed, at least "
                f"{ACCEPTABLE_RESIDUAL_M_S:g} m/s"
            ),
        }


def default_settings(
    tolerance: float = 1.0e-8, max_iterations: int = 5000
) -> pin.ADMMSolverSettings:
    """Pinocchio's ADMM settings with its absolute and relative feasibility and
    complementarity tolerances at ``tolerance`` [m/s, rad/s] and at most ``max_iterations``.

    A gap closes to within h times the tolerance: Pinocchio's own 1e-6 leaves joints ~2e-6
    rad past their limits at h = 2 ms, 1e-8 costs about two more iterations (median 8 on
    the BlueROV2 + Alpha 5 driven into its limits). Its 1000 iterations are not always
    enough when the Delassus operator is badly conditioned (the Alpha 5's wrist, 8e-5 kg m^2,
    against its elbow: a ratio ~1e3): the slowest of 2,000 such periods took 2,393."""
    settings = pin.ADMMSolverSettings()
    settings.absolute_feasibility_tol = tolerance
    settings.relative_feasibility_tol = tolerance
    settings.absolute_complementarity_tol = tolerance
    settings.relative_complementarity_tol = tolerance
    settings.max_iterations = max_iterations
    return settings


def constrained_velocity(
    model: pin.Model,
    mass_matrix: np.ndarray,
    v_free: np.ndarray,
    q: np.ndarray,
    constraints: Sequence[ConstraintSet],
    period_s: float,
    *,
    correction: float = DEFAULT_CORRECTION,
    settings: pin.ADMMSolverSettings | None = None,
    least_speed: np.ndarray | None = None,
) -> ConstrainedVelocity:
    """v+ = v_free + M^-1 J^T lambda over the period ``period_s`` (see the module docstring).

    Args:
        model: the Pinocchio model. mass_matrix: M(q) (nv x nv) [kg, kg m, kg m^2], with
            the added mass (`uvms_pin.physics.dynamics.mass_matrix`).
        v_free: the velocity the smooth dynamics reach at the period's end (nv,).
        q: the configuration at the period's start (nq,): J and the gaps are taken there.
        constraints: the constraint sets (`joint_limits.JointLimits`,
            `joint_friction.JointCoulombFriction`, `contacts.PlaneContacts`), each named
            once.
        period_s: h [s] (> 0). correction: beta, the fraction of a penetration removed per
            period (0 < beta <= 1). settings: the ADMM settings (`default_settings`).
        least_speed: (nv,) [m/s, rad/s], the smooth step's own speeds (its start velocity and
            its mean over the period, whose end may cross a limit that its end velocity would
            not reach); None: none.

    Only the rows that can close within the period are solved: those whose gap is at most
    h |J_k| |v| with |v| the velocity's magnitudes (at least ``least_speed``); as the
    impulses change v, the selection is widened with the new velocity and solved again
    until it no longer grows.

    Raises:
        ParameterError: a size that does not match the model, a non-finite value, a period
            or correction out of range, two sets with one name.
    """
    h = _checked_period(period_s)
    v_free, q, mass = _checked_state(model, mass_matrix, v_free, q)
    if not (math.isfinite(correction) and 0.0 < correction <= 1.0):
        raise ParameterError(f"correction must be in (0, 1], got {correction}")
    names = [c.name for c in constraints]
    if len(set(names)) != len(names):
        raise ParameterError(f"each constraint set needs its own name, got {names}")
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    data.q_in = q
    speed = np.abs(v_free)
    if least_speed is not None:
        speed = np.maximum(speed, np.abs(finite_vector("least_speed", least_speed, model.nv)))
    blocks = tuple(c.rows(model, data, q, speed, h) for c in constraints)
    settings = settings or default_settings()
    for _ in range(_MAX_ROUNDS):
        step = _solve_or_accelerate(mass, v_free, blocks, h, correction, settings=settings)
        speed = np.maximum(speed, np.abs(step.velocity))
        wider = tuple(c.rows(model, data, q, speed, h) for c in constraints)
        if sum(b.size for b in wider) == sum(b.size for b in blocks):
            return step
        blocks = wider
    return _solve_or_accelerate(mass, v_free, blocks, h, correction, settings=settings)


def _solve_or_accelerate(*problem: object, settings: pin.ADMMSolverSettings) -> ConstrainedVelocity:
    """`_solve` of ``problem`` (mass, v_free, blocks, h, correction), and when it stalls above
    the residual it may keep, the same solve again with Anderson acceleration (`ANDERSON_CAPACITY` iterates): the better of the two (the
    accepted one, else the smaller residual), with both solves' iterations. A stab in its
    receptacle's bore held by two fingers (45 rows) stalled at 5.1e-5 m/s after 5,000 plain
    iterations (above its 4.4e-5) and at 1.8e-5 after 20,000; accelerated, it converged to
    1.6e-8 in 461. Only a stalled solve is retried: every other period is unchanged."""
    plain = _solve(*problem, settings)
    if plain.accepted:
        return plain
    faster = default_settings(settings.absolute_feasibility_tol, settings.max_iterations)
    faster.anderson_capacity = ANDERSON_CAPACITY
    retried = _solve(*problem, faster)
    best = retried if retried.accepted or retried.residual < plain.residual else plain
    return dataclasses.replace(best, iterations=plain.iterations + retried.iterations)


def constrained_configuration(
    model: pin.Model,
    q: np.ndarray,
    q_free: np.ndarray,
    step: ConstrainedVelocity,
    period_s: float,
) -> np.ndarray:
    """The configuration at the period's end (nq,) after `constrained_velocity`.

    With rows solved, q+ = q (+) h v+ from the period's start ``q`` (semi-implicit Euler):
    the one update under which every gap ends at h sigma >= 0. Without (nothing could
    touch), ``q_free``, the smooth step's own end (RK4's, say), unchanged. Moving
    ``q_free`` by h (v+ - v_free) instead would not do: RK4's q_free differs from
    q (+) h v_free by O(h^2 a), and a joint of the Alpha 5 driven into its limits ended
    0.01 rad past them."""
    if not step.rows:
        return np.asarray(q_free, dtype=float)
    return pin.integrate(model, q, _checked_period(period_s) * step.velocity)


def free_body_configuration(q: np.ndarray, v: np.ndarray, period_s: float) -> np.ndarray:
    """A free body's pose (7,) [m; quaternion x, y, z, w] at the period's end from its pose
    ``q`` and its constrained body velocity ``v`` (6,) [m/s, rad/s, LOCAL]: its position
    along the world velocity it has at the start and its rotation by the angular velocity,

        p+ = p + h R v_lin,      R+ = R exp(h w),

    the semi-implicit Euler step on R^3 x SO(3). Not ``pin.integrate`` (the exponential of
    SE(3), a screw motion): a sphere rolling without slip has the twist of a rotation about
    its contact point, whose screw lifts its centre by r (1 - cos(w h)) a period (0.1 mm at
    24 rad/s and 2 ms) off the plane the constraint held it on; here its centre moves along
    the plane, as the contact's rows J v+ say."""
    h = _checked_period(period_s)
    rotation = pin.Quaternion(q[3:7]).normalized().matrix()
    turned = pin.Quaternion(rotation @ pin.exp3(h * v[3:6])).normalized()
    return np.concatenate([q[:3] + h * rotation @ v[:3], turned.coeffs()])


def _solve(
    mass: np.ndarray,
    v_free: np.ndarray,
    blocks: tuple[ConstraintRows, ...],
    h: float,
    correction: float,
    settings: pin.ADMMSolverSettings,
) -> ConstrainedVelocity:
    """One ADMM solve of the rows ``blocks`` (all of them, as they are)."""
    units = {b.name: b.unit for b in blocks}
    if sum(b.size for b in blocks) == 0:
        empty = {b.name: np.zeros(0) for b in blocks}
        return ConstrainedVelocity(
            v_free.copy(), empty, units, np.zeros_like(v_free), (), 0, 0.0, True
        )
    jacobian = np.vstack([b.jacobian for b in blocks])
    gap = np.concatenate([b.gap for b in blocks])
    positional = np.concatenate([b.positional for b in blocks])
    phi = np.where(positional, np.where(gap >= 0.0, gap, correction * gap), 0.0)
    bilateral = np.concatenate(
        [np.zeros(b.size, dtype=bool) if b.bilateral is None else b.bilateral for b in blocks]
    )
    phi = np.where(bilateral, correction * gap, phi)  # an error both ways (an attachment)
    minv_jt = np.linalg.solve(mass, jacobian.T)
    delassus = jacobian @ minv_jt
    drift = jacobian @ v_free + phi / h
    models, datas = pin.StdVec_ConstraintModel(), pin.StdVec_ConstraintData()
    for block in blocks:
        for model, data in zip(block.models, block.datas, strict=True):
            models.append(model)
            datas.append(data)
    solver, result = pin.ADMMConstraintSolver(), pin.ADMMSolverResult()
    solver.solve(pin.DelassusOperatorDense(delassus), drift, models, datas, settings, result)
    impulse = np.array(result.retrieveConstraintImpulses(), dtype=float)
    bounds = np.cumsum([0] + [b.size for b in blocks])
    per_set = {b.name: impulse[bounds[k] : bounds[k + 1]] for k, b in enumerate(blocks)}
    residual = max(result.primal_feasibility, result.dual_feasibility, result.complementarity)
    return ConstrainedVelocity(
        v_free + minv_jt @ impulse,
        per_set,
        units,
        jacobian.T @ impulse,
        blocks,
        int(result.iterations),
        float(residual),
        bool(result.converged),
        float(np.max(np.abs(drift))),
    )


def _checked_period(period_s: float) -> float:
    if not (isinstance(period_s, int | float) and math.isfinite(period_s) and period_s > 0.0):
        raise ParameterError(f"period_s must be a finite number > 0 [s], got {period_s!r}")
    return float(period_s)


def _checked_state(
    model: pin.Model, mass_matrix: np.ndarray, v_free: np.ndarray, q: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(v_free, q, M) as float arrays of the model's sizes, or ParameterError."""
    v_free = finite_vector("v_free", v_free, model.nv)
    q = finite_vector("q", q, model.nq)
    mass = np.asarray(mass_matrix, dtype=float)
    if mass.shape != (model.nv, model.nv):
        raise ParameterError(
            f"mass_matrix must be {model.nv} x {model.nv} (nv x nv), got shape {mass.shape}"
        )
    if not np.all(np.isfinite(mass)):
        raise ParameterError("mass_matrix contains a non-finite value")
    return v_free, q, mass
