"""The displaced volume and its centroid of a link's URDF collision primitives: what gz-sim's
Buoyancy system computes from the collision shapes (uniform fluid)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from uvms_pin.model.urdf.read import read_numbers, read_origin

__all__ = ["collision_volume"]


def _shape_volume(geometry: ET.Element, where: str, link: str) -> float | None:
    """V [m^3] of a box, sphere or cylinder; None for a mesh or anything else."""
    shape = next(iter(geometry), None)
    if shape is None:
        return None
    if shape.tag == "box":
        return float(np.prod(read_numbers(shape.get("size"), 3, "<box size>", where, link)))
    if shape.tag == "sphere":
        r = float(read_numbers(shape.get("radius"), 1, "<sphere radius>", where, link)[0])
        return 4.0 / 3.0 * math.pi * r**3
    if shape.tag == "cylinder":
        r = float(read_numbers(shape.get("radius"), 1, "<cylinder radius>", where, link)[0])
        length = float(read_numbers(shape.get("length"), 1, "<cylinder length>", where, link)[0])
        return math.pi * r**2 * length
    return None


def collision_volume(link: ET.Element, where: str, notes: list[str]) -> tuple[float, np.ndarray]:
    """(sum of the primitives' volumes [m^3], their volume centroid in the link frame [m]);
    a shape without a closed-form volume (a mesh) is left out and noted."""
    name = link.get("name", "?")
    total, moment = 0.0, np.zeros(3)
    for collision in link.findall("collision"):
        geometry = collision.find("geometry")
        volume = None if geometry is None else _shape_volume(geometry, where, name)
        if volume is None:
            notes.append(
                f"link '{name}': a collision shape without a primitive volume left out of its buoyancy"
            )
            continue
        centre = read_origin(collision.find("origin"), where, name).translation
        total += volume
        moment += volume * centre
    return total, (moment / total if total > 0.0 else np.zeros(3))
