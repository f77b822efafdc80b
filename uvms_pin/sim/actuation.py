"""Actuators: what part of a commanded tau the vehicle and the arm can actually apply.

The vehicle's body wrench comes from thrusters, tau_v = B f, with B (6 x m) built from
each thruster's position r_i and unit direction d_i in the body frame, column
[d_i; r_i x d_i]. A command is allocated by the pseudo-inverse, f = B^+ tau_v, each thrust
is clipped to its limits, and B f is applied: directions no thruster can push (e.g. an
LBV150's roll and pitch) are simply not applied. Arm torques are clipped to the joints'
effort limits. `Unlimited` applies the command as it is (the paper's assumption).

Each thruster is a drive (`uvms_pin.sim.thruster_drive`): its driver sends the command u on
its thrust curve that gives the allocated thrust, and the thrust follows with first-order
dynamics and a rate limit; by default the curve is linear up to the limits and the lag is
none, so the allocated thrust is applied at once. The commands and thrusts are logged as the
signals ``thruster_command`` (u, dimensionless) and ``thrust`` (N), a column per thruster.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.model.thrust_curve import TabulatedThrustCurve
from uvms_pin.model.thruster import Thruster
from uvms_pin.sim.thruster_drive import ThrusterDrives

#: how far past its limit a command must ask to count as saturating an actuator [N or N m]:
#: more than the allocation's rounding (a thrust planned on its bound, B^+ (B u) = u to
#: ~1e-15, is not saturated; the compared controllers' saturated fraction must not depend on
#: which side of the bound the rounding falls)
PAST_LIMIT_N = 1e-9


class Actuation(ABC):
    """Maps a commanded generalized input to the applied one."""

    @abstractmethod
    def apply(self, tau_commanded: np.ndarray) -> np.ndarray:
        """The applied tau (nv,) [N, N m]."""

    def saturated(self, tau_commanded: np.ndarray) -> bool:
        """True when an actuator cannot give what the command asks."""
        return False

    def start(self, period_s: float | None = None) -> None:  # noqa: B027 - optional hook
        """A run starts: actuator states to rest, and what earlier runs dropped forgotten;
        ``period_s`` the control period (None: the controller is evaluated continuously)."""

    def dropped(self) -> str | None:
        """What the run so far asked that the actuators cannot produce at all (not a
        saturation: a direction), for a warning; None if nothing."""
        return None

    def signals(self) -> dict[str, np.ndarray]:
        """The actuators' signals after the last `apply`, by name."""
        return {}

    def signal_columns(self) -> dict[str, list[tuple[str, str]]]:
        """Per signal of `signals`: (column name, unit suffix) of each entry."""
        return {}


class Unlimited(Actuation):
    """Every DoF actuated without limit: tau_applied = tau_commanded."""

    def apply(self, tau_commanded):
        return tau_commanded


