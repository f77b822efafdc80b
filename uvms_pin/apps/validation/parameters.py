"""Hydrodynamic parameters of one body that identification can fit, and their sensitivities.

A parameter is named ``<kind>.<axis>``:

- ``linear_damping.<axis>``, ``quadratic_damping.<axis>``, ``added_mass.<axis>``: the diagonal
  entry of D_lin, D_quad or M_A for ``axis`` in x, y, z, roll, pitch, yaw [N s/m, N m s/rad;
  N s^2/m^2, N m s^2/rad^2; kg, kg m^2], in the body's hydro frame;
- ``center_of_buoyancy.<x|y|z>``: the centre of buoyancy r_B in the hydro frame [m].

The generalized force the body's water puts on the system, F_p = J_j^T X^T w(p) (w the
body-frame fluid wrench, X the joint-to-body motion transform, J_j the LOCAL Jacobian of the
body's joint), is *linear* in the damping coefficients and in r_B, so its derivative is exact
and analytic (`generalized_force_sensitivity`):

    dw/dD_lin,ii = -nu_r,i e_i,   dw/dD_quad,ii = -|nu_r,i| nu_r,i e_i,
    dw/dr_B = [0; -[f_B]x],       f_B = R^T (-rho V g)  (the buoyancy in body axes).

Added mass enters M(q) and the Kirchhoff and Coriolis terms nonlinearly: its sensitivity is
taken by central finite differences of the vehicle's acceleration (`uvms_pin.apps.validation.
sensitivity`), the one hydrodynamic kind the analytic path does not cover.

Two parameters are not the water's: they belong to the recording, not to the model.
``arm_delay`` [s] is how late the arm's encoder stream is on the IMU's clock (the arm is
prescribed at t + delay); its sensitivity is a central difference too. ``imu_yaw`` [rad] is the
IMU's mounting yaw on the hull (`uvms_pin.apps.validation.imu_mount`): it moves the start and
the reading of the attitude, not the dynamics, and its sensitivity is analytic.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.params import HydroParams
from uvms_pin.hydro.vector import skew
from uvms_pin.model.uvms import UVMS, HydroBody

__all__ = [
    "AXES",
    "DEFAULT_FIT",
    "KINDS",
    "HydroParameter",
    "generalized_force_sensitivity",
    "parameter_values",
    "parse_parameters",
    "with_parameters",
]

AXES = ("x", "y", "z", "roll", "pitch", "yaw")
KINDS = ("linear_damping", "quadratic_damping", "added_mass", "center_of_buoyancy")
ARM_DELAY = "arm_delay"
IMU_YAW = "imu_yaw"
#: the recording's parameters (not the model's), named alone
RECORDING = (ARM_DELAY, IMU_YAW)
#: kinds that enter the fluid's force linearly (analytic `generalized_force_sensitivity`)
FORCE_LINEAR = ("linear_damping", "quadratic_damping", "center_of_buoyancy")
#: kinds whose entries must stay >= 0 (dissipation, a positive semi-definite added mass)
NONNEGATIVE = ("linear_damping", "quadratic_damping", "added_mass")


@dataclass(frozen=True)
class HydroParameter:
    """One identifiable coefficient: ``kind`` (`KINDS`) along ``axis`` (index in `AXES`)."""

    kind: str
    axis: int

    @property
    def name(self) -> str:
        return self.kind if self.kind in RECORDING else f"{self.kind}.{AXES[self.axis]}"

    @property
    def analytic(self) -> bool:
        """True when the sensitivity is analytic (the force is linear in the parameter, or
        the IMU's mounting yaw)."""
        return self.kind in FORCE_LINEAR or self.kind == IMU_YAW

    @property
    def force_linear(self) -> bool:
        """True when the fluid's force is linear in the parameter (damping, r_B)."""
        return self.kind in FORCE_LINEAR

    @property
    def unit(self) -> str:
        """Its SI unit: a translational axis's (x, y, z) or a rotational one's (roll, pitch,
        yaw) for the diagonal coefficients; m, s, rad for the others."""
        if self.kind == "center_of_buoyancy":
            return "m"
        if self.kind in RECORDING:
            return "s" if self.kind == ARM_DELAY else "rad"
        rotational = self.axis > 2
        return {
            "linear_damping": ("N m s/rad" if rotational else "N s/m"),
            "quadratic_damping": ("N m s^2/rad^2" if rotational else "N s^2/m^2"),
            "added_mass": ("kg m^2" if rotational else "kg"),
        }[self.kind]

    @property
    def hydrodynamic(self) -> bool:
        """True for a coefficient of the body (False: the recording's ``arm_delay``,
        ``imu_yaw``)."""
        return self.kind not in RECORDING

    @property
    def nonnegative(self) -> bool:
        return self.kind in NONNEGATIVE

    def value(self, params: HydroParams) -> float:
        """The parameter's value in ``params``."""
        if self.kind == "center_of_buoyancy":
            return float(params.center_of_buoyancy_m[self.axis])
        if self.kind == "quadratic_damping":
            return float(params.quadratic_damping[self.axis])
        return float(getattr(params, self.kind)[self.axis, self.axis])

    def replaced(self, params: HydroParams, value: float) -> HydroParams:
        """``params`` with this coefficient set to ``value``."""
        i = self.axis
        if self.kind == "center_of_buoyancy":
            cob = params.center_of_buoyancy_m.copy()
            cob[i] = value
            return dataclasses.replace(params, center_of_buoyancy_m=cob)
        if self.kind == "quadratic_damping":
            quadratic = params.quadratic_damping.copy()
            quadratic[i] = value
            return dataclasses.replace(params, quadratic_damping=quadratic)
        matrix = getattr(params, self.kind).copy()
        matrix[i, i] = value
        return dataclasses.replace(params, **{self.kind: matrix})


#: what the pool trials excite: roll and pitch damping, the hull's centre of buoyancy, and two
#: properties of the recording: the encoders' lag on the IMU clock (left out, ~0.2 s of lag
#: reads as too little damping) and the IMU's mounting yaw on the hull (left out, the roll the
#: IMU reads in proportion to pitch, psi theta, is left as a pitch-dependent roll error)
DEFAULT_FIT = (
    "linear_damping.roll",
    "linear_damping.pitch",
    "quadratic_damping.roll",
    "quadratic_damping.pitch",
    "center_of_buoyancy.x",
    "center_of_buoyancy.y",
    "center_of_buoyancy.z",
    "arm_delay",
    "imu_yaw",
)


def parse_parameters(names: Sequence[str]) -> tuple[HydroParameter, ...]:
    """`HydroParameter` s from names such as ``quadratic_damping.roll``.

    Raises:
        ParameterError: an unknown kind or axis, a centre of buoyancy along a rotation, a
            name given twice, or no name at all.
    """
    if not names:
        raise ParameterError(
            "no parameter to identify: name at least one, e.g. linear_damping.roll"
        )
    out = []
    for name in names:
        if name.strip() in RECORDING:
            out.append(HydroParameter(name.strip(), 0))
            continue
        kind, _, axis = name.strip().partition(".")
        if kind not in KINDS or axis not in AXES:
            raise ParameterError(
                f"unknown parameter '{name}': give <kind>.<axis>, kind one of {', '.join(KINDS)}, "
                f"axis one of {', '.join(AXES)}, or {' or '.join(RECORDING)}"
            )
        if kind == "center_of_buoyancy" and AXES.index(axis) > 2:
            raise ParameterError(f"unknown parameter '{name}': center_of_buoyancy has x, y, z")
        out.append(HydroParameter(kind, AXES.index(axis)))
    seen = [p.name for p in out]
    twice = sorted({n for n in seen if seen.count(n) > 1})
    if twice:
        raise ParameterError(f"parameter given twice: {', '.join(twice)}")
    return tuple(out)


def hydro_body(uvms: UVMS, link: str) -> HydroBody:
    """The body named ``link`` (ParameterError naming the bodies there are otherwise)."""
    found = [b for b in uvms.hydro_bodies if b.name == link]
    if len(found) != 1:
        names = ", ".join(b.name for b in uvms.hydro_bodies)
        raise ParameterError(f"no hydrodynamic body '{link}' to identify (have {names})")
    return found[0]


def parameter_values(uvms: UVMS, parameters: Sequence[HydroParameter], link: str) -> np.ndarray:
    """The parameters' current values on ``link`` of ``uvms`` (``arm_delay``, ``imu_yaw``:
    0, the model holds none)."""
    params = hydro_body(uvms, link).params
    return np.array([p.value(params) if p.hydrodynamic else 0.0 for p in parameters])


def with_parameters(
    uvms: UVMS, parameters: Sequence[HydroParameter], values: np.ndarray, link: str
) -> UVMS:
    """The same system with ``link``'s parameters set to ``values`` (ParameterError if the
    result is not a valid body, e.g. a negative damping; the recording's parameters are not the
    model's)."""
    hydro_body(uvms, link)

    def replaced(body: HydroBody) -> HydroParams:
        if body.name != link:
            return body.params
        params = body.params
        for parameter, value in zip(parameters, values, strict=True):
            if parameter.hydrodynamic:
                params = parameter.replaced(params, float(value))
        return params

    return uvms.with_hydro(replaced)


def _wrench_sensitivity(
    parameter: HydroParameter, nu_r_body: np.ndarray, buoyancy_body_N: np.ndarray
) -> np.ndarray:
    """dw/dp (6,): the body-frame fluid wrench's derivative in one analytic parameter."""
    out = np.zeros(6)
    i = parameter.axis
    if parameter.kind == "linear_damping":
        out[i] = -nu_r_body[i]
    elif parameter.kind == "quadratic_damping":
        out[i] = -abs(nu_r_body[i]) * nu_r_body[i]
    else:  # centre of buoyancy: d(r x f)/dr_i = -[f]x e_i
        out[3:] = -skew(buoyancy_body_N)[:, i]
    return out


def generalized_force_sensitivity(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    parameters: Sequence[HydroParameter],
    link: str,
) -> np.ndarray:
    """dF/dp (nv, n_linear) of the fluid's generalized force, in still water without a
    free surface, for the parameters among ``parameters`` it is linear in (`force_linear`, in
    their order).

    F = J_j^T X^T w: w the body-frame wrench, nu_r = X J_j v the body's velocity in its hydro
    frame (no current), f_B the buoyancy R_body^T (-rho V g).
    """
    body = hydro_body(uvms, link)
    model, data = uvms.model, uvms.data
    pin.computeJointJacobians(model, data, q)
    jac = pin.getJointJacobian(model, data, body.joint_id, pin.LOCAL)
    action = body.action_joint_to_body
    nu_r = action @ (jac @ v)
    rotation = data.oMi[body.joint_id].rotation @ body.placement_in_joint.rotation
    buoyancy_world = -uvms.water_density_kg_m3 * body.params.volume_m3 * model.gravity.linear
    buoyancy_body = rotation.T @ buoyancy_world
    columns = [_wrench_sensitivity(p, nu_r, buoyancy_body) for p in parameters if p.force_linear]
    if not columns:
        return np.zeros((uvms.nv, 0))
    return jac.T @ action.T @ np.column_stack(columns)
