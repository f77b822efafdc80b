"""Placements in URDF elements: reading and writing ``<origin xyz rpy>`` [m, rad], and the
fixed joints the mount adds. Numbers are written exactly (`numbers_text`, repr)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.results.format import numbers_text

__all__ = ["add_fixed_joint", "origin_of", "set_origin", "vector_attribute"]


def vector_attribute(
    element: ET.Element | None, key: str, default: str, path: Path, what: str
) -> np.ndarray:
    """The 3 finite numbers of ``element``'s attribute ``key`` (``default`` when the element
    or the attribute is absent); ModelError naming ``what`` and the file otherwise."""
    text = default if element is None else element.get(key, default)
    try:
        values = np.array([float(t) for t in text.split()])
    except ValueError as exc:
        raise ModelError(f"'{what}': non-numeric {key} '{text}'", path=str(path)) from exc
    if values.shape != (3,) or not np.all(np.isfinite(values)):
        raise ModelError(f"'{what}': {key} needs 3 finite numbers, got '{text}'", path=str(path))
    return values


def origin_of(element: ET.Element, path: Path) -> pin.SE3:
    """The placement ``element``'s <origin> gives (identity when absent)."""
    origin = element.find("origin")
    name = element.get("name", element.tag)
    xyz = vector_attribute(origin, "xyz", "0 0 0", path, name)
    rpy = vector_attribute(origin, "rpy", "0 0 0", path, name)
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)


def set_origin(element: ET.Element, placement: pin.SE3) -> None:
    """Write ``placement`` as ``element``'s <origin> (added first if there is none)."""
    origin = element.find("origin")
    if origin is None:
        origin = ET.Element("origin")
        element.insert(0, origin)
    origin.set("xyz", numbers_text(placement.translation))
    origin.set("rpy", numbers_text(pin.rpy.matrixToRpy(placement.rotation)))


def add_fixed_joint(
    out: ET.Element, name: str, parent: str, child: str, placement: pin.SE3
) -> None:
    """Append a fixed joint placing link ``child`` at ``placement`` in link ``parent``."""
    joint = ET.SubElement(out, "joint", {"name": name, "type": "fixed"})
    ET.SubElement(joint, "parent", {"link": parent})
    ET.SubElement(joint, "child", {"link": child})
    set_origin(joint, placement)
