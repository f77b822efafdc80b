"""The URDF hydrodynamic extension (docs/physics.md): a ``<hydrodynamics>`` element inside a
``<link>``, or at the top level with ``link="NAME"``, holds that link's coefficients::

    <hydrodynamics>
      <volume value="V [m^3]"/>
      <center_of_buoyancy xyz="r_b [m], link frame"/>
      <added_mass diagonal="6 numbers" | matrix="36 numbers"/>   [kg, kg m, kg m^2]
      <linear_damping diagonal="6" | matrix="36"/>              [N/(m/s), N m/(rad/s)]
      <quadratic_damping diagonal="6"/>                         [N/(m/s)^2, N m/(rad/s)^2]
    </hydrodynamics>

at the link origin, in the link frame, spatial order [linear x, y, z; angular x, y, z].
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.hydro.params import HydroParams
from uvms_pin.model.urdf.read import known_children, read_numbers, single

__all__ = ["HYDRO_TAGS", "hydro_elements_by_link", "parse_hydro"]

#: The child elements a <hydrodynamics> element may have.
HYDRO_TAGS = {"volume", "center_of_buoyancy", "added_mass", "linear_damping", "quadratic_damping"}


def hydro_elements_by_link(
    root: ET.Element, links: dict[str, ET.Element], where: str
) -> dict[str, ET.Element]:
    """Each link's one <hydrodynamics> element (in the link or top-level with link=...)."""
    found: dict[str, ET.Element] = {}
    for name, link in links.items():
        elements = link.findall("hydrodynamics")
        if len(elements) > 1:
            raise ModelError("has more than one <hydrodynamics> element", path=where, link=name)
        if elements:
            found[name] = elements[0]
    for element in root.findall("hydrodynamics"):
        name = element.get("link")
        if name is None:
            raise ModelError('top-level <hydrodynamics> needs a link="NAME" attribute', path=where)
        if name not in links:
            raise ModelError(
                "top-level <hydrodynamics> names a link that does not exist", path=where, link=name
            )
        if name in found:
            raise ModelError("has more than one <hydrodynamics> element", path=where, link=name)
        found[name] = element
    return found


def parse_hydro(element: ET.Element, where: str, link: str) -> HydroParams:
    """The coefficients a <hydrodynamics> element gives (absent matrices are zero)."""
    known_children(element, HYDRO_TAGS, where, link)
    volume_el = single(element, "volume", where, link)
    if volume_el is None:
        raise ModelError("<hydrodynamics> has no <volume>", path=where, link=link)
    volume = float(read_numbers(volume_el.get("value"), 1, "<volume value>", where, link)[0])
    if volume < 0.0:
        raise ModelError(f"negative volume {volume} m^3", path=where, link=link)
    cob_el = single(element, "center_of_buoyancy", where, link)
    cob = (
        np.zeros(3)
        if cob_el is None
        else read_numbers(cob_el.get("xyz"), 3, "<center_of_buoyancy xyz>", where, link)
    )
    added = _matrix_6x6(single(element, "added_mass", where, link), "added_mass", where, link)
    linear = _matrix_6x6(
        single(element, "linear_damping", where, link), "linear_damping", where, link
    )
    quad_el = single(element, "quadratic_damping", where, link)
    quadratic = np.zeros(6)
    if quad_el is not None:
        quadratic = read_numbers(
            quad_el.get("diagonal"), 6, "<quadratic_damping diagonal>", where, link
        )
    try:
        return HydroParams(volume, cob, added, linear, quadratic, derived=False, origin="URDF")
    except ParameterError as exc:
        raise ModelError(str(exc), path=where, link=link) from exc


def _matrix_6x6(element: ET.Element | None, what: str, where: str, link: str) -> np.ndarray:
    """A 6x6 matrix from ``diagonal`` (magnitudes, >= 0) or ``matrix`` (row-major); zero
    when the element is absent."""
    if element is None:
        return np.zeros((6, 6))
    diagonal, matrix = element.get("diagonal"), element.get("matrix")
    if (diagonal is None) == (matrix is None):
        raise ModelError(
            f'<{what}> needs exactly one of diagonal="6 numbers" or matrix="36 numbers"',
            path=where,
            link=link,
        )
    if diagonal is not None:
        values = read_numbers(diagonal, 6, f"<{what} diagonal>", where, link)
        if np.any(values < 0.0):
            raise ModelError(
                f"<{what}> diagonal must be >= 0 (magnitudes), got {values.tolist()}",
                path=where,
                link=link,
            )
        return np.diag(values)
    return read_numbers(matrix, 36, f"<{what} matrix>", where, link).reshape(6, 6)
