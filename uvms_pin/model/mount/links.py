"""What the links carry into the merged file: mesh paths made absolute (a missing collision
mesh that is needed is an error, a missing visual one is dropped), visual materials the
merged file defines, and an explicit empty ``<hydrodynamics>`` on links that weigh but
displace nothing."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

from uvms_pin.errors import ModelError
from uvms_pin.model.mount.names import original_name
from uvms_pin.model.mount.tree import URDFTree
from uvms_pin.model.resources import resolve_resource

__all__ = ["mark_dry_links", "resolve_meshes", "strip_undefined_materials"]


def resolve_meshes(
    link: ET.Element,
    urdf: Path,
    package_dirs: Sequence[str | Path],
    *,
    needs_collision: bool,
    link_name: str | None = None,
) -> None:
    """Make mesh paths absolute; a missing collision mesh that is needed is an error;
    a missing visual mesh is dropped (it only matters for drawing)."""
    for tag in ("visual", "collision"):
        for element in list(link.findall(tag)):
            mesh = element.find("geometry/mesh")
            if mesh is None:
                continue
            filename = mesh.get("filename", "")
            resolved = resolve_resource(filename, urdf.parent, package_dirs)
            if resolved is not None:
                mesh.set("filename", str(resolved.resolve()))
            elif tag == "collision" and needs_collision:
                raise ModelError(
                    f"collision mesh '{filename}' not found (relative paths from {urdf.parent}; "
                    "package:// in package_dirs and the installed example-robot-data)",
                    path=str(urdf),
                    link=link_name or link.get("name"),
                )
            else:
                link.remove(element)


def strip_undefined_materials(link: ET.Element, materials: set[str]) -> None:
    """Drop a visual's reference to a material the merged file does not define."""
    for visual in link.findall("visual"):
        material = visual.find("material")
        if material is not None and len(material) == 0 and material.get("name") not in materials:
            visual.remove(material)


def mark_dry_links(
    links: list[ET.Element], arm: URDFTree, renamed: dict[str, str], allow_dry_links: bool
) -> list[str]:
    """Give links with an <inertial> but no geometry and no hydrodynamics an explicit empty
    ``<hydrodynamics>`` (volume 0): always for massless frame links, and for links with mass
    when ``allow_dry_links`` (returned: they weigh but displace nothing). Links with mass
    are otherwise left for `load_uvms` to reject, naming them."""
    top_level = {h.get("link") for h in arm.root.findall("hydrodynamics")}
    dry = []
    for link in links:
        name = link.get("name")
        inertial = link.find("inertial")
        if (
            inertial is None
            or link.find("collision") is not None
            or link.find("hydrodynamics") is not None
            or original_name(name, renamed) in top_level
        ):
            continue
        mass_el = inertial.find("mass")
        try:
            mass = float(mass_el.get("value")) if mass_el is not None else math.nan
        except (TypeError, ValueError):
            continue  # load_uvms reports the bad <mass>
        if mass == 0.0 or (allow_dry_links and math.isfinite(mass)):
            ET.SubElement(link, "hydrodynamics").append(ET.Element("volume", {"value": "0"}))
            if mass > 0.0:
                dry.append(name)
    return dry
