"""The trim in the URDF: the foam and ballast slabs `uvms_pin.model.trim.plan_trim` chose,
as fixed links of the vehicle link (box inertia, a ``<hydrodynamics>`` holding their volume;
their added mass and drag are neglected, see `uvms_pin.model.trim`)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from uvms_pin.model.trim import TrimReport
from uvms_pin.results.format import numbers_text

__all__ = ["TRIM_LINKS", "add_trim_links"]

#: The links the trim adds (each on a fixed joint ``<link>_joint``): foam, ballast.
TRIM_LINKS = ("trim_foam", "trim_ballast")


def add_trim_links(root: ET.Element, vehicle_link: str, report: TrimReport, prefix: str) -> None:
    """Append the foam and ballast as fixed links of ``vehicle_link`` to a URDF tree, named
    `TRIM_LINKS`, each with ``prefix`` put before it while the tree uses the name (the trim
    of an arm a vehicle file keeps beside the new one)."""
    foam, ballast = TRIM_LINKS
    slabs = []
    if report.foam_volume_m3 > 0.0:
        slabs.append(
            (foam, report.foam_mass_kg, report.foam_size_m, report.foam_position_m,
             report.foam_volume_m3)
        )  # fmt: skip
    if report.ballast_mass_kg > 0.0:
        slabs.append(
            (ballast, report.ballast_mass_kg, report.ballast_size_m,
             report.ballast_position_m, report.ballast_volume_m3)
        )  # fmt: skip
    taken = {element.get("name") for element in root if element.tag in ("link", "joint")}
    for kind, mass, size, position, volume in slabs:
        name = kind
        while name in taken or f"{name}_joint" in taken:
            name = prefix + name
        root.append(_slab_link(name, mass, size, _hydro_element(volume), _TRIM_RGBA[kind]))
        joint = ET.SubElement(root, "joint", {"name": f"{name}_joint", "type": "fixed"})
        ET.SubElement(joint, "parent", {"link": vehicle_link})
        ET.SubElement(joint, "child", {"link": name})
        ET.SubElement(joint, "origin", {"xyz": numbers_text(position), "rpy": "0 0 0"})


# drawing only: the foam a translucent amber sheet, the ballast a translucent lead-grey one
# (each spans the hull's footprint, thin)
_TRIM_RGBA = {"trim_foam": "1 0.8 0.3 0.2", "trim_ballast": "0.35 0.35 0.38 0.6"}


def _slab_link(
    name: str, mass: float, size: tuple[float, float, float], hydro: ET.Element, rgba: str
) -> ET.Element:
    """A solid slab of ``size`` (lx, ly, lz) [m] and ``mass`` [kg] centred on the link
    origin: box inertia m (b^2 + c^2) / 12, a box to draw (``rgba``), ``hydro`` for its
    volume."""
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
    ET.SubElement(material, "color", {"rgba": rgba})
    link.append(hydro)
    return link


def _hydro_element(volume: float) -> ET.Element:
    """A <hydrodynamics> with ``volume`` [m^3] at the link origin and nothing else."""
    element = ET.Element("hydrodynamics")
    ET.SubElement(element, "volume", {"value": repr(float(volume))})
    ET.SubElement(element, "center_of_buoyancy", {"xyz": "0 0 0"})
    return element
