"""The gains and funnels of the prescribed-performance controller, with the paper's values
and its errata fixed."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from uvms_pin.checks import sized_vector
from uvms_pin.control.performance import check_funnel_bounds
from uvms_pin.errors import ParameterError
from uvms_pin.results.components import FIRST_LEVEL_NAMES, VEHICLE_VELOCITY_NAMES

#: The vehicle's generalized velocities (a free-flyer: 6); the arm's follow.
N_VEHICLE = 6


@dataclass(frozen=True, eq=False)
class PPCParams:
    """Gains and funnels of :class:`PrescribedPerformanceController`.

    Every array field accepts a scalar (broadcast to all components) or one value per
    component: 6 for the first level (``_x``: f_x, f_y, f_z [N]; roll, pitch, yaw [rad]),
    nv = 6 + n_joints for the second level (``_zeta``: u, v, w [m/s]; p, q, r [rad/s];
    joint rates [rad/s]). :meth:`for_uvms` returns fully sized arrays; :meth:`sized`
    validates and sizes any instance: that is where the parameters are checked, once; the
    sized instance it returns is trusted downstream (sizing it again for the same nv
    returns it as it is).

    Defaults are the paper's simulation values (Section 5) with its errata fixed
    (docs/controller.md):

    - ``k_x = 0.2`` and ``k_zeta = 5``: the paper prints k_x = -0.2 and k_v = -5, but its
      law (eq. 13, 18) already carries the minus sign and requires k > 0; negative gains
      would push every error out of its funnel.
    - The paper's rho_v / rho_zeta and P(t) / P_zeta(t) are the same thing: here ``_zeta``.
    - ``l_x = 3`` for all six: the paper gives l_x only for j = 1..3 (forces); we use 3 for
      the orientation components too.
    - ``rho_inf_zeta``: 0.2 for the 6 vehicle components and 0.4 for the arm joints (the
      paper's second "j in {1..6}" line is the vehicle). ``None`` means this split.

    Attributes:
        k_x: first-level gains k_x [m/s or rad/s per unit of eps], > 0, (6,).
        k_zeta: diagonal of K_zeta [N, N m per unit of eps rho^-1], > 0, (nv,).
        rho0_x, rho_inf_x: first-level funnel bounds [N (3); rad (3)].
        l_x_per_s: first-level decay rates [1/s].
        rho0_zeta, rho_inf_zeta: second-level funnel bounds [m/s (3); rad/s (3 + n)].
        l_zeta_per_s: second-level decay rates [1/s].
        desired_rpy: constant desired end-effector Euler angles (roll, pitch, yaw) [rad],
            used when the controller is given no ``desired_rpy``.
        null_space_gain_per_s: gain k_0 >= 0 [rad/s] of the optional secondary task
            (joint-limit avoidance in the null space of J). 0 (default) = the paper's plain
            pseudo-inverse, eq. (9).
        pinv_relative_cutoff: singular values of J below this fraction of the largest are
            treated as zero in J^+ (numerical rank only, no damping).
        null_space_target: arm joint positions (n_joints,) [rad] the secondary task pulls
            toward (e.g. a pose with reach in the task direction); None = mid-range.
        velocity_weights: positive weights W (nv,) of the generalized pseudo-inverse of the
            paper's remark, J^# = W^-1 J^T (J W^-1 J^T)^+, which minimises zeta^T W zeta:
            a large weight keeps that DoF out of the task (e.g. an unactuated vehicle roll).
            1 (default) = the Moore-Penrose pseudo-inverse of eq. (9).
    """

    k_x: ArrayLike = 0.2
    k_zeta: ArrayLike = 5.0
    rho0_x: ArrayLike = (1.0, 1.0, 1.0, 0.9, 0.9, 0.9)
    rho_inf_x: ArrayLike = 0.2
    l_x_per_s: ArrayLike = 3.0
    rho0_zeta: ArrayLike = 1.0
    rho_inf_zeta: ArrayLike | None = None
    l_zeta_per_s: ArrayLike = 2.2
    desired_rpy: ArrayLike = (0.0, 0.0, 0.0)
    null_space_gain_per_s: float = 0.0
    pinv_relative_cutoff: float = 1e-12
    velocity_weights: ArrayLike = 1.0
    null_space_target: ArrayLike | None = None

    @classmethod
    def for_uvms(cls, n_joints: int, **overrides) -> PPCParams:
        """The paper's parameters sized for a vehicle with ``n_joints`` arm DoFs.

        ``overrides`` replace fields before sizing (e.g. ``k_zeta=2.0``).
        """
        if int(n_joints) != n_joints or n_joints < 0:
            raise ParameterError(f"n_joints must be a non-negative integer, got {n_joints}")
        return cls(**overrides).sized(N_VEHICLE + int(n_joints))

    def sized(self, nv: int, velocity_names: Sequence[str] | None = None) -> PPCParams:
        """A copy whose array fields have 6 (first level) or ``nv`` (second level) entries,
        every value checked (the one place the parameters are); ``self`` when it already is
        such a copy for ``nv``. ``velocity_names``: the nv generalized velocities' names, as
        errors name a second-level funnel (default: u, v, w, p, q, r, joint 1 rate, ...).

        Raises:
            ParameterError: naming the field first: a wrong size or a non-finite value, a
                gain not > 0, a funnel without rho0 > rho_inf > 0 and a decay rate > 0, or
                ``null_space_gain_per_s`` / ``pinv_relative_cutoff`` not finite and >= 0.
        """
        nv = int(nv)
        if getattr(self, "_checked_nv", None) == nv:
            return self
        if nv < N_VEHICLE:
            raise ParameterError(f"nv = {nv}: a UVMS has at least the 6 vehicle velocities")
        rho_inf_zeta = self.rho_inf_zeta
        if rho_inf_zeta is None:
            rho_inf_zeta = np.r_[np.full(N_VEHICLE, 0.2), np.full(nv - N_VEHICLE, 0.4)]
        sized = {
            "k_x": sized_vector("k_x", self.k_x, 6),
            "rho0_x": sized_vector("rho0_x", self.rho0_x, 6),
            "rho_inf_x": sized_vector("rho_inf_x", self.rho_inf_x, 6),
            "l_x_per_s": sized_vector("l_x_per_s", self.l_x_per_s, 6),
            "desired_rpy": sized_vector("desired_rpy", self.desired_rpy, 3),
            "k_zeta": sized_vector("k_zeta", self.k_zeta, nv),
            "rho0_zeta": sized_vector("rho0_zeta", self.rho0_zeta, nv),
            "rho_inf_zeta": sized_vector("rho_inf_zeta", rho_inf_zeta, nv),
            "l_zeta_per_s": sized_vector("l_zeta_per_s", self.l_zeta_per_s, nv),
            "velocity_weights": sized_vector("velocity_weights", self.velocity_weights, nv),
        }
        if self.null_space_target is not None:
            sized["null_space_target"] = sized_vector(
                "null_space_target", self.null_space_target, nv - N_VEHICLE
            )
        for name in ("k_x", "k_zeta", "velocity_weights"):
            bad = np.flatnonzero(~(sized[name] > 0.0))
            if bad.size:
                raise ParameterError(
                    f"{name} must be > 0 (the law already has the minus sign; the paper's "
                    f"printed negative gains are an erratum), got {sized[name][bad]} at "
                    f"indices {bad.tolist()}"
                )
        names_zeta = _velocity_names(nv) if velocity_names is None else tuple(velocity_names)
        for level, names in (("x", FIRST_LEVEL_NAMES), ("zeta", names_zeta)):
            funnel = (sized[f"rho0_{level}"], sized[f"rho_inf_{level}"], sized[f"l_{level}_per_s"])
            check_funnel_bounds(*funnel, names)
        for name in ("null_space_gain_per_s", "pinv_relative_cutoff"):
            value = _number(name, getattr(self, name))
            if not (np.isfinite(value) and value >= 0.0):
                raise ParameterError(f"{name} must be finite and >= 0, got {value}")
        checked = dataclasses.replace(self, **sized)
        object.__setattr__(checked, "_checked_nv", nv)  # not a field: not recorded, not compared
        return checked


def _velocity_names(nv: int) -> tuple[str, ...]:
    return (*VEHICLE_VELOCITY_NAMES, *(f"joint {k + 1} rate" for k in range(nv - N_VEHICLE)))


def _number(name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise ParameterError(f"{name} must be a number, got {value!r}")
    return float(value)
