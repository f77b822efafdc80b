"""A source's rotational inertia that no mass distribution has: refused, or balanced.

Gazebo does not check a link's ``<inertia>``; uvms-pin's loader does (`uvms_pin.model.urdf.
inertial`): principal moments I1 <= I2 <= I3 must satisfy the triangle inequality
I1 + I2 >= I3 (I1 + I2 - I3 = 2 sum m z^2 in the principal frame). Some published vehicles
break it (uuv_simulator's ECA A9: (0.6, 30, 35) kg m^2). The import checks every link before
it writes anything: such a link is refused, naming it and the moments; with ``balance``
(``uvms-pin import --balance-inertia``, as MuJoCo's ``balanceinertia``) its smallest principal
moment is raised to I3 - I2, the least change that makes the inertia one a body can have,
in the same principal axes, and the notes say what changed. Every other check of the
``<inertial>`` is the loader's, at the import.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from uvms_pin.errors import ModelError
from uvms_pin.model.urdf.inertial import (
    INERTIA_KEYS,
    check_inertial,
    inertia_matrix,
    triangle_slack,
)
from uvms_pin.results.format import numbers_text

__all__ = ["check_inertias"]


def check_inertias(robot: ET.Element, where: str, notes: list[str], *, balance: bool) -> None:
    """Every ``<inertial>`` of ``robot`` checked as the loader checks it; an inertia that
    breaks only the triangle inequality balanced when ``balance`` (noted), else refused.

    Raises:
        ModelError: naming the link: an inertial the loader refuses (without ``balance``,
            one that breaks the triangle inequality too, saying how to balance it).
    """
    for link in robot.iter("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        name = link.get("name", "?")
        inertia = inertial.find("inertia")
        matrix = _matrix(inertia) if inertia is not None else None
        principal, axes = np.linalg.eigh(matrix) if matrix is not None else (None, None)
        # balanced only when that is all that is wrong (a negative moment is refused below)
        if principal is not None and triangle_slack(principal) < 0.0 and principal[0] >= 0.0:
            shown = numbers_text(principal, 6, ", ")
            if not balance:
                raise ModelError(
                    f"inertia violates the triangle inequality I1 + I2 >= I3: principal "
                    f"moments ({shown}) kg m^2, which no mass distribution has (Gazebo does "
                    "not check it); uvms-pin import --balance-inertia raises I1 to I3 - I2, "
                    "the least change that makes it one",
                    path=where,
                    link=name,
                )
            balanced = principal.copy()
            balanced[0] = balanced[2] - balanced[1]
            _write(inertia, axes @ np.diag(balanced) @ axes.T)
            notes.append(
                f"link '{name}': inertia ({shown}) kg m^2 breaks the triangle inequality "
                f"I1 + I2 >= I3: balanced to ({numbers_text(balanced, 6, ', ')}) kg m^2 in "
                "the same principal axes (--balance-inertia)"
            )
        check_inertial(inertial, where, name)


def _matrix(inertia: ET.Element) -> np.ndarray | None:
    """The 3x3 matrix of ``<inertia>`` (`inertia_matrix`); None when an entry is missing, not
    a finite number or a negative moment (the loader's check says which)."""
    try:
        entries = {key: float(inertia.get(key, "")) for key in INERTIA_KEYS}
    except ValueError:
        return None
    finite = all(math.isfinite(value) for value in entries.values())
    if not finite or min(entries["ixx"], entries["iyy"], entries["izz"]) < 0.0:
        return None
    return inertia_matrix(entries)


def _write(inertia: ET.Element, matrix: np.ndarray) -> None:
    for key, (row, col) in zip(INERTIA_KEYS, ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)), strict=True):  # fmt: skip
        inertia.set(key, repr(float(matrix[row, col])))
