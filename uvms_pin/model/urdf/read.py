"""Reading URDF text: the ``<robot>`` root of a file, numbers and ``<origin>`` placements of
attributes, with a `ModelError` naming the file, the link and what is wrong."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError

__all__ = ["known_children", "read_numbers", "read_origin", "read_urdf_root"]


#: what an undeclared prefix stands for where the name is known (an unexpanded xacro file
#: that forgot its ``xmlns:xacro`` is still recognised as one)
_KNOWN_NAMESPACES = {"xacro": "http://www.ros.org/wiki/xacro"}
_UNDECLARED_NAMESPACE = "urn:uvms-pin:undeclared:"
# a prefix in an element's or an attribute's name
_PREFIXED = re.compile(r"</?([A-Za-z_][\w.-]*):[A-Za-z_]|\s([A-Za-z_][\w.-]*):[A-Za-z_][\w.-]*\s*=")
# the root element's start tag: the first tag that is no declaration, comment or doctype
_ROOT_TAG = re.compile(r"<([A-Za-z_][\w.:-]*)")


def xml_root(path: Path) -> ET.Element:
    """The root element of an XML file; ModelError naming the file if it is missing or not
    well-formed.

    A prefix used without its ``xmlns`` declaration is declared for it: SDFormat's parser
    (TinyXML2) does not ask for one, and files gz-sim loads use ``gz:`` and ``experimental:``
    so (MBARI's LRAUV). Such an element's tag is then ``{urn:uvms-pin:undeclared:gz}type``
    (``xacro:``'s is its usual namespace), which nothing here reads as its own."""
    if not path.is_file():
        raise ModelError("file not found", path=str(path))
    try:
        return ET.parse(path).getroot()
    except ET.ParseError as exc:
        if "unbound prefix" in str(exc):
            declared = _with_prefixes_declared(path.read_text(encoding="utf-8", errors="replace"))
            if declared is not None:
                return declared
        raise ModelError(f"not well-formed XML ({exc})", path=str(path)) from exc


def _with_prefixes_declared(text: str) -> ET.Element | None:
    """The root of ``text`` with every prefix it uses and does not declare declared on its
    root element; None when it is still not well-formed."""
    used = {a or b for a, b in _PREFIXED.findall(text)} - {"xmlns", "xml"}
    declared = set(re.findall(r"xmlns:([A-Za-z_][\w.-]*)\s*=", text))
    missing = sorted(used - declared)
    root = _ROOT_TAG.search(re.sub(r"<!--.*?-->", lambda m: " " * len(m[0]), text, flags=re.S))
    if not missing or root is None:
        return None
    declarations = "".join(
        f' xmlns:{p}="{_KNOWN_NAMESPACES.get(p, _UNDECLARED_NAMESPACE + p)}"' for p in missing
    )
    try:
        return ET.fromstring(text[: root.end()] + declarations + text[root.end() :])
    except ET.ParseError:
        return None


def read_urdf_root(path: Path) -> ET.Element:
    """The <robot> element of a URDF file; ModelError naming the file otherwise."""
    where = str(path)
    if path.is_dir():
        raise ModelError("is a directory, not a URDF file", path=where)
    root = xml_root(path)
    if root.tag != "robot":
        hint = (
            ": an SDF model, which `uvms-pin import FILE --out model.urdf` converts (with its "
            "Gazebo plugins' hydrodynamics and thrusters)"
            if root.tag == "sdf"
            else ""
        )
        raise ModelError(f"root element is <{root.tag}>, expected <robot>{hint}", path=where)
    return root


def read_numbers(text: str | None, count: int, what: str, where: str, link: str) -> np.ndarray:
    """``count`` finite numbers from an attribute's text (``what`` names it in errors)."""
    if text is None:
        raise ModelError(f"{what} is missing its value", path=where, link=link)
    try:
        values = np.array([float(tok) for tok in text.split()])
    except ValueError as exc:
        raise ModelError(f"{what} has a non-numeric value '{text}'", path=where, link=link) from exc
    if values.size != count:
        raise ModelError(f"{what} needs {count} numbers, got {values.size}", path=where, link=link)
    if not np.all(np.isfinite(values)):
        raise ModelError(f"{what} has a non-finite value", path=where, link=link)
    return values


def read_origin(element: ET.Element | None, where: str, link: str) -> pin.SE3:
    """The placement an ``<origin xyz rpy>`` element gives [m, rad] (identity when absent)."""
    if element is None:
        return pin.SE3.Identity()
    xyz = read_numbers(element.get("xyz", "0 0 0"), 3, "<origin xyz>", where, link)
    rpy = read_numbers(element.get("rpy", "0 0 0"), 3, "<origin rpy>", where, link)
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)


def single(element: ET.Element, tag: str, where: str, link: str) -> ET.Element | None:
    """The one ``<tag>`` child of ``element`` (None without one).

    Raises:
        ModelError: more than one (a reader taking the first would silently drop the rest).
    """
    found = element.findall(tag)
    if len(found) > 1:
        raise ModelError(
            f"<{element.tag}> has {len(found)} <{tag}> elements; give one", path=where, link=link
        )
    return found[0] if found else None


def known_children(element: ET.Element, known, where: str, link: str) -> None:
    """ModelError naming the first child of ``element`` whose tag is not in ``known``."""
    for child in element:
        if child.tag not in known:
            raise ModelError(
                f"unknown tag <{child.tag}> in <{element.tag}>; known: {', '.join(sorted(known))}",
                path=where,
                link=link,
            )
