"""The hull envelope: the first box collision of the vehicle link, used by the trim (where
the foam and ballast go) and by the reach check of `uvms_pin.apps.arms`."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from uvms_pin.model.mount.tree import URDFTree

__all__ = ["first_box", "hull_box"]


def hull_box(urdf: str | Path, link: str | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """(centre, full size) [m] of the first box collision of ``link`` (default: the root) in
    that link's frame, or None: the hull envelope used by the trim and the reach check."""
    tree = URDFTree.read(Path(urdf))
    name = tree.root_link if link is None else tree.require_link(link, "link")
    return first_box(tree.links[name])


def first_box(link: ET.Element) -> tuple[np.ndarray, np.ndarray] | None:
    """(centre, full size) [m] of the first box collision of a link, or None."""
    for collision in link.findall("collision"):
        box = collision.find("geometry/box")
        if box is None:
            continue
        origin = collision.find("origin")
        xyz = (
            np.zeros(3)
            if origin is None
            else np.array([float(t) for t in origin.get("xyz", "0 0 0").split()])
        )
        size = np.array([float(t) for t in box.get("size").split()])
        return xyz, size
    return None
