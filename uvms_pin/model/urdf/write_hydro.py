"""Writing a link's coefficients back into a URDF's ``<hydrodynamics>`` element (the inverse
of `uvms_pin.model.urdf.hydrodynamics.parse_hydro`), e.g. an identified vehicle's."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from uvms_pin.errors import ModelError
from uvms_pin.hydro.params import HydroParams
from uvms_pin.model.urdf.hydrodynamics import hydro_elements_by_link
from uvms_pin.model.urdf.read import read_urdf_root
from uvms_pin.results.format import numbers_text

__all__ = ["urdf_with_hydro"]


def _matrix_attributes(matrix: np.ndarray) -> dict[str, str]:
    """``diagonal`` for a diagonal matrix, else the 36 numbers row-major as ``matrix``."""
    if np.array_equal(matrix, np.diag(np.diag(matrix))):
        return {"diagonal": numbers_text(np.diag(matrix))}
    return {"matrix": numbers_text(matrix.ravel())}


def _set_child(element: ET.Element, tag: str, attributes: dict[str, str]) -> None:
    child = element.find(tag)
    if child is None:
        child = ET.SubElement(element, tag)
    child.attrib.clear()
    child.attrib.update(attributes)


def urdf_with_hydro(path: str | Path, link: str, params: HydroParams) -> ET.Element:
    """The <robot> tree of the URDF at ``path`` with ``link``'s <hydrodynamics> holding
    ``params`` (every number written exactly; the rest of the file unchanged).

    Raises:
        ModelError: an unreadable file, or no <hydrodynamics> for ``link`` in it.
    """
    root = read_urdf_root(Path(path))
    links = {el.get("name"): el for el in root.findall("link")}
    element = hydro_elements_by_link(root, links, str(path)).get(link)
    if element is None:
        raise ModelError("has no <hydrodynamics> element to write into", path=str(path), link=link)
    _set_child(element, "volume", {"value": numbers_text([params.volume_m3])})
    _set_child(element, "center_of_buoyancy", {"xyz": numbers_text(params.center_of_buoyancy_m)})
    _set_child(element, "added_mass", _matrix_attributes(params.added_mass))
    _set_child(element, "linear_damping", _matrix_attributes(params.linear_damping))
    _set_child(element, "quadratic_damping", {"diagonal": numbers_text(params.quadratic_damping)})
    return root
