"""Checking a link's ``<inertial>``: what urdfdom and Pinocchio let through silently."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from uvms_pin.errors import ModelError
from uvms_pin.model.urdf.read import read_numbers, read_origin, single
from uvms_pin.results.format import numbers_text

__all__ = ["INERTIA_KEYS", "check_inertial", "inertia_matrix", "triangle_slack"]

# Relative slack of the inertia checks: URDF inertias are often printed with 3-4 digits,
# and a flat plate (I3 = I1 + I2 exactly) must not fail on its rounding.
_INERTIA_RELATIVE_TOLERANCE = 1e-3
#: the attributes of ``<inertia>``
INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def check_inertial(inertial: ET.Element, where: str, link: str) -> float:
    """Validate <inertial> ourselves; return the mass [kg].

    Fix: urdfdom only prints to stderr when <mass> or <inertia> is missing or non-numeric,
    and Pinocchio then builds the link with zero mass and/or zero rotational inertia, which
    silently changes the dynamics (or makes M singular). Origin xyz/rpy are checked too.
    """
    read_origin(single(inertial, "origin", where, link), where, link)
    mass_el = single(inertial, "mass", where, link)
    if mass_el is None:
        raise ModelError("<inertial> has no <mass>", path=where, link=link)
    mass = read_numbers(mass_el.get("value"), 1, "<mass value>", where, link)[0]
    if mass < 0.0:
        raise ModelError(f"negative mass {mass} kg", path=where, link=link)
    inertia_el = single(inertial, "inertia", where, link)
    if inertia_el is None:
        raise ModelError("<inertial> has no <inertia>", path=where, link=link)
    entries = {
        key: float(read_numbers(inertia_el.get(key), 1, f"<inertia {key}>", where, link)[0])
        for key in INERTIA_KEYS
    }
    _check_rotational_inertia(entries, mass, where, link)
    return mass


def _check_rotational_inertia(entries: dict[str, float], mass_kg: float, where: str, link: str):
    """The rotational inertia of a body [kg m^2] must be one a mass distribution can have.

    I = sum m_k (|r_k|^2 1 - r_k r_k^T) gives: principal moments I1 <= I2 <= I3 all >= 0
    (positive semi-definite: zero for a point mass), the triangle inequality
    I1 + I2 >= I3 (I1 + I2 - I3 = 2 sum m_k z_k^2 in the principal frame), and I = 0 when
    the mass is zero. Negative diagonal entries are refused outright.
    """
    matrix = inertia_matrix(entries)
    principal = np.linalg.eigvalsh(matrix)
    scale = float(np.max(np.abs(principal)))
    if scale == 0.0:
        return
    moments = "(" + numbers_text(principal, 6, ", ") + ")"
    if mass_kg == 0.0:
        raise ModelError(
            f"zero mass but a rotational inertia (principal moments {moments} kg m^2)",
            path=where,
            link=link,
        )
    negative = [k for k in ("ixx", "iyy", "izz") if entries[k] < 0.0]
    if negative or principal[0] < -_INERTIA_RELATIVE_TOLERANCE * scale:
        raise ModelError(
            f"inertia is not positive semi-definite: principal moments {moments} "
            f"kg m^2{' (negative ' + ', '.join(negative) + ')' if negative else ''}",
            path=where,
            link=link,
        )
    if triangle_slack(principal) < 0.0:
        raise ModelError(
            f"inertia violates the triangle inequality I1 + I2 >= I3: principal moments "
            f"{moments} kg m^2 (no mass distribution has them)",
            path=where,
            link=link,
        )


def inertia_matrix(entries: dict[str, float]) -> np.ndarray:
    """The symmetric 3x3 rotational inertia [kg m^2] of ``<inertia>``'s entries
    (`INERTIA_KEYS`)."""
    e = entries
    return np.array(
        [
            [e["ixx"], e["ixy"], e["ixz"]],
            [e["ixy"], e["iyy"], e["iyz"]],
            [e["ixz"], e["iyz"], e["izz"]],
        ]
    )


def triangle_slack(principal: np.ndarray) -> float:
    """I1 + I2 - I3 (1 - tolerance) of a rotational inertia's principal moments I1 <= I2 <= I3
    [kg m^2] (``np.linalg.eigvalsh``'s order): negative when it breaks the triangle
    inequality by more than the rounding of a printed inertia (a flat plate's I1 + I2 = I3
    passes)."""
    return float(principal[0] + principal[1] - principal[2] * (1.0 - _INERTIA_RELATIVE_TOLERANCE))
