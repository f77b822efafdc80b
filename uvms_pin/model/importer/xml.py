"""Reading numbers out of plugin elements, with a `ModelError` naming file, link and tag."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from uvms_pin.errors import ModelError

__all__ = ["child_numbers", "child_text", "element_numbers"]


def element_numbers(
    element: ET.Element, counts: tuple[int, ...], where: str, link: str
) -> np.ndarray:
    """The whitespace-separated finite numbers of an element's text; their count must be
    one of ``counts``."""
    text = element.text or ""
    try:
        values = np.array([float(tok) for tok in text.split()])
    except ValueError as exc:
        raise ModelError(
            f"<{element.tag}> has a non-numeric value '{text.strip()}'", path=where, link=link
        ) from exc
    if values.size not in counts:
        wanted = " or ".join(str(c) for c in counts)
        raise ModelError(
            f"<{element.tag}> needs {wanted} numbers, got {values.size}", path=where, link=link
        )
    if not np.all(np.isfinite(values)):
        raise ModelError(f"<{element.tag}> has a non-finite value", path=where, link=link)
    return values


def child_numbers(
    parent: ET.Element, tag: str, counts: tuple[int, ...], where: str, link: str
) -> np.ndarray | None:
    """`element_numbers` of the child ``tag``, None when there is no such child."""
    child = parent.find(tag)
    return None if child is None else element_numbers(child, counts, where, link)


def child_text(parent: ET.Element, tag: str) -> str | None:
    """The stripped text of the child ``tag`` (None when absent)."""
    child = parent.find(tag)
    return None if child is None or child.text is None else child.text.strip()
