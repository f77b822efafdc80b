"""gz-sim's ``LiftDrag`` system -> a ``<lift_drag>`` element in its link
(`uvms_pin.model.urdf.lift_drag`, `uvms_pin.hydro.lift_drag`).

The plugin's parameters map one to one (``air_density`` is the fluid's density, whatever the
fluid; ``control_joint_name``, ``control_joint_rad_to_cl`` and ``cm_delta`` become
``<control_joint>``); gz-sim's defaults stand for the ones the plugin leaves out, and a
missing ``air_density`` (1.2041 kg/m^3: air) is reported. gz-sim applies the force at ``cp``
taken from the link's origin (``LiftDrag.cc``: the world wrench at the link origin with the
torque cp x F), and so does uvms-pin. Source: gz-sim (github.com/gazebosim/gz-sim, commit
93bbf3e), ``src/systems/lift_drag/LiftDrag.cc``.

uuv_simulator's Fin plugin with its ``<liftdrag>`` of type ``TwoLines`` (uuv_gazebo_plugins,
``FinPlugin.cc``, ``LiftDragModel.cc``) becomes the same element: it takes the fin link's
velocity through the water in the link's x-y plane, the angle of attack from x toward y,
lift along -z x v and drag along -v, both c q S with c_L = c_La alpha and c_D = c_Da alpha
below the stall and the stall slopes beyond, at the link's centre of mass (ODE's
``dBodyAddRelForce``); gz-sim's LiftDrag with forward = x, upward = -y, ``reversible`` (uuv
folds a flow from behind onto the chord) and the centre of pressure at the link's inertial
origin is that (tests/model/importer/test_import_inertia_fins.py compares the two for flows
in the plane). What differs, said in the notes: gz-sim scales the coefficients by
cos^2 of the sweep (uuv does not) and applies no force below 0.01 m/s; beyond the negative
stall uuv's c_L takes the drag's stall slope, and its c_D changes sign with alpha (a fin that
pushes): uvms-pin keeps gz-sim's (the lift's slope, |c_D|). ``Quadratic`` (c_D in alpha^2) is
no LiftDrag: reported as not mapped.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from uvms_pin.errors import ModelError
from uvms_pin.model.importer.plugins import PluginKind, plugin_kind
from uvms_pin.model.importer.xml import child_numbers, child_text, element_numbers
from uvms_pin.model.urdf.lift_drag import FLAGS, NUMBERS, VECTORS

__all__ = ["add_fins"]

#: the plugin's tag -> the <lift_drag> child's (numbers: value attribute)
_NUMBER_TAGS = {
    "air_density": "fluid_density",
    **{tag: tag for tag in NUMBERS if tag != "fluid_density"},
}
_CONTROL = {"control_joint_name", "control_joint_rad_to_cl", "cm_delta"}


def add_fins(robot: ET.Element, plugins: list[ET.Element], where: str, notes: list[str]) -> None:
    """A ``<lift_drag>`` in the link of each LiftDrag plugin and each uuv_simulator fin of
    the TwoLines model."""
    links = {link.get("name"): link for link in robot.findall("link")}
    moving = {j.get("name") for j in robot.findall("joint") if j.get("type") != "fixed"}
    for plugin in plugins:
        if plugin_kind(plugin) is PluginKind.UUV_FIN:
            _uuv_fin(plugin, links, where, notes)
            continue
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


#: uuv's TwoLines parameters -> the <lift_drag> child's (empty text: 0, as the plugin reads it)
_UUV_NUMBERS = {
    "area": "area", "fluid_density": "fluid_density", "a0": "a0", "alpha_stall": "alpha_stall",
    "cla": "cla", "cla_stall": "cla_stall", "cda": "cda", "cda_stall": "cda_stall",
}  # fmt: skip


def _uuv_fin(
    plugin: ET.Element, links: dict[str, ET.Element], where: str, notes: list[str]
) -> None:
    """uuv_simulator's fin ``plugin`` as a ``<lift_drag>`` in its link, or a note."""
    name = child_text(plugin, "link_name")
    model = plugin.find("liftdrag")
    kind = None if model is None else child_text(model, "type")
    if name not in links or model is None or kind != "TwoLines":
        why = "no link of the model" if name not in links else f"<liftdrag> type {kind!r}"
        notes.append(f"fin plugin '{plugin.get('name')}': {why}; its lift and drag not mapped")
        return
    out = ET.Element("lift_drag")
    for tag, ours in _UUV_NUMBERS.items():
        element = model.find(tag)
        if element is None:
            continue
        # an empty value is 0 to the plugin (ECA A9's <cda_stall></cda_stall>)
        empty = not (element.text or "").strip()
        value = 0.0 if empty else float(element_numbers(element, (1,), where, name)[0])
        ET.SubElement(out, ours, value=repr(value))
    origin = links[name].find("inertial/origin")
    centre = "0 0 0" if origin is None else (origin.get("xyz") or "0 0 0")
    ET.SubElement(out, "cp", xyz=centre)
    ET.SubElement(out, "forward", xyz="1 0 0")
    ET.SubElement(out, "upward", xyz="0 -1 0")
    ET.SubElement(out, "reversible", value="true")
    links[name].append(out)
    notes.append(
        f"fin '{name}': uuv_simulator's TwoLines lift and drag as a <lift_drag> (gz-sim's "
        "model: coefficients scaled by cos^2 of the sweep, none below 0.01 m/s, beyond the "
        "negative stall the lift's slope and |c_D|, where uuv differs)"
    )
