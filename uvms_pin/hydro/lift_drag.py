"""A fin's lift and drag against its angle of attack: gz-sim's ``LiftDrag`` system, as a pure
function of the fin's orientation and the flow it meets.

Source: gz-sim (github.com/gazebosim/gz-sim, commit 93bbf3e), ``src/systems/lift_drag/
LiftDrag.cc`` (``LiftDragPrivate::Update``), followed step by step. With v the velocity of
the centre of pressure relative to the water (world axes), R the fin link's orientation, f =
R forward, u = R upward (or, with ``radial_symmetry``, f x (f x v^)) and the span s = f x u /
|f x u|:

- no force when |v| <= 0.01 m/s, nor (unless ``reversible``) when f . v <= 0;
- sweep: sin(beta) = s . v^ and the coefficients are scaled by cos^2(beta);
- the flow in the lift-drag plane v_ld = v - (v . s) s; drag along -v_ld, lift along
  s x v_ld / |s x v_ld|; the angle of attack alpha = alpha_0 + acos(lift . u), its sign that
  of lift . f (a flow meeting the fin from below its upward side is a positive alpha),
  wrapped into [-pi/2, pi/2];
- the dynamic pressure q = rho |v_ld|^2 / 2; below the stall (|alpha| <= alpha_stall)
  c_L = c_La alpha, c_D = c_Da alpha, c_M = c_Ma alpha; beyond it the slopes after the stall
  continue from the stall's values (c_L = c_La alpha_s + c_La,stall (alpha - alpha_s), kept
  >= 0; mirrored below -alpha_s, kept <= 0; c_M likewise); a control joint's angle delta
  adds k delta to c_L and c_Mdelta delta to c_M; c_D is taken positive;
- lift c_L q S, drag c_D q S (S the area) at the centre of pressure, and a moment c_M q S
  about the span.

The drag opposes v_ld and the lift is normal to v_ld and to the span: the force never does
positive work on the fin (F . v = -|c_D| q S |v_ld| <= 0); with the flow along the chord
(alpha = alpha_0 = 0) c_L and c_D are zero and so is the force. gz-sim's model has no drag
at zero angle of attack (c_D is proportional to alpha).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.vector import cross3

__all__ = ["LiftDragParams", "angle_of_attack", "lift_drag_coefficients", "lift_drag_wrench"]

#: below this speed of the centre of pressure through the water no force acts [m/s] (gz-sim)
MIN_SPEED_M_S = 0.01


def _unit(name: str, value) -> np.ndarray:
    vector = np.asarray(value, dtype=float).reshape(-1)
    norm = float(np.linalg.norm(vector)) if vector.size == 3 else math.nan
    if not (math.isfinite(norm) and norm > 0.0):
        raise ParameterError(f"lift_drag {name} must be 3 finite numbers, not zero, got {value}")
    return vector / norm


@dataclass(frozen=True)
class LiftDragParams:
    """One fin, in its link's frame (gz-sim's ``LiftDrag`` parameters and defaults).

    Attributes:
        area_m2: S, the planform area [m^2] (``area``).
        fluid_density_kg_m3: rho [kg/m^3] (gz-sim's ``air_density``, default 1.2041: air).
        cla, cda, cma: dc_L/dalpha, dc_D/dalpha, dc_M/dalpha [1/rad] below the stall.
        alpha_stall_rad: alpha_s [rad]; cla_stall, cda_stall, cma_stall: the slopes beyond it.
        alpha0_rad: alpha_0, the angle of attack at zero lift [rad] (``a0``).
        cp_m: the centre of pressure in the link frame [m] (``cp``).
        forward: the chord's direction at zero angle of attack, link frame (normalised).
        upward: the direction of positive lift, link frame (normalised; not along forward).
        radial_symmetry: the upward direction follows the flow (a body of revolution).
        reversible: a flow from behind (f . v <= 0) makes lift and drag too.
        control_joint_rad_to_cl: dc_L/ddelta per radian of the control joint [1/rad].
        cm_delta: dc_M/ddelta per radian of the control joint [1/rad].
    """

    area_m2: float
    fluid_density_kg_m3: float = 1.2041
    cla: float = 1.0
    cda: float = 0.01
    cma: float = 0.0
    alpha_stall_rad: float = 0.5 * math.pi
    cla_stall: float = 0.0
    cda_stall: float = 1.0
    cma_stall: float = 0.0
    alpha0_rad: float = 0.0
    cp_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    forward: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    upward: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    radial_symmetry: bool = False
    reversible: bool = False
    control_joint_rad_to_cl: float = 4.0
    cm_delta: float = 0.0

    def __post_init__(self) -> None:
        numbers = {k: getattr(self, k) for k in ("cla", "cda", "cma", "alpha_stall_rad",
                   "cla_stall", "cda_stall", "cma_stall", "alpha0_rad",
                   "control_joint_rad_to_cl", "cm_delta")}  # fmt: skip
        for name, value in numbers.items():
            if not math.isfinite(value):
                raise ParameterError(f"lift_drag {name} must be finite, got {value}")
        if not (math.isfinite(self.area_m2) and self.area_m2 >= 0.0):
            raise ParameterError(f"lift_drag area must be >= 0 m^2, got {self.area_m2}")
        if not (math.isfinite(self.fluid_density_kg_m3) and self.fluid_density_kg_m3 > 0.0):
            raise ParameterError(
                f"lift_drag fluid density must be > 0 kg/m^3, got {self.fluid_density_kg_m3}"
            )
        cp = np.asarray(self.cp_m, dtype=float).reshape(-1)
        if cp.size != 3 or not np.all(np.isfinite(cp)):
            raise ParameterError(f"lift_drag cp must be 3 finite numbers, got {self.cp_m}")
        forward, upward = _unit("forward", self.forward), _unit("upward", self.upward)
        if np.linalg.norm(cross3(forward, upward)) < 1e-9:
            raise ParameterError("lift_drag upward must not be along forward (no span)")
        object.__setattr__(self, "cp_m", cp)
        object.__setattr__(self, "forward", forward)
        object.__setattr__(self, "upward", upward)


def _past_stall(slope: float, slope_stall: float, alpha: float, stall: float) -> float:
    """c = slope alpha below the stall; beyond +-stall the post-stall slope from there."""
    if alpha > stall:
        return slope * stall + slope_stall * (alpha - stall)
    if alpha < -stall:
        return -slope * stall + slope_stall * (alpha + stall)
    return slope * alpha


def lift_drag_coefficients(
    alpha_rad: float, params: LiftDragParams, cos2_sweep: float = 1.0, control_rad: float = 0.0
) -> tuple[float, float, float]:
    """(c_L, c_D, c_M) at the angle of attack ``alpha_rad`` in [-pi/2, pi/2], scaled by the
    sweep's cos^2, with a control joint's angle ``control_rad`` (the module's formulas)."""
    p, stall = params, params.alpha_stall_rad
    cl = _past_stall(p.cla, p.cla_stall, alpha_rad, stall) * cos2_sweep
    cm = _past_stall(p.cma, p.cma_stall, alpha_rad, stall) * cos2_sweep
    if alpha_rad > stall:  # past the stall the lift and moment keep their sign
        cl, cm = max(0.0, cl), max(0.0, cm)
    elif alpha_rad < -stall:
        cl, cm = min(0.0, cl), min(0.0, cm)
    cd = abs(_past_stall(p.cda, p.cda_stall, alpha_rad, stall) * cos2_sweep)
    return (
        cl + p.control_joint_rad_to_cl * control_rad,
        cd,
        cm + p.cm_delta * control_rad,
    )


def _normalized(vector: np.ndarray) -> np.ndarray:
    norm = float(np.linalg.norm(vector))
    return vector / norm if norm > 0.0 else np.zeros(3)


def angle_of_attack(
    params: LiftDragParams, rotation_world: np.ndarray, velocity_world_m_s: np.ndarray
) -> tuple[float, float, np.ndarray, np.ndarray] | None:
    """(alpha [rad], cos^2 of the sweep, the lift's unit direction, the span's, world axes)
    of a flow ``velocity_world_m_s`` (the centre of pressure relative to the water) past a
    fin turned by ``rotation_world``; None when no force acts (the module's conditions)."""
    vel = np.asarray(velocity_world_m_s, dtype=float)
    if not float(np.linalg.norm(vel)) > MIN_SPEED_M_S:
        return None
    vel_hat = _normalized(vel)
    forward = rotation_world @ params.forward
    if not params.reversible and float(forward @ vel) <= 0.0:
        return None
    if params.radial_symmetry:
        upward = _normalized(cross3(forward, cross3(forward, vel_hat)))
    else:
        upward = rotation_world @ params.upward
    span = _normalized(cross3(forward, upward))
    sin_sweep = min(max(float(span @ vel_hat), -1.0), 1.0)
    in_plane = vel - float(vel @ span) * span
    lift = _normalized(cross3(span, in_plane))
    cos_alpha = min(max(float(lift @ upward), -1.0), 1.0)
    turn = math.acos(cos_alpha)
    alpha = params.alpha0_rad + (turn if float(lift @ forward) >= 0.0 else -turn)
    while abs(alpha) > 0.5 * math.pi:
        alpha += -math.pi if alpha > 0.0 else math.pi
    return alpha, 1.0 - sin_sweep * sin_sweep, lift, span


def lift_drag_wrench(
    params: LiftDragParams,
    rotation_world: np.ndarray,
    velocity_world_m_s: np.ndarray,
    control_rad: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """(the force [N] at the centre of pressure, the moment [N m]), world axes, of the flow
    ``velocity_world_m_s`` (the centre of pressure's velocity less the water's) past a fin
    whose link is turned by ``rotation_world`` (3x3, link to world); ``control_rad``: the
    control joint's angle (0 without one)."""
    attack = angle_of_attack(params, rotation_world, velocity_world_m_s)
    if attack is None:
        return np.zeros(3), np.zeros(3)
    alpha, cos2_sweep, lift, span = attack
    vel = np.asarray(velocity_world_m_s, dtype=float)
    in_plane = vel - float(vel @ span) * span
    pressure_area = 0.5 * params.fluid_density_kg_m3 * float(in_plane @ in_plane) * params.area_m2
    cl, cd, cm = lift_drag_coefficients(alpha, params, cos2_sweep, control_rad)
    force = pressure_area * (cl * lift - cd * _normalized(in_plane))
    return force, pressure_area * cm * span
