"""gz-sim's ``LiftDrag`` system -> a ``<lift_drag>`` element in its link
(`uvms_pin.model.urdf.lift_drag`, `uvms_pin.hydro.lift_drag`).

The plugin's parameters map one to one (``air_density`` is the fluid's density, whatever the
fluid; ``control_joint_name``, ``control_joint_rad_to_cl`` and ``cm_delta`` become
``<control_joint>``); gz-sim's defaults stand for the ones the plugin leaves out, and a
missing ``air_density`` (1.2041 kg/m^3: air) is reported. gz-sim applies the force at ``cp``
taken from the link's origin (``LiftDrag.cc``: the world wrench at the link origin with the
torque cp x F), and so does uvms-pin. Source: gz-sim (github.com/gazebosim/gz-sim, commit
93bbf3e), ``src/systems/lift_drag/LiftDrag.cc``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from uvms_pin.errors import ModelError
from uvms_pin.model.importer.plugins import PluginKind, plugin_kind
from uvms_pin.model.importer.xml import child_numbers, child_text
from uvms_pin.model.urdf.lift_drag import FLAGS, NUMBERS, VECTORS

__all__ = ["add_fins"]

#: the plugin's tag -> the <lift_drag> child's (numbers: value attribute)
_NUMBER_TAGS = {
    "air_density": "fluid_density",
    **{tag: tag for tag in NUMBERS if tag != "fluid_density"},
}
_CONTROL = {"control_joint_name", "control_joint_rad_to_cl", "cm_delta"}


def add_fins(robot: ET.Element, plugins: list[ET.Element], where: str, notes: list[str]) -> int:
    """A ``<lift_drag>`` in the link of each LiftDrag plugin; the number of fins added."""
    links = {link.get("name"): link for link in robot.findall("link")}
    moving = {j.get("name") for j in robot.findall("joint") if j.get("type") != "fixed"}
    count = 0
    for plugin in plugins:
        if plugin_kind(plugin) is not PluginKind.GZ_LIFT_DRAG:
            continue
        name = child_text(plugin, "link_name")
        if name not in links:
            raise ModelError(
                f"a LiftDrag plugin names link {name!r}, which is not in the model (or is a "
                "thruster's propeller, which leaves it)",
                path=where,
            )
        links[name].append(_element(plugin, moving, where, name, notes))
        count += 1
    return count


def _element(
    plugin: ET.Element, moving: set[str], where: str, link: str, notes: list[str]
) -> ET.Element:
    out = ET.Element("lift_drag")
    known = {*_NUMBER_TAGS, *VECTORS, *FLAGS, *_CONTROL, "link_name"}
    for child in plugin:
        if child.tag not in known:
            notes.append(f"link '{link}': LiftDrag <{child.tag}> not mapped")
    for tag, ours in _NUMBER_TAGS.items():
        value = child_numbers(plugin, tag, (1,), where, link)
        if value is not None:
            ET.SubElement(out, ours, value=repr(float(value[0])))
    if plugin.find("air_density") is None:
        notes.append(f"link '{link}': LiftDrag without <air_density>: gz-sim's 1.2041 kg/m^3 (air)")
    for tag in VECTORS:
        value = child_numbers(plugin, tag, (3,), where, link)
        if value is not None:
            ET.SubElement(out, tag, xyz=" ".join(repr(float(x)) for x in value))
    for tag in FLAGS:
        text = child_text(plugin, tag)
        if text is not None:
            ET.SubElement(out, tag, value="true" if text.lower() in ("1", "true") else "false")
    joint = child_text(plugin, "control_joint_name")
    if joint is not None:
        if joint not in moving:
            raise ModelError(
                f"LiftDrag <control_joint_name> '{joint}' is not a moving joint of the model",
                path=where,
                link=link,
            )
        control = ET.SubElement(out, "control_joint", name=joint)
        for tag, attribute in (("control_joint_rad_to_cl", "rad_to_cl"), ("cm_delta", "cm_delta")):
            value = child_numbers(plugin, tag, (1,), where, link)
            if value is not None:
                control.set(attribute, repr(float(value[0])))
    return out