class ThrustersAndJointLimits(Actuation):
    """Thruster allocation with saturation for the vehicle, effort limits for the joints.

    Args:
        thrusters: the vehicle's thrusters (at least one).
        joint_effort_limits_Nm: |tau_j| limits (n_joints,), e.g. the URDF's effort limits;
            None = arm torques unlimited.
        allocated_components: indices (0-5: surge, sway, heave, roll, pitch, yaw) of the
            commanded body wrench the allocation tries to produce, f = B_s^+ tau_s; the
            others are ignored (e.g. the roll and pitch of a vehicle whose thrusters cannot
            produce them on purpose). The applied wrench is always B f, side effects
            included. Default: all six.
        drives: the thrusters' curves and dynamics (default: linear curves to the limits,
            no lag).

    Attributes (read-only, what the compiled actuation mirrors): ``allocation`` B (6 x m);
    ``allocation_pinv`` (m x 6), B_s^+ on the allocated components, zero columns elsewhere;
    ``lower_N``, ``upper_N`` (m,) the thrust bounds; ``full_forward_N``, ``full_reverse_N``
    (m,) the thrust of a full command (inf for a zero limit); ``residual`` I - B_s B_s^+ or
    None when the thrusters span the allocated components; ``drives_ideal``: the default
    drives (thrust = its allocation at once).
    """

    def __init__(
        self,
        thrusters: Sequence[Thruster],
        joint_effort_limits_Nm: np.ndarray | None,
        allocated_components: Sequence[int] = (0, 1, 2, 3, 4, 5),
        drives: ThrusterDrives | None = None,
    ):
        if not thrusters:
            raise ParameterError("at least one thruster is needed")
        components = np.asarray(allocated_components, dtype=int)
        if (
            components.size == 0
            or np.any((components < 0) | (components > 5))
            or len(set(components.tolist())) != components.size
        ):
            raise ParameterError(
                f"allocated_components must be distinct indices in 0..5, got {list(allocated_components)}"
            )
        self.thrusters = tuple(thrusters)
        self.allocation = np.column_stack([t.wrench_column for t in self.thrusters])  # B, 6 x m
        self.allocated_components = components
        # f = B_s^+ tau[s]: written as a 6-column map that ignores the other components
        self.allocation_pinv = np.zeros((len(self.thrusters), 6))
        self.allocation_pinv[:, components] = np.linalg.pinv(self.allocation[components])
        # what of an allocated command no thrust can produce: (I - B_s B_s^+) tau_s, tracked
        # only when the thrusters do not span the allocated components
        chosen = self.allocation[components]
        residual = np.eye(components.size) - chosen @ np.linalg.pinv(chosen)
        self.residual = residual if np.max(np.abs(residual)) > 1e-9 else None
        self.dropped_max = np.zeros(components.size)
        self.lower_N = -np.array([t.max_reverse_N for t in self.thrusters])
        self.upper_N = np.array([t.max_forward_N for t in self.thrusters])
        # the default drives give the allocated thrust at once: computed directly (fast path)
        self.drives_ideal = drives is None
        if drives is None:
            drives = ideal_drives(self.thrusters)
        if len(drives.curves) != len(self.thrusters):
            raise ParameterError(f"{len(drives.curves)} drives for {len(self.thrusters)} thrusters")
        self.drives = drives
        self.thruster_command = np.zeros(len(self.thrusters))
        self.thrust_N = np.zeros(len(self.thrusters))
        # the linear curve's command u = f / limit (a zero limit: u = 0, f = 0)
        self.full_forward_N = np.where(self.upper_N > 0.0, self.upper_N, np.inf)
        self.full_reverse_N = np.where(self.lower_N < 0.0, -self.lower_N, np.inf)
        if joint_effort_limits_Nm is not None:
            limits = np.asarray(joint_effort_limits_Nm, dtype=float)
            if np.any(~(limits > 0.0)) or not np.all(np.isfinite(limits)):
                raise ParameterError(
                    f"joint effort limits must be positive and finite, got {limits}"
                )
            joint_effort_limits_Nm = limits
        self.joint_effort_limits_Nm = joint_effort_limits_Nm

    def thrusts(self, tau_commanded: np.ndarray) -> np.ndarray:
        """Per-thruster thrust f (m,) [N] after allocation and saturation."""
        # minimum(maximum()) is np.clip without its per-call dispatch cost
        return np.minimum(
            np.maximum(self.allocation_pinv @ tau_commanded[:6], self.lower_N), self.upper_N
        )

    def saturated(self, tau_commanded: np.ndarray) -> bool:
        """True when a thruster or a joint cannot give what the command asks: past its limit
        by more than `PAST_LIMIT_N` (a plan that puts a thrust on its bound, as the MPC's
        box-constrained one does, is not saturated by the allocation's rounding)."""
        raw = self.allocation_pinv @ tau_commanded[:6]
        if np.any(raw < self.lower_N - PAST_LIMIT_N) or np.any(raw > self.upper_N + PAST_LIMIT_N):
            return True
        limits = self.joint_effort_limits_Nm
        return limits is not None and bool(
            np.any(np.abs(tau_commanded[6:]) > limits + PAST_LIMIT_N)
        )

    def start(self, period_s: float | None = None) -> None:
        self.dropped_max[:] = 0.0
        self.drives.start(period_s)
        self.thruster_command = np.zeros(len(self.thrusters))
        self.thrust_N = np.zeros(len(self.thrusters))

    def signals(self) -> dict[str, np.ndarray]:
        return {"thruster_command": self.thruster_command.copy(), "thrust": self.thrust_N.copy()}

    def signal_columns(self) -> dict[str, list[tuple[str, str]]]:
        names = [t.name for t in self.thrusters]
        return {
            "thruster_command": [(name, "") for name in names],
            "thrust": [(name, "N") for name in names],
        }

    def _unproducible(self) -> list[int]:
        """Positions (in the allocated components) of those the thrusters cannot produce: as
        many as the thrusters' rank lacks, those weighing most in what no thrust reaches."""
        chosen = self.allocation[self.allocated_components]
        missing = self.allocated_components.size - np.linalg.matrix_rank(chosen, tol=1e-9)
        weight = np.abs(np.diag(self.residual))  # each axis's share no thrust reaches
        return sorted(int(k) for k in np.argsort(-weight, kind="stable")[:missing])

    def dropped(self) -> str | None:
        """The allocated components no thrust can produce and the largest part of a command
        dropped on each (the allocation is least squares: it leaves them out silently)."""
        if self.residual is None or not np.any(self.dropped_max > 1e-6):
            return None
        names = ("surge force fx", "sway force fy", "heave force fz", "roll moment mx",
                 "pitch moment my", "yaw moment mz")  # fmt: skip
        units = ("N", "N", "N", "N m", "N m", "N m")
        lost = self._unproducible()
        components = self.allocated_components
        parts = [
            f"{self.dropped_max[k]:.3g} {units[components[k]]} of {names[components[k]]}"
            for k in lost
            if self.dropped_max[k] > 1e-6
        ] or [f"{np.max(self.dropped_max):.3g} N or N m"]  # coupled: no one axis stands out
        kept = [int(c) for k, c in enumerate(components) if k not in lost]
        return (
            "the thrusters cannot produce every wrench component the controller commands: "
            f"the allocation dropped up to {' and '.join(parts)}; if that is meant, say so "
            f"with actuation.allocated_components = {kept} (what they can produce)"
        )

    def apply(self, tau_commanded):
        if self.residual is not None:  # what no thrust can produce: the largest so far
            lost = np.abs(self.residual @ tau_commanded[self.allocated_components])
            np.maximum(self.dropped_max, lost, out=self.dropped_max)
        out = np.empty_like(tau_commanded)
        if self.drives_ideal:
            self.thrust_N = self.thrusts(tau_commanded)
            self.thruster_command = self.thrust_N / np.where(
                self.thrust_N >= 0.0, self.full_forward_N, self.full_reverse_N
            )
        else:
            self.thruster_command = self.drives.commands(self.thrusts(tau_commanded))
            self.thrust_N = self.drives.advance(self.thruster_command)
        out[:6] = self.allocation @ self.thrust_N
        arm = tau_commanded[6:]
        if self.joint_effort_limits_Nm is None:
            out[6:] = arm
        else:
            if arm.shape != self.joint_effort_limits_Nm.shape:
                raise ParameterError(
                    f"{arm.size} arm torques for {self.joint_effort_limits_Nm.size} effort limits"
                )
            limits = self.joint_effort_limits_Nm
            out[6:] = np.minimum(np.maximum(arm, -limits), limits)
        return out


def linear_curve(thruster: Thruster) -> TabulatedThrustCurve:
    """T = u max_forward_N (u > 0), u max_reverse_N (u < 0): a driver that gives the thrust
    asked for, up to the limits."""
    return TabulatedThrustCurve(
        np.array([-1.0, 0.0, 1.0]),
        np.array([-thruster.max_reverse_N, 0.0, thruster.max_forward_N]),
        name="linear",
    )


def ideal_drives(thrusters: Sequence[Thruster]) -> ThrusterDrives:
    """Linear curves, no lag, no rate limit: the allocated thrust at once."""
    m = len(thrusters)
    return ThrusterDrives([linear_curve(t) for t in thrusters], [0.0] * m, [np.inf] * m)
