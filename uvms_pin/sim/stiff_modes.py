"""The stiff modes a run integrates explicitly: every spring-damper of its contacts and stops,
linearised at the run's start (pure functions of the built system and its initial state).

A spring k and damper c acting along a direction n at a point of a body, whose material point
there moves with the linear Jacobian J_p, is one mode

    m_eff x'' + c x' + k x = 0,    m_eff = 1 / (n^T J_p M^-1 J_p^T n)          [kg]

(M the mass matrix with the added mass, `uvms_pin.sim.system.System.mass_matrix`), with the
rates lambda = -c / (2 m_eff) +- sqrt((c / (2 m_eff))^2 - k / m_eff) [1/s]. Which modes:

- a world contact (`uvms_pin.physics.world.contact_law`) of each body (each hull of the
  robot, each free object) against the fixed world, of each pair of moving bodies that can
  touch (the robot's bodies and the free objects, the free objects between them, each of
  them against each fixture's links, with ``self_collision`` the arm's links against their
  vehicle), with 1/m_eff the sum of both sides' (the arm against its own vehicle: of the
  two points' relative Jacobian; a fixture's link through its own joints, its root link
  fixed). A body's
  candidate points are its collision pieces' corners (a box's, a mesh hull's, a cylinder's
  rim prism) and, for a sphere or ellipsoid, its tips along its axes; its m_eff the lightest of them along its most mobile direction (the normal can be
  any: the body turns, an object lies anywhere; a sphere's or an ellipsoid's normal is its
  surface's, through a sphere's centre). The Hunt-Crossley law
  f_n = k delta max(0, 1 + d delta_dot) has the stiffness k at rest, whatever the depth, and
  the damping k d delta that grows with it: each contact is two modes, at first touch (c = 0,
  undamped) and at the working depth delta_w = max(1 mm, 2 |W - B| / k) (c = k d delta_w:
  twice the depth at which one point carries the body's whole net weight, where a step load
  from rest reaches; the start's overlap tolerance, `uvms_pin.physics.world.overlap`). The
  friction's stick spring (k_t, c_t) is a third mode of the same m_eff (the tangent can be
  along any direction too): it holds at most mu f_n, so it cannot diverge, but beyond the
  step's limit it rings at the step within the cone, a wrong answer that stays bounded (a
  rod held in the Alpha 5's jaw was logged spinning about its axis at 0.42 rad/s: a
  finger's m_eff is 13 g, and h c_t / m_eff = 7.4 at the 0.5 ms step, where RK4 keeps
  2.785).
- a compliant joint stop (`uvms_pin.physics.joint_stops`) of k_s, c_s on joint j:
  I_eff = 1 / (M^-1)_jj [kg m^2].
- the end-effector's environment (`uvms_pin.physics.contact`): the plane's k, c along its
  normal; the paper's spring K_f (no damper) at its fastest mode, omega^2 the largest
  eigenvalue of K^1/2 G K^1/2 (G = J_ee M^-1 J_ee^T), reported with k = max K_f and
  m_eff = k / omega^2.

The modes are taken at the initial state: an arm that unfolds changes its links' m_eff by a
little (the vehicle's mass dominates the arm's reflected inertia only near the base).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from uvms_pin.errors import StiffModeError
from uvms_pin.physics.constraints.contacts import point_jacobian
from uvms_pin.physics.contact import CompliantPlane, ContactModel, LinearSpring
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.overlap import OVERLAP_TOLERANCE_M
from uvms_pin.physics.world.robot_geometry import RobotPiece

__all__ = [
    "Body",
    "StiffMode",
    "body_mobility",
    "candidate_contacts",
    "contact_modes",
    "environment_mode",
    "stop_modes",
    "without_rigid_pairs",
]

LINEAR = ("N/m", "N s/m", "kg")
_SOFTER_CONTACT = (
    ", or soften the contact ([world.contact] stiffness_N_m, dissipation_s_m), or make the "
    "body heavier"
)
_RIGID_PAIRS = (
    ', or make the contacts between moving bodies rigid ([world] moving_contact = "rigid": '
    "solved implicitly, stable at any step)"
)
_SOFTER_ENV = ", or soften the environment ([environment] stiffness_N_m, damping_N_s_m)"
_SOFTER_STICK = (
    ", or soften the friction's stick spring ([world.contact] tangential_stiffness_N_m, "
    "tangential_damping_N_s_m)"
)
ANGULAR = ("N m/rad", "N m s/rad", "kg m^2")


@dataclass(frozen=True)
class StiffMode:
    """One spring-damper integrated explicitly: m_eff x'' + c x' + k x = 0.

    Attributes:
        what: which body, joint or object and which contact or stop, for messages.
        stiffness: k [N/m or N m/rad].
        damping: c [N s/m or N m s/rad].
        mass: m_eff [kg or kg m^2].
        units: those of (k, c, m_eff).
        remedy: what else makes it stable, as the end of a sentence (", or ...").
    """

    what: str
    stiffness: float
    damping: float
    mass: float
    units: tuple[str, str, str] = LINEAR
    remedy: str = ""

    @property
    def rate_matrix(self) -> np.ndarray:
        """A = [[0, 1], [-k/m_eff, -c/m_eff]] (2, 2) [1/s^2, 1/s] of y = (x, x_dot)."""
        return np.array([[0.0, 1.0], [-self.stiffness / self.mass, -self.damping / self.mass]])

    @property
    def rates(self) -> np.ndarray:
        """lambda (2,) complex [1/s]: -c/(2 m) +- sqrt((c/(2 m))^2 - k/m)."""
        half = self.damping / (2.0 * self.mass)
        root = np.sqrt(complex(half * half - self.stiffness / self.mass))
        return np.array([-half + root, -half - root])

    def describe(self) -> str:
        k_unit, c_unit, m_unit = self.units
        return (
            f"{self.what} (k = {self.stiffness:.4g} {k_unit}, c = {self.damping:.4g} {c_unit}, "
            f"m_eff = {self.mass:.4g} {m_unit})"
        )

    def record(self) -> dict[str, object]:
        rates = self.rates
        return {
            "what": self.what,
            "stiffness": self.stiffness,
            "damping": self.damping,
            "effective_mass": self.mass,
            "units": list(self.units),
            "rates_1_s": [[float(r.real), float(r.imag)] for r in rates],
        }


@dataclass(frozen=True)
class Body:
    """A moving body that touches: its name, its largest point mobility 1/m_eff [1/kg] over
    its candidate points and directions, and its working depth delta_w [m]."""

    name: str
    mobility_1_kg: float
    working_depth_m: float


def working_depth_m(net_buoyancy_N: float, law: ContactLaw) -> float:
    """delta_w = max(1 mm, 2 |W - B| / k) [m] (see the module's docstring)."""
    return max(OVERLAP_TOLERANCE_M, 2.0 * abs(net_buoyancy_N) / law.stiffness_N_m)


def candidate_contacts(piece: RobotPiece) -> list[tuple[np.ndarray, np.ndarray | None]]:
    """The (point, normal) pairs a piece touches by, in its joint's frame: each corner with
    any normal (None: a corner meets a plane or a face whatever its direction); a sphere's
    or an ellipsoid's tips along its axes, each with its own normal (a contact normal of a
    smooth shape is the surface's: through a sphere's centre)."""
    placement = piece.placement_in_joint
    if piece.corners_m is not None:
        return [(placement.act(p), None) for p in piece.corners_m]
    shape = piece.shape
    radii = np.asarray(shape.radii, dtype=float) if hasattr(shape, "radii") else None
    if radii is None:
        radii = np.full(3, float(getattr(shape, "radius", piece.bound_radius_m)))
    out = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            direction = np.zeros(3)
            direction[axis] = sign
            normal = placement.rotation @ direction
            out.append((placement.act(radii[axis] * direction), normal))
    return out


def body_mobility(
    model: pin.Model,
    data: pin.Data,
    inverse_mass: np.ndarray,
    pieces: list[RobotPiece],
    relative_to: int | None = None,
) -> float:
    """The largest n^T J_p M^-1 J_p^T n [1/kg] over the candidate contacts of ``pieces``
    (`candidate_contacts`; a corner's n the most mobile direction, G's largest eigenvalue),
    after ``pin.computeJointJacobians``. ``relative_to``: a joint whose material point at
    the same place is subtracted (the arm against its own vehicle)."""
    worst = 0.0
    for piece in pieces:
        placement = data.oMi[piece.joint_id]
        for point, normal in candidate_contacts(piece):
            at = placement.act(point)
            jac = point_jacobian(model, data, piece.joint_id, at)
            if relative_to is not None:
                jac = jac - point_jacobian(model, data, relative_to, at)
            mobility = jac @ inverse_mass @ jac.T
            if normal is None:
                worst = max(worst, float(np.linalg.eigvalsh(mobility)[-1]))
            else:
                n = placement.rotation @ normal
                worst = max(worst, float(n @ mobility @ n))
    return worst


def contact_modes(
    what: str, first: Body, second: Body | None, law: ContactLaw, moving: bool = False
) -> list[StiffMode]:
    """The modes of ``first`` against ``second`` (None: the fixed world): the normal ones at
    first touch and at the deeper of both bodies' working depth, and the friction's stick
    spring. ``moving``: a pair between moving bodies whose second side is fixed all the
    same (a fixture's root link), whose remedy is the rigid moving contact."""
    mobility = first.mobility_1_kg + (0.0 if second is None else second.mobility_1_kg)
    if not mobility > 0.0:
        return []
    depth = max(first.working_depth_m, 0.0 if second is None else second.working_depth_m)
    k, mass = law.stiffness_N_m, 1.0 / mobility
    damping = k * law.dissipation_s_m * depth
    remedy = _SOFTER_CONTACT if second is None and not moving else _RIGID_PAIRS + _SOFTER_CONTACT
    stick = remedy + _SOFTER_STICK
    return [
        StiffMode(f"{what}, at first touch", k, 0.0, mass, remedy=remedy),
        # a depth the check assumes, not one found: the pair may be far apart at the start
        StiffMode(
            f"{what}, should it press {depth * 1e3:.3g} mm deep (its working depth)",
            k,
            damping,
            mass,
            remedy=remedy,
        ),
        StiffMode(
            f"{what}, its friction's stick spring",
            law.tangential_stiffness_N_m,
            law.tangential_damping_N_s_m,
            mass,
            remedy=stick,
        ),
    ]


def without_rigid_pairs(error: StiffModeError) -> StiffModeError:
    """``error`` again without the rigid moving contact among its remedies: for a run that
    cannot take it (several robots: `uvms_pin.sim.system.robots.Robots` refuses it)."""
    mode = replace(error.mode, remedy=error.mode.remedy.replace(_RIGID_PAIRS, ""))
    return StiffModeError(mode, error.integrator, error.step_s, error.largest_stable_step_s)


_NO_DRIVE = (
    ", or give the joint its drive's reflected rotor inertia (the URDF's <armature "
    'value="..."/> inside the <joint>, kg m^2: J_rotor N^2; this one has none)'
)


def stop_modes(
    stops: JointStops, inverse_mass: np.ndarray, armature: np.ndarray | None = None
) -> list[StiffMode]:
    """One mode per stopped joint: k_s, c_s, I_eff = 1 / (M^-1)_jj. ``armature`` (nv,), the
    model's: a joint without any is also told it lacks its drive's inertia."""
    out = []
    for name, v_index in zip(stops.names, stops.v_index, strict=True):
        mobility = float(inverse_mass[v_index, v_index])
        no_drive = armature is not None and not armature[v_index] > 0.0
        out.append(
            StiffMode(
                f"the compliant stop of joint '{name}'",
                stops.stiffness_Nm_rad,
                stops.damping_Nm_s_rad,
                1.0 / mobility,
                ANGULAR,
                ', or solve the limits as constraints ([joints] stops = "implicit", with a '
                "[control] period_s), or soften the stops (stop_stiffness_Nm_rad, "
                "stop_damping_Nm_s_rad)" + (_NO_DRIVE if no_drive else ""),
            )
        )
    return out


def environment_mode(contact: ContactModel, ee_mobility: np.ndarray) -> StiffMode | None:
    """The end-effector environment's mode (``ee_mobility``: G = J_ee M^-1 J_ee^T (3, 3)
    [1/kg]), None for another kind of environment or one without stiffness."""
    if isinstance(contact, CompliantPlane):
        n = contact.normal_world
        mobility = float(n @ ee_mobility @ n)
        what = "the end-effector against its environment (plane)"
        return StiffMode(
            what, contact.stiffness_N_m, contact.damping_N_s_m, 1.0 / mobility, remedy=_SOFTER_ENV
        )
    if isinstance(contact, LinearSpring):
        root = np.diag(np.sqrt(contact.stiffness_N_m))
        omega2 = float(np.linalg.eigvalsh(root @ ee_mobility @ root)[-1])
        k = float(np.max(contact.stiffness_N_m))
        if not (omega2 > 0.0 and math.isfinite(omega2)):
            return None
        what = "the end-effector on its environment spring"
        return StiffMode(what, k, 0.0, k / omega2, remedy=_SOFTER_ENV)
    return None
