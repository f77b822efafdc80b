"""A URDF tree as the text of a file, and writing it."""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from pathlib import Path

from uvms_pin.results import atomic

__all__ = ["urdf_text", "write_text_file"]


def urdf_text(root: ET.Element) -> str:
    """``root`` as a URDF file: XML declaration, two-space indent, final newline (``root``
    itself is left as it is)."""
    tree = copy.deepcopy(root)
    ET.indent(tree, "  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(tree, encoding="unicode") + "\n"


def write_text_file(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically (`uvms_pin.results.atomic`), creating the
    directory first: ``save_urdf`` and split files may go to a folder not made yet."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return atomic.write_text_atomic(path, text)
