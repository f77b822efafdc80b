"""The trim in the URDF: the foam and ballast slabs `uvms_pin.model.trim.plan_trim` chose,
as fixed links of the vehicle link (box inertia, a ``<hydrodynamics>`` holding their volume;
their added mass and drag are neglected, see `uvms_pin.model.trim`)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from uvms_pin.model.trim import TrimReport
from uvms_pin.results.format import numbers_text

__all__ = ["add_trim_links"]


def add_trim_links(root: ET.Element, vehicle_link: str, report: TrimReport) -> None:
    """Append the foam and ballast as fixed links of ``vehicle_link`` to a URDF tree."""
    items = []
    if report.foam_volume_m3 > 0.0:
        items.append(
            (
                "trim_foam",
                report.foam_mass_kg,
                report.foam_size_m,
                report.foam_position_m,
                _hydro_element(report.foam_volume_m3),
            )
        )
    if report.ballast_mass_kg > 0.0:
        items.append(
            (
                "trim_ballast",
                report.ballast_mass_kg,
                report.ballast_size_m,
                report.ballast_position_m,
                _hydro_element(report.ballast_volume_m3),
            )
        )
    for name, mass, size, position, hydro in items:
        root.append(_slab_link(name, mass, size, hydro))
        joint = ET.SubElement(root, "joint", {"name": f"{name}_joint", "type": "fixed"})
        ET.SubElement(joint, "parent", {"link": vehicle_link})
        ET.SubElement(joint, "child", {"link": name})
        ET.SubElement(joint, "origin", {"xyz": numbers_text(position), "rpy": "0 0 0"})


# drawing only: the foam a translucent amber sheet, the ballast a translucent lead-grey one
# (each spans the hull's footprint, thin)
_TRIM_RGBA = {"trim_foam": "1 0.8 0.3 0.2", "trim_ballast": "0.35 0.35 0.38 0.6"}


def _slab_link(
    name: str, mass: float, size: tuple[float, float, float], hydro: ET.Element
) -> ET.Element:
    """A solid slab of ``size`` (lx, ly, lz) [m] and ``mass`` [kg] centred on the link
    origin: box inertia m (b^2 + c^2) / 12, a box to draw, ``hydro`` for its volume."""
    lx, ly, lz = size
    link = ET.Element("link", {"name": name})
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", {"xyz": "0 0 0", "rpy": "0 0 0"})
    ET.SubElement(inertial, "mass", {"value": repr(float(mass))})
    ixx, iyy, izz = (
        mass * (ly * ly + lz * lz) / 12.0,
        mass * (lx * lx + lz * lz) / 12.0,
        mass * (lx * lx + ly * ly) / 12.0,
    )
    ET.SubElement(
        inertial,
        "inertia",
        {
            "ixx": repr(float(ixx)),
            "iyy": repr(float(iyy)),
            "izz": repr(float(izz)),
            "ixy": "0",
            "ixz": "0",
            "iyz": "0",
        },
    )
    visual = ET.SubElement(link, "visual")
    geom = ET.SubElement(visual, "geometry")
    ET.SubElement(geom, "box", {"size": numbers_text([lx, ly, max(lz, 1e-4)])})
    material = ET.SubElement(visual, "material", {"name": name})
    ET.SubElement(material, "color", {"rgba": _TRIM_RGBA.get(name, "0.5 0.5 0.5 1")})
    link.append(hydro)
    return link


def _hydro_element(volume: float) -> ET.Element:
    """A <hydrodynamics> with ``volume`` [m^3] at the link origin and nothing else."""
    element = ET.Element("hydrodynamics")
    ET.SubElement(element, "volume", {"value": repr(float(volume))})
    ET.SubElement(element, "center_of_buoyancy", {"xyz": "0 0 0"})
    return element
