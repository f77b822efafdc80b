"""Hydrodynamic parameters of one rigid body (a URDF link or a collision primitive)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from uvms_pin.errors import ParameterError


@dataclass(frozen=True)
class HydroParams:
    """Hydrodynamic coefficients of one rigid body, at its frame origin, in its frame.

    Spatial quantities use Pinocchio's ordering [linear (3); angular (3)].

    Attributes:
        volume_m3: displaced volume V [m^3]; buoyancy is rho g V.
        center_of_buoyancy_m: centre of buoyancy r_b in the body frame [m].
        added_mass: M_A (6x6), symmetric positive semi-definite [kg, kg m, kg m^2].
        linear_damping: D_lin (6x6) [N/(m/s), N m/(rad/s)]; the body-frame wrench on the
            body is -D_lin nu_r.
        quadratic_damping: diagonal of D_quad (6,) [N/(m/s)^2, N m/(rad/s)^2]; the wrench
            is -diag(D_quad) |nu_r| nu_r, component-wise.
        derived: True when the numbers were computed from geometry, not read from a file.
        origin: a short human-readable note on where the numbers come from.
    """

    volume_m3: float
    center_of_buoyancy_m: np.ndarray
    added_mass: np.ndarray
    linear_damping: np.ndarray
    quadratic_damping: np.ndarray
    derived: bool = False
    origin: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        cob = np.asarray(self.center_of_buoyancy_m, dtype=float).reshape(-1)
        ma = np.asarray(self.added_mass, dtype=float)
        dl = np.asarray(self.linear_damping, dtype=float)
        dq = np.asarray(self.quadratic_damping, dtype=float).reshape(-1)
        if dl.shape == (6,):
            dl = np.diag(dl)
        if ma.shape == (6,):
            ma = np.diag(ma)
        checks = [
            (cob.shape == (3,), f"center_of_buoyancy must have 3 numbers, got {cob.shape}"),
            (ma.shape == (6, 6), f"added_mass must be 6x6, got {ma.shape}"),
            (dl.shape == (6, 6), f"linear_damping must be 6x6 or 6 numbers, got {dl.shape}"),
            (dq.shape == (6,), f"quadratic_damping must have 6 numbers, got {dq.shape}"),
        ]
        for ok, msg in checks:
            if not ok:
                raise ParameterError(msg)
        for name, arr in (
            ("volume", np.asarray(self.volume_m3)),
            ("center_of_buoyancy", cob),
            ("added_mass", ma),
            ("linear_damping", dl),
            ("quadratic_damping", dq),
        ):
            if not np.all(np.isfinite(arr)):
                raise ParameterError(f"{name} contains a non-finite value")
        if self.volume_m3 < 0.0:
            raise ParameterError(f"volume must be >= 0, got {self.volume_m3}")
        scale = max(1.0, float(np.max(np.abs(ma))))
        if not np.allclose(ma, ma.T, rtol=0.0, atol=1e-9 * scale):
            raise ParameterError("added_mass must be symmetric")
        if np.min(np.linalg.eigvalsh(ma)) < -1e-9 * scale:
            raise ParameterError("added_mass must be positive semi-definite")
        dl_sym = 0.5 * (dl + dl.T)
        if np.min(np.linalg.eigvalsh(dl_sym)) < -1e-9 * max(1.0, float(np.max(np.abs(dl)))):
            raise ParameterError("linear_damping must be positive semi-definite (dissipative)")
        if np.any(dq < 0.0):
            raise ParameterError("quadratic_damping must be >= 0 (dissipative)")
        object.__setattr__(self, "center_of_buoyancy_m", cob)
        object.__setattr__(self, "added_mass", 0.5 * (ma + ma.T))
        object.__setattr__(self, "linear_damping", dl)
        object.__setattr__(self, "quadratic_damping", dq)
        object.__setattr__(self, "volume_m3", float(self.volume_m3))

    def __eq__(self, other: object) -> bool:
        # Fix: the dataclass-generated __eq__ compares the array fields with `==` inside a
        # tuple comparison and raised "truth value of an array is ambiguous". Compare the
        # values instead (``origin`` is a note and, as declared, not compared).
        if not isinstance(other, HydroParams):
            return NotImplemented
        return (
            self.volume_m3 == other.volume_m3
            and self.derived == other.derived
            and np.array_equal(self.center_of_buoyancy_m, other.center_of_buoyancy_m)
            and np.array_equal(self.added_mass, other.added_mass)
            and np.array_equal(self.linear_damping, other.linear_damping)
            and np.array_equal(self.quadratic_damping, other.quadratic_damping)
        )

    @staticmethod
    def dry() -> HydroParams:
        """A body with no volume and no hydrodynamic effect (e.g. a frame-only link)."""
        return HydroParams(0.0, np.zeros(3), np.zeros((6, 6)), np.zeros((6, 6)), np.zeros(6))
