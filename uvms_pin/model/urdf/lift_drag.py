"""``<lift_drag>`` in a URDF link: a fin's lift and drag (gz-sim's ``LiftDrag`` parameters,
`uvms_pin.hydro.lift_drag`), read into the UVMS's `Fin` list.

    <link name="fin">
      <lift_drag>
        <area value="0.0244"/>            <!-- m^2, required -->
        <fluid_density value="1000"/>     <!-- kg/m^3 (gz-sim: air_density; default 1.2041) -->
        <cla value="4.13"/> <cda value="0.2"/> <cma value="0"/>
        <alpha_stall value="0.17"/> <cla_stall value="-1.1"/> <cda_stall value="0.03"/>
        <cma_stall value="0"/> <a0 value="0"/>
        <cp xyz="0 0 0"/> <forward xyz="1 0 0"/> <upward xyz="0 0 1"/>   <!-- link frame -->
        <radial_symmetry value="false"/> <reversible value="false"/>
        <control_joint name="elevator" rad_to_cl="4.0" cm_delta="0"/>  <!-- optional -->
      </lift_drag>
    </link>

Every child but ``<area>`` is optional, with gz-sim's default; a link may hold several.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pinocchio as pin

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.hydro.lift_drag import LiftDragParams
from uvms_pin.model.urdf.bodies import link_carrier
from uvms_pin.model.urdf.read import known_children, read_numbers, single
from uvms_pin.model.uvms import Fin

__all__ = ["FLAGS", "NUMBERS", "VECTORS", "read_fins"]

#: <tag value> -> LiftDragParams field
NUMBERS = {"area": "area_m2", "fluid_density": "fluid_density_kg_m3", "cla": "cla",
           "cda": "cda", "cma": "cma", "alpha_stall": "alpha_stall_rad",
           "cla_stall": "cla_stall", "cda_stall": "cda_stall", "cma_stall": "cma_stall",
           "a0": "alpha0_rad"}  # fmt: skip
#: <tag xyz> -> field
VECTORS = {"cp": "cp_m", "forward": "forward", "upward": "upward"}
#: <tag value="true|false"> -> field
FLAGS = {"radial_symmetry": "radial_symmetry", "reversible": "reversible"}


def read_fins(root: ET.Element, model: pin.Model, where: str) -> tuple[Fin, ...]:
    """Every ``<lift_drag>`` of every link, in file order; ModelError naming the link and
    the tag for a bad one."""
    fins = []
    for link in root.findall("link"):
        name = link.get("name", "?")
        for element in link.findall("lift_drag"):
            params, control = _params(element, where, name)
            joint_id, placement = link_carrier(model, name, where)
            fins.append(
                Fin(name, joint_id, placement, params, _q_index(model, control, where, name))
            )
    return tuple(fins)


def _params(element: ET.Element, where: str, link: str) -> tuple[LiftDragParams, str | None]:
    known_children(element, {*NUMBERS, *VECTORS, *FLAGS, "control_joint"}, where, link)
    values = {}
    for tag, key in NUMBERS.items():
        child = single(element, tag, where, link)
        if child is not None:
            values[key] = float(
                read_numbers(child.get("value"), 1, f"<{tag} value>", where, link)[0]
            )
    if "area_m2" not in values:
        raise ModelError("<lift_drag> needs <area value=...> [m^2]", path=where, link=link)
    for tag, key in VECTORS.items():
        child = single(element, tag, where, link)
        if child is not None:
            values[key] = read_numbers(child.get("xyz"), 3, f"<{tag} xyz>", where, link)
    for tag, key in FLAGS.items():
        child = single(element, tag, where, link)
        if child is not None:
            text = (child.get("value") or "").strip().lower()
            if text not in ("true", "false", "1", "0"):
                raise ModelError(
                    f"<{tag} value> must be true or false, got '{text}'", path=where, link=link
                )
            values[key] = text in ("true", "1")
    control = single(element, "control_joint", where, link)
    joint = None
    if control is not None:
        joint = control.get("name")
        for attribute, key in (("rad_to_cl", "control_joint_rad_to_cl"), ("cm_delta", "cm_delta")):
            if control.get(attribute) is not None:
                text = control.get(attribute)
                values[key] = float(
                    read_numbers(text, 1, f"<control_joint {attribute}>", where, link)[0]
                )
    try:
        return LiftDragParams(**values), joint
    except ParameterError as exc:
        raise ModelError(str(exc), path=where, link=link) from exc


def _q_index(model: pin.Model, joint: str | None, where: str, link: str) -> int | None:
    if joint is None:
        return None
    if not joint or not model.existJointName(joint) or model.getJointId(joint) < 2:
        raise ModelError(
            f"<lift_drag><control_joint name='{joint}'> is not an arm joint of the model",
            path=where,
            link=link,
        )
    joint_model = model.joints[model.getJointId(joint)]
    if joint_model.nq != 1:
        raise ModelError(
            f"control joint '{joint}' has {joint_model.nq} coordinates, not 1",
            path=where,
            link=link,
        )
    return int(joint_model.idx_q)
